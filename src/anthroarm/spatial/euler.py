"""Euler angles: z–x–z (book §5-4, Eq. (5-80)/(5-81)) and X–Y–X (book §8-3, Eq. (8-41)/(8-42)).

Both are *intrinsic* proper-Euler sequences returning the active, new → old rotation
(columns = new axes in the old frame; Pinocchio's ``oMi.rotation``).

* z–x–z (θ, α, δ): rotate about z₁ by θ (x onto the line of nodes), about the new x′ by α
  (z₁ onto z₂), about z₂ by δ:  ``C = C_z(θ) C_x(α) C_z(δ)`` (5-80).
* X–Y–X (θ, ψ, φ): ``R = R_x(θ) R_y(ψ) R_x(φ)`` (8-41)/(8-42) (= scipy ``from_euler('XYX')``).

The inverses report the gimbal-lock singularity (sin α = 0, resp. sin ψ = 0): only the sum
(or difference) of the outer angles is defined there; the result says so in ``status`` and
puts the whole outer rotation into the first angle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .rotations import as_angle, as_scalar, check_rotation, rot_x, rot_y, rot_z

#: |sin(middle angle)| below this counts as gimbal lock
SINGULAR_TOL = 1e-9


@dataclass
class EulerAngles:
    """Result of an Euler-angle inverse.  ``angles`` = (first, middle, last) in rad;
    ``singular`` is True at gimbal lock, where ``status`` explains which combination is defined."""

    angles: np.ndarray
    singular: bool
    status: str

    def __iter__(self):
        return iter(self.angles)


def euler_zxz_partial(theta, alpha) -> np.ndarray:
    """C^{(θ,α)} = C_z(θ) C_x(α), Eq. (5-81)."""
    return rot_z(theta) @ rot_x(alpha)


def euler_zxz(theta, alpha, delta) -> np.ndarray:
    """C^{(θ,α,δ)} = C_z(θ) C_x(α) C_z(δ), Eq. (5-80) (element (3,2) corrected to sin α cos δ;
    the print has sin δ cos δ, see docs/errata.md).  Active, new → old; vectorised."""
    theta, alpha, delta = (
        as_angle(a, n) for a, n in ((theta, "theta"), (alpha, "alpha"), (delta, "delta"))
    )
    ct, st, ca, sa, cd, sd = (
        np.cos(theta),
        np.sin(theta),
        np.cos(alpha),
        np.sin(alpha),
        np.cos(delta),
        np.sin(delta),
    )
    ct, st, ca, sa, cd, sd = np.broadcast_arrays(ct, st, ca, sa, cd, sd)
    return np.stack(
        [
            np.stack([ct * cd - st * ca * sd, -ct * sd - st * ca * cd, st * sa], -1),
            np.stack([st * cd + ct * ca * sd, -st * sd + ct * ca * cd, -ct * sa], -1),
            np.stack([sa * sd, sa * cd, ca], -1),
        ],
        -2,
    )


def euler_zxz_inverse(C, tol: float = SINGULAR_TOL) -> EulerAngles:
    """(θ, α, δ) with α ∈ [0, π] from a rotation matrix, inverting Eq. (5-80):
    α = acos c₃₃, θ = atan2(c₁₃, −c₂₃), δ = atan2(c₃₁, c₃₂).

    At sin α = 0 (z₂ = ±z₁) the line of nodes is undefined: ``singular`` is True, δ = 0 and
    θ carries θ ± δ."""
    C = check_rotation(C, "C")
    if C.ndim != 2:
        raise ValueError(f"euler_zxz_inverse takes one (3, 3) matrix, got shape {C.shape}")
    sa = np.hypot(C[0, 2], C[1, 2])
    alpha = float(np.arctan2(sa, C[2, 2]))
    if sa < tol:
        theta = float(np.arctan2(C[1, 0], C[0, 0]))  # C = Cz(θ + δ) (α = 0) or Cz(θ − δ)Cx(π)
        which = "θ + δ" if C[2, 2] > 0 else "θ − δ"
        return EulerAngles(
            np.array([theta, alpha, 0.0]),
            True,
            f"gimbal lock: sin α = {sa:.2e}; only {which} = {theta:.6g} rad is defined (δ set to "
            "0)",
        )
    theta = float(np.arctan2(C[0, 2], -C[1, 2]))
    delta = float(np.arctan2(C[2, 0], C[2, 1]))
    return EulerAngles(np.array([theta, alpha, delta]), False, "ok")


def euler_xyx(theta, psi, phi) -> np.ndarray:
    """R = R_x(θ) R_y(ψ) R_x(φ) = Θᵀ Ψᵀ Φᵀ, Eq. (8-41)/(8-42): fixed ← body.  Vectorised."""
    return rot_x(theta) @ rot_y(psi) @ rot_x(phi)


def euler_xyx_inverse(R, tol: float = SINGULAR_TOL) -> EulerAngles:
    """(θ, ψ, φ) with ψ ∈ [0, π] from R = R_x(θ) R_y(ψ) R_x(φ):
    ψ = acos r₁₁, θ = atan2(r₂₁, −r₃₁), φ = atan2(r₁₂, r₁₃).

    sin ψ = 0 is the gimbal lock of §8-3 (det Π = −sin ψ, Eq. (8-45)); the zero posture is
    singular.  There ``singular`` is True, φ = 0 and θ carries θ ± φ."""
    R = check_rotation(R, "R")
    if R.ndim != 2:
        raise ValueError(f"euler_xyx_inverse takes one (3, 3) matrix, got shape {R.shape}")
    sp = np.hypot(R[1, 0], R[2, 0])
    psi = float(np.arctan2(sp, R[0, 0]))
    if sp < tol:
        theta = float(np.arctan2(R[2, 1], R[1, 1]))
        which = "θ + φ" if R[0, 0] > 0 else "θ − φ"
        return EulerAngles(
            np.array([theta, psi, 0.0]),
            True,
            f"gimbal lock: sin ψ = {sp:.2e}; only {which} = {theta:.6g} rad is defined (φ set to "
            "0)",
        )
    theta = float(np.arctan2(R[1, 0], -R[2, 0]))
    phi = float(np.arctan2(R[0, 1], R[0, 2]))
    return EulerAngles(np.array([theta, psi, phi]), False, "ok")


def euler_xyx_rate_matrix(psi, phi) -> np.ndarray:
    """Π of Eq. (8-45): body angular velocity ω = Π (θ̇, ψ̇, φ̇)ᵀ for R = R_x(θ)R_y(ψ)R_x(φ).
    det Π = −sin ψ."""
    psi, phi = as_scalar(psi, "psi"), as_scalar(phi, "phi")
    cp, sp, cf, sf = np.cos(psi), np.sin(psi), np.cos(phi), np.sin(phi)
    return np.array([[cp, 0.0, 1.0], [sp * sf, cf, 0.0], [sp * cf, -sf, 0.0]])


def euler_zxz_rate_matrix(alpha, delta) -> np.ndarray:
    """Body angular velocity ω = B (θ̇, α̇, δ̇)ᵀ for C = C_z(θ)C_x(α)C_z(δ) (from Ċ = C W,
    Eq. (5-85)).  det B = −sin α: singular where the inverse is (gimbal lock)."""
    alpha, delta = as_scalar(alpha, "alpha"), as_scalar(delta, "delta")
    ca, sa, cd, sd = np.cos(alpha), np.sin(alpha), np.cos(delta), np.sin(delta)
    return np.array([[sa * sd, cd, 0.0], [sa * cd, -sd, 0.0], [ca, 0.0, 1.0]])
