"""Screw matrices and the velocity / acceleration matrices of the 002 text, §4-1 (Suh–Radcliffe).

Notation of the 002 text (column vectors, fixed frame, active):

* [P_u] = skew(u) (u × r = [P_u] r), [Q_u] = u uᵀ;
* [R_{θ,u}] = −[P_u]² cos θ + [P_u] sin θ + [Q_u], the finite rotation by θ about the unit
  axis u (line 185 of 002; identical to Rodrigues / the rotation tensor E^{uθ} of §5-5);
* the screw matrix (4-6), reconstructed (the print lost a sign and a row): rotation φ about and
  slide s along the axis u through the point p,

      [S_{φ,s,u,p}] = [[R_{φ,u}, s u + (I − R_{φ,u}) p], [0, 1]],   (q; 1) = [S] (q₁; 1);

* the velocity matrix [W_{φ̇,u}] = φ̇ [P_u] (line 92), with q̇ − ṗ = [W](q − p);
* the acceleration matrix [E_{φ̇,φ̈,u}] = φ̈ [P_u] + φ̇ [Ṗ_u] + φ̇² [P_u]² (= Ẇ + W², from (4-28)).

Lengths in m, angles in rad.  A screw matrix equals ``pin.exp6(Motion(v, ω))`` with
ω = φ u and v = s u − φ u × p (see :func:`screw_twist`).
"""

from __future__ import annotations

import numpy as np

from .rotations import (
    as_angle,
    as_scalar,
    as_vector3,
    axis_angle,
    check_rotation,
    check_unit_axis,
    skew,
    unskew,
)


def P(u) -> np.ndarray:
    """[P_u] = skew(u) (002 §4-1); u must be unit."""
    return skew(check_unit_axis(u, "axis u"))


def Q(u) -> np.ndarray:
    """[Q_u] = u uᵀ (002 §4-1); u must be unit."""
    u = check_unit_axis(u, "axis u")
    return u[..., :, None] * u[..., None, :]


def rotation_matrix(theta, u) -> np.ndarray:
    """[R_{θ,u}] = −[P_u]² cos θ + [P_u] sin θ + [Q_u] (002 §4-1, line 185).  Vectorised in θ."""
    u = check_unit_axis(u, "axis u")
    th = as_angle(theta, "theta")
    Pu = skew(u)
    c, s = np.cos(th)[..., None, None], np.sin(th)[..., None, None]
    return -(Pu @ Pu) * c + Pu * s + u[:, None] * u[None, :]


def screw_matrix(phi, s, u, p) -> np.ndarray:
    """Screw matrix [S_{φ,s,u,p}] of 002 Eq. (4-6) (reconstructed): rotation φ about, and slide
    s along, the unit axis u through point p.  4×4 homogeneous, active, fixed frame."""
    u = check_unit_axis(u, "axis u")
    p = as_vector3(p, "point p")
    R = rotation_matrix(phi, u)
    s = as_angle(s, "slide s")
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = s[..., None] * u + p - np.einsum("...ij,j->...i", R, p)
    T[..., 3, 3] = 1.0
    return T


def screw_twist(phi, s, u, p) -> np.ndarray:
    """Twist (v; ω) (Pinocchio order, fixed frame) whose exponential is [S_{φ,s,u,p}]:
    ω = φ u, v = s u − φ u × p = s u + p × ω."""
    u = check_unit_axis(u, "axis u")
    p = as_vector3(p, "point p")
    phi, s = as_scalar(phi, "phi"), as_scalar(s, "slide s")
    return np.concatenate([s * u - phi * np.cross(u, p), phi * u])


def screw_parameters(T, tol: float = 1e-10) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Inverse of :func:`screw_matrix` (Chasles): (φ ∈ [0, π], s, u, p) with p the foot of the
    perpendicular from the origin to the axis.  A pure translation returns φ = 0, u = its
    direction and p = 0; the identity returns (0, 0, (0, 0, 1), 0)."""
    T = np.asarray(T, float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ValueError(
            f"T must be a finite 4x4 matrix, got {T.tolist() if T.size <= 16 else T.shape}"
        )
    R = check_rotation(T[:3, :3], "T[:3,:3]")
    t = T[:3, 3]
    u, phi = axis_angle(R)
    if phi < tol:
        n = np.linalg.norm(t)
        if n < tol:
            return 0.0, 0.0, np.array([0.0, 0.0, 1.0]), np.zeros(3)
        return 0.0, float(n), t / n, np.zeros(3)
    s = float(u @ t)
    # (I − R) p = t − s u, with p ⟂ u: solve in the plane ⟂ u
    A = np.eye(3) - R + np.outer(u, u)
    p = np.linalg.solve(A, t - s * u)
    return float(phi), s, u, p


def velocity_matrix(phi_dot, u) -> np.ndarray:
    """[W_{φ̇,u}] = φ̇ [P_u] (002 line 92): q̇ − ṗ = [W](q − p) for a point q of a body turning at
    φ̇ about the axis u through p (= Ṙ Rᵀ)."""
    return as_scalar(phi_dot, "phi_dot") * P(u)


def acceleration_matrix(phi_dot, phi_ddot, u, u_dot=None) -> np.ndarray:
    """[E_{φ̇,φ̈,u}] = φ̈ [P_u] + φ̇ [Ṗ_u] + φ̇² [P_u]² (002 (4-28); = Ẇ + W²): q̈ − p̈ = [E](q − p).
    ``u_dot`` (default 0: fixed axis) gives the [Ṗ_u] term."""
    Pu = P(u)
    phi_dot, phi_ddot = as_scalar(phi_dot, "phi_dot"), as_scalar(phi_ddot, "phi_ddot")
    E = phi_ddot * Pu + phi_dot**2 * (Pu @ Pu)
    if u_dot is not None:
        E = E + phi_dot * skew(as_vector3(u_dot, "u_dot"))
    return E


def angular_velocity_of(W) -> np.ndarray:
    """The vector ω of a velocity matrix [W] = [ω]×."""
    return unskew(W)
