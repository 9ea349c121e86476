"""Hand direction angles (α, β, γ) of an arm, book §6-3, Eq. (6-44)–(6-47), with the sign fix.

From the hanging initial state the hand is turned horizontal (π/2), swung by α in the
horizontal plane, pitched down by β and rolled about its own axis by γ:

    C = C_z(−π/2) C_x(π/2) C_y(α) C_x(−β) C_z(−γ)                                (6-44)

(the book's text labels the last two factors C_z(−β)C_x(−γ), but its printed matrices are
C_x(−β)C_z(−γ)).  The hand points along −z_H = (cos α cos β, sin α cos β, −sin β): α is the
azimuth from +x toward +y, β > 0 pitches downward, γ is the roll.  The product has
element (1,3) = −cos α cos β (minus); the book prints +cos α cos β (non-orthogonal), and its
inverse (6-47) α = tan⁻¹(−c₂₃/c₁₃) then returns −α.  Corrected inverse (cos β > 0):

    α = atan2(−c₂₃, −c₁₃),   β = asin c₃₃,   γ = atan2(−c₃₁, c₃₂).

For an arm, C is the total hand rotation C₁C₂⋯Cₙ (6-45) (h_kl for the 7-DOF arm).
"""

from __future__ import annotations

import numpy as np

from .euler import SINGULAR_TOL, EulerAngles
from .rotations import as_angle, check_rotation, rot_x, rot_y, rot_z


def hand_matrix(alpha, beta, gamma) -> np.ndarray:
    """Hand rotation C(α, β, γ) of Eq. (6-44) (corrected element (1,3) = −cα cβ), i.e. the
    product C_z(−π/2) C_x(π/2) C_y(α) C_x(−β) C_z(−γ).  Vectorised."""
    a, b, g = as_angle(alpha, "alpha"), as_angle(beta, "beta"), as_angle(gamma, "gamma")
    base = rot_z(-np.pi / 2) @ rot_x(np.pi / 2)
    return base @ rot_y(a) @ rot_x(-b) @ rot_z(-g)


def hand_pointing(alpha, beta) -> np.ndarray:
    """Unit pointing direction of the hand, −z_H = (cα cβ, sα cβ, −sβ)."""
    a, b = as_angle(alpha, "alpha"), as_angle(beta, "beta")
    return np.stack(
        [np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), -np.sin(b) * np.ones_like(a)], -1
    )


def hand_angles(C, tol: float = SINGULAR_TOL) -> EulerAngles:
    """(α, β, γ) from the hand rotation C, the corrected Eq. (6-46)/(6-47), β ∈ [−π/2, π/2].

    At cos β = 0 (hand pointing straight up or down) α and γ are not separable: ``singular``
    is True, γ = 0 and α carries the combined rotation."""
    C = check_rotation(C, "C")
    if C.ndim != 2:
        raise ValueError(f"hand_angles takes one (3, 3) matrix, got shape {C.shape}")
    cb = float(np.hypot(C[0, 2], C[1, 2]))
    beta = float(np.arctan2(C[2, 2], cb))
    if cb < tol:
        # β = ±π/2: C_x(∓π/2) C_z(−γ) = C_y(∓γ) C_x(∓π/2), so C = B C_y(α ∓ γ) C_x(−β);
        # with γ = 0, C_y(α) = Bᵀ C C_x(β)
        M = (rot_z(-np.pi / 2) @ rot_x(np.pi / 2)).T @ C @ rot_x(beta)
        alpha = float(np.arctan2(M[0, 2], M[0, 0]))
        return EulerAngles(
            np.array([alpha, beta, 0.0]),
            True,
            f"hand points vertically (cos β = {cb:.2e}): α and γ are coupled; γ set to 0",
        )
    alpha = float(np.arctan2(-C[1, 2], -C[0, 2]))
    gamma = float(np.arctan2(-C[2, 0], C[2, 1]))
    return EulerAngles(np.array([alpha, beta, gamma]), False, "ok")
