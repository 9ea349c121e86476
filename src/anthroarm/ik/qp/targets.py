"""Validation of IK targets: rigid 4×4 transforms, rotations and positions (SI units).

Every function raises ``ValueError`` naming the value at fault: wrong shape, NaN/inf, a
rotation block that is not orthonormal with det +1 (tolerance 1e-6), or a bottom row that is
not (0, 0, 0, 1).  A rotation within the tolerance is re-orthonormalised (nearest rotation,
SVD) so that log(R) is well defined.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

RIGID_TOL = 1e-6
_F64 = np.dtype(np.float64)


def _check_finite(a: np.ndarray, name: str) -> None:
    f = a.ravel()
    if not math.isfinite(f @ f) and not np.isfinite(f).all():
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise ValueError(f"{name}{list(idx)} is {a[idx]} (targets must be finite)")


def _rotation_defect(r) -> tuple[float, float]:
    """(max |R Rᵀ − I|, det R) of a 3×3 nested list (pure Python: cheaper than numpy at 3×3;
    longer rows, e.g. those of a 4×4 transform, are read up to their third entry)."""
    a, b, c = r[0], r[1], r[2]
    e = max(
        abs(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1.0),
        abs(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] - 1.0),
        abs(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - 1.0),
        abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]),
        abs(a[0] * c[0] + a[1] * c[1] + a[2] * c[2]),
        abs(b[0] * c[0] + b[1] * c[1] + b[2] * c[2]),
    )
    det = (
        a[0] * (b[1] * c[2] - b[2] * c[1])
        - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
    )
    return e, det


def _clean_rigid(r) -> bool:
    """True when the nested 4×4 list ``r`` is finite, has the bottom row (0, 0, 0, 1) exactly
    and a rotation block orthonormal to 1e-12 with det > 0: then :func:`as_se3` takes it as it
    is (the checks of :func:`_rotation_defect` written for one unpacked 4×4)."""
    (a0, a1, a2, a3), (b0, b1, b2, b3), (c0, c1, c2, c3), d = r
    if d != [0.0, 0.0, 0.0, 1.0] or not math.isfinite(
        a0 + a1 + a2 + a3 + b0 + b1 + b2 + b3 + c0 + c1 + c2 + c3
    ):
        return False
    if (
        max(
            abs(a0 * a0 + a1 * a1 + a2 * a2 - 1.0),
            abs(b0 * b0 + b1 * b1 + b2 * b2 - 1.0),
            abs(c0 * c0 + c1 * c1 + c2 * c2 - 1.0),
            abs(a0 * b0 + a1 * b1 + a2 * b2),
            abs(a0 * c0 + a1 * c1 + a2 * c2),
            abs(b0 * c0 + b1 * c1 + b2 * c2),
        )
        > 1e-12
    ):
        return False
    return a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0) > 0.0


def as_rotation(R, name: str = "R") -> np.ndarray:
    """A proper rotation matrix (3, 3) or ``ValueError``."""
    R = np.asarray(R, dtype=float)
    if R.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 rotation matrix, got shape {R.shape}")
    _check_finite(R, name)
    err, det = _rotation_defect(R.tolist())
    if err > RIGID_TOL or det < 0:
        raise ValueError(
            f"{name} is not a rotation: max|RRᵀ − I| = {err:.3g}, det = {det:.6g} "
            f"(need orthonormal with det +1 within {RIGID_TOL:g})"
        )
    if err > 1e-12:
        U, _, Vt = np.linalg.svd(R)
        R = U @ Vt
    return R


def as_position(p, name: str = "p") -> np.ndarray:
    """A position (3,) in m, or ``ValueError``."""
    p = np.asarray(p, dtype=float)
    if p.shape != (3,):
        raise ValueError(f"{name} must be a position of shape (3,), got shape {p.shape}")
    _check_finite(p, name)
    return p


def as_rigid(T, name: str = "T") -> np.ndarray:
    """A rigid 4×4 homogeneous matrix (a fresh float64 C-order array) from ``T`` (array-like or
    ``pin.SE3``), or ``ValueError``; a rotation block off by more than 1e-12 (at most
    :data:`RIGID_TOL`) is replaced by the nearest rotation."""
    if (
        T.__class__ is np.ndarray
        and T.shape == (4, 4)
        and T.dtype == _F64
        and _clean_rigid(T.tolist())
    ):
        # fast path (a per-step target): taken as it is; anything else goes through the full
        # checks below (which raise or re-orthonormalise)
        return T.copy()  # C order (ndarray.copy's default)
    if isinstance(T, pin.SE3):
        T = T.homogeneous
    T = np.asarray(T, dtype=float)
    if T.shape != (4, 4):
        raise ValueError(f"{name} must be a 4x4 homogeneous transform, got shape {T.shape}")
    _check_finite(T, name)
    b = T[3].tolist()
    if (
        abs(b[0]) > RIGID_TOL
        or abs(b[1]) > RIGID_TOL
        or abs(b[2]) > RIGID_TOL
        or abs(b[3] - 1.0) > RIGID_TOL
    ):
        raise ValueError(f"{name} is not rigid: bottom row {b} is not [0, 0, 0, 1]")
    H = np.eye(4)
    H[:3, :3] = as_rotation(T[:3, :3], f"{name}[:3, :3]")
    H[:3, 3] = T[:3, 3]
    return H


def as_se3(T, name: str = "T") -> pin.SE3:
    """A ``pin.SE3`` from a rigid 4×4 homogeneous matrix (or a ``pin.SE3``), or ``ValueError``
    (:func:`as_rigid`)."""
    return pin.SE3(as_rigid(T, name))
