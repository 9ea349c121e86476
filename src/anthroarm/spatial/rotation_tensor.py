"""The rotation transformation tensor E^{wθ} (book §5-5) and direction-cosine kinematics (§5-4 三).

E^{wθ}(R) rotates the vector R *actively* about the unit axis w by θ (right-hand rule),
Eq. (5-88).  Its decomposition into the three component tensors, Eq. (5-105)–(5-108):

    E^{wθ} = J₁ + J₂ cos θ + J₃ sin θ,   J₁ = w wᵀ,  J₂ = I − w wᵀ,  J₃ = [w]×.

Time derivatives (5-121)–(5-130) are returned term by term, named as in the book:
tangential (θ̈ J₃ R), centripetal (−θ̇² J₂ R), Coriolis (2 θ̇ J₃ Ṙ) and relative (R̈), each
already mapped by E (Eq. (5-130)).  Vectors in m, angles in rad, rates in rad/s, rad/s².

Direction-cosine kinematics (5-85)–(5-87′): with C_ij mapping frame-j to frame-i coordinates,
``Ċ = C W_body = W_space C`` and ``C̈ = C(ε + W²)_body = (ε + W²)_space C``, where W is the
skew matrix of the angular velocity and ε that of the angular acceleration.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .rotations import (
    as_angle,
    as_scalar,
    as_vector3,
    check_rotation,
    check_unit_axis,
    skew,
    unskew,
)


# ----------------------------------------------------------------------------- component tensors
def J1(w) -> np.ndarray:
    """First component tensor J₁ = w wᵀ, Eq. (5-106) (projection onto the axis)."""
    w = check_unit_axis(w, "axis w")
    return w[..., :, None] * w[..., None, :]


def J2(w) -> np.ndarray:
    """Second component tensor J₂ = I − w wᵀ, Eq. (5-107) (projection onto the plane ⟂ w)."""
    return np.eye(3) - J1(w)


def J3(w) -> np.ndarray:
    """Third component tensor J₃ = [w]×, Eq. (5-108): J₃(R) = w × R."""
    return skew(check_unit_axis(w, "axis w"))


def axis_from_angles(alpha, beta) -> np.ndarray:
    """Axis w = E^{kβ}(E^{jα}(k)) = (cos β sin α, sin β sin α, cos α), Eq. (5-100)/(5-101):
    α is the polar angle from k, β the azimuth."""
    alpha, beta = as_angle(alpha, "alpha"), as_angle(beta, "beta")
    return np.stack(
        [
            np.cos(beta) * np.sin(alpha),
            np.sin(beta) * np.sin(alpha),
            np.cos(alpha) * np.ones_like(beta),
        ],
        -1,
    )


def rotation_tensor(w, theta) -> np.ndarray:
    """E^{wθ} = J₁ + J₂ cos θ + J₃ sin θ, Eq. (5-105) (element form (5-104), with (3,3)
    corrected to cos θ + ν²(1 − cos θ)).  ``theta`` may be an array (result (..., 3, 3))."""
    w = check_unit_axis(w, "axis w")
    theta = as_angle(theta, "theta")
    c, s = np.cos(theta)[..., None, None], np.sin(theta)[..., None, None]
    j1 = w[..., :, None] * w[..., None, :]
    return j1 + (np.eye(3) - j1) * c + skew(w) * s


def rotate(w, theta, R) -> np.ndarray:
    """R′ = E^{wθ}(R), Eq. (5-88): the vector R rotated about the unit axis w by θ."""
    return np.einsum("...ij,...j->...i", rotation_tensor(w, theta), as_vector3(R, "R"))


def rotation_tensor_rate(w, theta, theta_dot, w_dot=None) -> np.ndarray:
    """Ė^{wθ}, Eq. (5-122): J̇₁ + J̇₂ cos θ + J̇₃ sin θ + θ̇(−J₂ sin θ + J₃ cos θ).

    For a fixed axis (``w_dot`` None or 0) this is (5-123) = θ̇ J₃ E, Eq. (5-125).  A moving
    axis needs ẇ ⟂ w (|w| stays 1)."""
    w = check_unit_axis(w, "axis w")
    th, thd = as_scalar(theta, "theta"), as_scalar(theta_dot, "theta_dot")
    c, s = np.cos(th), np.sin(th)
    j1 = np.outer(w, w)
    out = thd * (-(np.eye(3) - j1) * s + skew(w) * c)
    if w_dot is not None:
        wd = as_vector3(w_dot, "w_dot")
        j1d = np.outer(wd, w) + np.outer(w, wd)
        out = out + j1d - j1d * c + skew(wd) * s
    return out


def rotation_tensor_acc(w, theta, theta_dot, theta_ddot, w_dot=None, w_ddot=None) -> np.ndarray:
    """Ë^{wθ}.  Fixed axis: Eq. (5-129), Ë = θ̈ J₃ E − θ̇² J₂ E.  With a moving axis the
    second derivative of (5-122): J̈₁(1 − c) + J̈₃ s + 2θ̇(J̇₁ s + J̇₃ c) + θ̈(−J₂ s + J₃ c)
    − θ̇²(J₂ c + J₃ s), using J̇₂ = −J̇₁."""
    w = check_unit_axis(w, "axis w")
    th, thd, thdd = (
        as_scalar(theta, "theta"),
        as_scalar(theta_dot, "theta_dot"),
        as_scalar(theta_ddot, "theta_ddot"),
    )
    c, s = np.cos(th), np.sin(th)
    j1 = np.outer(w, w)
    j2, j3 = np.eye(3) - j1, skew(w)
    out = thdd * (-j2 * s + j3 * c) - thd**2 * (j2 * c + j3 * s)
    if w_dot is not None or w_ddot is not None:
        wd = np.zeros(3) if w_dot is None else as_vector3(w_dot, "w_dot")
        wdd = np.zeros(3) if w_ddot is None else as_vector3(w_ddot, "w_ddot")
        j1d = np.outer(wd, w) + np.outer(w, wd)
        j1dd = np.outer(wdd, w) + 2.0 * np.outer(wd, wd) + np.outer(w, wdd)
        out = out + j1dd * (1.0 - c) + skew(wdd) * s + 2.0 * thd * (j1d * s + skew(wd) * c)
    return out


@dataclass
class RotatedVectorMotion:
    """Velocity and acceleration of R′ = E^{wθ}(R) about a fixed axis, split into the book's
    terms (all in the fixed frame, already mapped by E), Eq. (5-126) and (5-130):

    * ``velocity = rotation_velocity + stretch_velocity`` = E[θ̇ J₃(R)] + E[Ṙ];
    * ``acceleration = tangential + centripetal + coriolis + relative``
      = E[θ̈ J₃(R)] + E[−θ̇² J₂(R)] + E[2θ̇ J₃(Ṙ)] + E[R̈].
    """

    position: np.ndarray
    velocity: np.ndarray
    rotation_velocity: np.ndarray
    stretch_velocity: np.ndarray
    acceleration: np.ndarray
    tangential: np.ndarray
    centripetal: np.ndarray
    coriolis: np.ndarray
    relative: np.ndarray


def rotated_vector_motion(
    w, theta, theta_dot, theta_ddot, R, R_dot=(0.0, 0.0, 0.0), R_ddot=(0.0, 0.0, 0.0)
) -> RotatedVectorMotion:
    """Position, velocity (5-126) and acceleration (5-130) of R′ = E^{wθ}(R) for a fixed
    axis w, with R(t) given in the rotating frame (Ṙ, R̈ are its rates there).  Vectorised over
    a batch of θ, θ̇, θ̈, R, Ṙ, R̈ of a common leading shape."""
    w = check_unit_axis(w, "axis w")
    R, Rd, Rdd = (as_vector3(v, n) for v, n in ((R, "R"), (R_dot, "R_dot"), (R_ddot, "R_ddot")))
    th = as_angle(theta, "theta")[..., None]
    thd = as_angle(theta_dot, "theta_dot")[..., None]
    thdd = as_angle(theta_ddot, "theta_ddot")[..., None]
    E = rotation_tensor(w, th[..., 0])

    def EE(v):
        return np.einsum("...ij,...j->...i", E, v)

    with np.errstate(over="ignore", invalid="ignore"):
        j3R = np.cross(w, R)
        j2R = R - (R @ w)[..., None] * w if R.ndim > 1 else R - (R @ w) * w
        rot_v = EE(thd * j3R)
        str_v = EE(np.broadcast_to(Rd, rot_v.shape))
        tang = EE(thdd * j3R)
        cent = EE(-(thd**2) * j2R)
        cor = EE(2.0 * thd * np.cross(w, Rd))
        rel = EE(np.broadcast_to(Rdd, tang.shape))
        res = RotatedVectorMotion(
            EE(np.broadcast_to(R, rot_v.shape)),
            rot_v + str_v,
            rot_v,
            str_v,
            tang + cent + cor + rel,
            tang,
            cent,
            cor,
            rel,
        )
    for f in fields(res):  # a rate whose square overflows: a ValueError naming the term
        if not np.all(np.isfinite(getattr(res, f.name))):
            raise ValueError(
                f"{f.name} of the rotated vector cannot be represented in floating point "
                f"(theta_dot = {np.max(np.abs(thd)):.3g}, theta_ddot = {np.max(np.abs(thdd)):.3g}, "
                f"|R| = {np.max(np.abs(R)):.3g}); use smaller rates or other units"
            )
    return res


def component_products(w) -> dict:
    """The J-product table of Eq. (5-118) evaluated for axis w: keys like ``'J1J2'``."""
    j = {1: J1(w), 2: J2(w), 3: J3(w)}
    return {f"J{a}J{b}": j[a] @ j[b] for a in (1, 2, 3) for b in (1, 2, 3)}


# ----------------------------------------------------------------------------- DCM kinematics
def dcm_rate(C, omega, frame: str = "body") -> np.ndarray:
    """Ċ of a direction-cosine matrix C (frame-j → frame-i) rotating with angular velocity ω:
    ``frame='body'``: ω in the moving axes, Ċ = C W, Eq. (5-85);
    ``frame='space'``: ω in the fixed axes, Ċ = W C, Eq. (5-85′)."""
    C = check_rotation(C, "C")
    W = skew(omega)
    if frame == "body":
        return C @ W
    if frame == "space":
        return W @ C
    raise ValueError(f"frame must be 'body' or 'space', got {frame!r}")


def dcm_acc(C, omega, omega_dot, frame: str = "body") -> np.ndarray:
    """C̈ = C(ε + W²) (body, Eq. (5-87)) or (ε + W²)C (space, Eq. (5-87′)), with W = [ω]× and
    ε = [ω̇]× both in the named frame."""
    C = check_rotation(C, "C")
    W, eps = skew(omega), skew(omega_dot)
    if frame == "body":
        return C @ (eps + W @ W)
    if frame == "space":
        return (eps + W @ W) @ C
    raise ValueError(f"frame must be 'body' or 'space', got {frame!r}")


def _finite_matrix(M, name: str) -> np.ndarray:
    a = np.asarray(M, dtype=float)
    if a.ndim < 2 or a.shape[-2:] != (3, 3) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a finite (3, 3) or (N, 3, 3) array, got {a.tolist()}")
    return a


def body_to_space_rate(C, W_body) -> np.ndarray:
    """(W)_i = C (W)_j Cᵀ, Eq. (5-86): the angular-velocity matrix in the fixed axes."""
    C = check_rotation(C, "C")
    return C @ _finite_matrix(W_body, "W_body") @ np.swapaxes(C, -1, -2)


def angular_velocity(C, C_dot, frame: str = "body") -> np.ndarray:
    """ω from C and Ċ: body ω = vee(Cᵀ Ċ) (5-85), space ω = vee(Ċ Cᵀ) (5-85′)."""
    C = check_rotation(C, "C")
    Cd = _finite_matrix(C_dot, "C_dot")
    if frame == "body":
        return unskew(np.swapaxes(C, -1, -2) @ Cd)
    if frame == "space":
        return unskew(Cd @ np.swapaxes(C, -1, -2))
    raise ValueError(f"frame must be 'body' or 'space', got {frame!r}")
