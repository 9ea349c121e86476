"""Elementary rotations and the validation of axes and rotation matrices (book §5-4).

Convention (book §5-4, §5-5): rotation matrices are **active**, new → old: the columns of
``C`` are the new axes written in the old frame, ``r_old = C r_new`` (Eq. (5-64)–(5-66)).
This is Pinocchio's ``oMi.rotation``.  Angles in rad, lengths in m.

Every function accepts a scalar angle or an array of angles (the result then has the shape
``angle.shape + (3, 3)``).
"""

from __future__ import annotations

import math

import numpy as np

#: tolerance for |u| = 1 and for R Rᵀ = I
UNIT_TOL = 1e-9
ORTHO_TOL = 1e-9


# ----------------------------------------------------------------------------- validation
def as_vector3(v, name: str = "vector") -> np.ndarray:
    """``v`` as a float array of shape (..., 3); ``ValueError`` naming the value if the last
    axis is not 3 or a component is NaN/inf."""
    a = np.asarray(v, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (3,) or (N, 3), got shape {a.shape}: {v!r}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} has a NaN or infinite component: {a.tolist()}")
    return a


def as_angle(a, name: str = "angle") -> np.ndarray:
    """Finite float array; ``ValueError`` naming the value otherwise."""
    arr = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def as_scalar(x, name: str = "value") -> float:
    """``x`` as one finite float; ``ValueError`` naming the value for NaN/inf, a non-number or
    an array of more than one element."""
    if isinstance(x, (float, int, np.floating, np.integer)):  # fast path for plain numbers
        v = float(x)
        if not math.isfinite(v):
            raise ValueError(f"{name} must be finite, got {v}")
        return v
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {x!r}") from None
    if arr.size != 1:
        raise ValueError(f"{name} must be a scalar, got shape {arr.shape}")
    v = float(arr.reshape(()))
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v}")
    return v


def check_unit_axis(u, name: str = "axis", tol: float = UNIT_TOL) -> np.ndarray:
    """A unit axis (shape (..., 3)).  Raises ``ValueError`` with the offending value for a
    zero-length axis or an axis whose length differs from 1 by more than ``tol``.

    The book's rotation tensor E^{wθ} and screw matrices need |w| = 1 (Eq. (5-101), 002 (4-6));
    use :func:`unit_axis` to normalise a direction explicitly."""
    a = as_vector3(u, name)
    # a component above 2 cannot belong to a unit vector (and its square might overflow)
    n = np.where(
        np.max(np.abs(a), axis=-1) > 2.0, np.inf, np.linalg.norm(np.clip(a, -2.0, 2.0), axis=-1)
    )
    if np.any(n < 1e-12):
        raise ValueError(f"{name} has zero length: {a.tolist()}")
    if np.any(np.abs(n - 1.0) > tol):
        bad = a if a.ndim == 1 else a[np.argmax(np.abs(n - 1.0))]
        raise ValueError(
            f"{name} must be a unit vector, got {np.asarray(bad).tolist()} with length "
            f"{float(np.max(n) if a.ndim == 1 else np.linalg.norm(bad)):.12g}; normalise it with "
            "unit_axis()"
        )
    return a


def unit_axis(u, name: str = "axis") -> np.ndarray:
    """Normalise a direction (shape (..., 3)); ``ValueError`` for a zero-length one."""
    a = as_vector3(u, name)
    m = np.max(np.abs(a), axis=-1, keepdims=True)  # divide by the largest component first:
    if np.any(m < 1e-300):  # no square overflows or underflows
        raise ValueError(f"{name} has zero length: {a.tolist()}")
    a = a / m
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    if np.any(m * n < 1e-12):
        raise ValueError(f"{name} has zero length: {(a * m).tolist()}")
    return a / n


def check_rotation(R, name: str = "rotation", tol: float = ORTHO_TOL) -> np.ndarray:
    """A proper rotation matrix (shape (..., 3, 3)).

    Raises ``ValueError`` naming the offending value when the shape is wrong, an element is
    NaN/inf, ``R Rᵀ`` differs from I by more than ``tol`` (max abs), or det R ≠ +1 (a
    reflection).  Book: C is orthogonal, det C = 1 (Eq. (5-66), (5-113))."""
    a = np.asarray(R, dtype=float)
    if a.ndim < 2 or a.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have shape (3, 3) or (N, 3, 3), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} has a NaN or infinite element: {a.tolist()}")
    big = np.abs(a).max(axis=(-2, -1))
    if np.any(big > 2.0):  # entries of a rotation lie in [-1, 1]; R R^T would overflow at ~1e154
        raise ValueError(
            f"{name} is not orthogonal: it has an element of magnitude {float(np.max(big)):.6g} "
            f"(the entries of a rotation lie in [-1, 1])"
        )
    err = np.abs(a @ np.swapaxes(a, -1, -2) - np.eye(3)).max(axis=(-2, -1))
    if np.any(err > tol):
        i = int(np.argmax(err)) if a.ndim > 2 else 0
        bad = a if a.ndim == 2 else a.reshape(-1, 3, 3)[i]
        raise ValueError(
            f"{name} is not orthogonal: max |R R^T - I| = {float(np.max(err)):.3e} > {tol:g} for "
            f"{bad.tolist()}"
        )
    det = np.linalg.det(a)
    if np.any(det < 0):
        raise ValueError(
            f"{name} is a reflection (det = {float(np.min(det)):.6g}), not a rotation: {a.tolist()}"
        )
    return a


# ----------------------------------------------------------------------------- skew
def skew(v) -> np.ndarray:
    """Skew matrix [v]× with [v]× r = v × r (the book's J₃ of Eq. (5-108) and 002 [P_u])."""
    a = as_vector3(v, "vector")
    x, y, z = a[..., 0], a[..., 1], a[..., 2]
    o = np.zeros_like(x)
    return np.stack(
        [np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2
    )


def unskew(W) -> np.ndarray:
    """Vector w of a skew matrix W = [w]× (the antisymmetric part is used)."""
    W = np.asarray(W, dtype=float)
    if W.shape[-2:] != (3, 3) or not np.all(np.isfinite(W)):
        raise ValueError(
            f"W must be a finite (..., 3, 3) matrix, got shape {W.shape}: {W.tolist()}"
        )
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]], -1
    )


# ----------------------------------------------------------------------------- elementary rotations
def _cs(angle, name="angle"):
    a = as_angle(angle, name)
    return np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)


def rot_x(angle) -> np.ndarray:
    """C_x(angle), Eq. (5-70) (= E^{iθ}, Eq. (5-98)): active rotation about x."""
    c, s, one, o = _cs(angle)
    return np.stack(
        [np.stack([one, o, o], -1), np.stack([o, c, -s], -1), np.stack([o, s, c], -1)], -2
    )


def rot_y(angle) -> np.ndarray:
    """C_y(angle), Eq. (5-71) (= E^{jθ}, Eq. (5-99)): active rotation about y."""
    c, s, one, o = _cs(angle)
    return np.stack(
        [np.stack([c, o, s], -1), np.stack([o, one, o], -1), np.stack([-s, o, c], -1)], -2
    )


def rot_z(angle) -> np.ndarray:
    """C_z(angle), Eq. (5-72) (= E^{kθ}, Eq. (5-94)–(5-97)): active rotation about z."""
    c, s, one, o = _cs(angle)
    return np.stack(
        [np.stack([c, -s, o], -1), np.stack([s, c, o], -1), np.stack([o, o, one], -1)], -2
    )


def rot(axis: str, angle) -> np.ndarray:
    """Elementary rotation about ``'x'``, ``'y'`` or ``'z'``."""
    try:
        return {"x": rot_x, "y": rot_y, "z": rot_z}[axis](angle)
    except KeyError:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}") from None


def rot_axis(n, phi) -> np.ndarray:
    """Rotation by ``phi`` about the unit axis ``n`` = (cos α, cos β, cos γ), Eq. (5-82)–(5-84):
    ``C = cos φ I + (1 − cos φ) n nᵀ + sin φ [n]×`` (Rodrigues).  Active; ``n`` must be unit."""
    n = check_unit_axis(n, "axis n")
    phi = as_angle(phi, "phi")
    c, s = np.cos(phi)[..., None, None], np.sin(phi)[..., None, None]
    nn = n[..., :, None] * n[..., None, :]
    return c * np.eye(3) + (1.0 - c) * nn + s * skew(n)


def rotation_between(a, b) -> np.ndarray:
    """The smallest rotation C with C â = b̂ for two nonzero directions a, b (any length): the
    turn about v = â × b̂ by the angle between them, Rodrigues (5-84) written as
    ``C = I + [v]× + [v]×² / (1 + c)`` with c = â·b̂.  For b̂ = −â: a half turn about the
    coordinate axis least aligned with â, made perpendicular to â (about x for â = ±y or ±z).
    Active; ``ValueError`` for a zero-length or non-finite direction."""
    a = unit_axis(a, "direction a")
    b = unit_axis(b, "direction b")
    if a.ndim != 1 or b.ndim != 1:
        raise ValueError(
            f"rotation_between takes two (3,) directions, got shapes {a.shape} and {b.shape}"
        )
    v = np.cross(a, b)
    c = float(a @ b)
    if np.linalg.norm(v) < 1e-12:
        if c > 0:
            return np.eye(3)
        k = int(np.argmin(np.abs(a)))
        n = np.eye(3)[k] - a[k] * a
        n /= np.linalg.norm(n)
        return 2.0 * np.outer(n, n) - np.eye(3)
    V = skew(v)
    if c >= 0.0:
        return np.eye(3) + V + V @ V * (1.0 / (1.0 + c))
    # beyond a quarter turn 1/(1 + c) amplifies the rounding of V @ V (orthogonality lost as
    # eps/(1 + c)): Rodrigues with the unit axis and (sin, cos) of the angle, orthogonal to eps
    s = float(np.linalg.norm(v))
    K = V / s
    r = float(np.hypot(s, c))
    return np.eye(3) + K * (s / r) + K @ K * (1.0 - c / r)


def axis_angle(R) -> tuple[np.ndarray, float]:
    """Inverse of Eq. (5-84): unit axis n and angle φ ∈ [0, π] with ``rot_axis(n, φ) = R``.

    At φ = 0 the axis is arbitrary and (1, 0, 0) is returned; near φ = π the axis is taken
    from the symmetric part (n nᵀ = (R + I)/2)."""
    R = check_rotation(R)
    if R.ndim != 2:
        raise ValueError(f"axis_angle takes one (3, 3) matrix, got shape {R.shape}")
    w = unskew(R)
    s = np.linalg.norm(w)
    c = 0.5 * (np.trace(R) - 1.0)
    phi = float(np.arctan2(s, np.clip(c, -1.0, 1.0)))
    if s < 1e-12 and c > 0:
        return np.array([1.0, 0.0, 0.0]), 0.0
    if c < -0.5:  # near π: sin φ small, use n nᵀ = (R + Rᵀ)/2 - c I over (1 - c)
        B = (0.5 * (R + R.T) - c * np.eye(3)) / (1.0 - c)
        k = int(np.argmax(np.diag(B)))
        n = B[:, k] / np.sqrt(B[k, k])
        if n @ w < 0:
            n = -n
        return n / np.linalg.norm(n), phi
    return w / s, phi


# ----------------------------------------------------------------------------- homogeneous matrices
def homogeneous(C=None, r=None) -> np.ndarray:
    """A = [[C, r′], [0ᵀ, 1]], Eq. (5-67): new → old pose (rotation C, new origin r′ in old)."""
    A = np.eye(4)
    if C is not None:
        A[:3, :3] = check_rotation(C)
    if r is not None:
        A[:3, 3] = as_vector3(r, "r")
    return A


def translation(x=0.0, y=0.0, z=0.0) -> np.ndarray:
    """L = [[U, l], [0ᵀ, 1]], Eq. (5-76)–(5-78): pure translation by (x, y, z)."""
    return homogeneous(None, [x, y, z])


def planar_transform(theta, x0, y0) -> np.ndarray:
    """Planar 3×3 homogeneous transform, Eq. (5-62): (x₁, y₁, 1) = T (x₂, y₂, 1); new → old."""
    theta = as_scalar(theta, "theta")
    c, s = float(np.cos(theta)), float(np.sin(theta))
    return np.array([[c, -s, as_scalar(x0, "x0")], [s, c, as_scalar(y0, "y0")], [0.0, 0.0, 1.0]])


def direction_cosines(a) -> np.ndarray:
    """(cos α, cos β, cos γ) of a nonzero vector, Eq. (5-31); their squares sum to 1 (5-32)."""
    return unit_axis(a, "vector")
