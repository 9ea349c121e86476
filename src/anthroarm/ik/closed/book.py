"""The book's own procedure for the prosthetic arm of Fig. 7-2: Eqs. (7-17)–(7-31) with Cramer's
rule for the elbow (Table 7.2), kept as ``aa.ik.analytic(robot, T, method="book")``; the
production path is the general closed form, through which Table 7.2 reproduces.

The printed coefficient A of (7-20)/(7-21) has m2 where m3 is right (docs/errata.md);
``printed_m2=True`` keeps the printed form to show that it fails.
"""

from __future__ import annotations

import numpy as np

from .. import geometric as _geo
from .finish import fk_residual
from .results import AnalyticIKResult


def prosthetic_book_procedure(
    T,
    L1: float = 0.340,
    L2: float = 0.260,
    L3: float = 0.130,
    *,
    det_tol: float = 1e-9,
    printed_m2: bool = False,
):
    """The book's prosthetic-arm IK exactly as printed (corrected), Eqs. (7-17)–(7-31), Fig. 7-3.

    Elbow by Cramer's rule (7-20)/(7-21) (coefficient A with m3, not the printed m2) and the
    quadratic (7-22); θ1 = atan2(yE, xE) (7-18), θ2 = acos(−zE/L1) (7-19), θ4 (7-24),
    θ3 = asin(...) (7-27), θ6 = asin r3 (7-30), θ5 = atan2(r2, r1) (7-31, r2 with −cθ2cθ3).
    Units: whatever ``T`` and the lengths use (the book: mm).  Returns (solutions, reason):
    ``solutions`` a list of two 6-vectors (rad; the two elbow roots, not limit-filtered) or
    empty with ``reason`` ("elbow determinant Δ = 0", "outside workspace", "s2·s4 = 0").
    ``printed_m2=True`` uses the printed numerator "m2/2 (L1² + L3² + L0² − L2²)" of A (a
    misprint, kept to show that it fails; docs/errata.md)."""
    T = np.asarray(T, float)
    l1_, l2_, l3_ = T[:3, 0]
    m1, m2, m3 = T[:3, 1]
    n1, n2, n3 = T[:3, 2]
    x, y, z = T[:3, 3]
    L0s = x * x + y * y + z * z
    K0 = 0.5 * (L1**2 + L3**2 + L0s - L2**2)
    nC = n1 * x + n2 * y + n3 * z
    mC = m1 * x + m2 * y + m3 * z
    Delta = m3 * x - m1 * z + L3 * (m1 * n3 - m3 * n1)
    scale = max(1.0, abs(x) + abs(y) + abs(z))
    if abs(Delta) <= det_tol * scale:
        return [], (
            f"elbow determinant Δ = m3·x − m1·z + L3(m1·n3 − m3·n1) = {Delta:.3g} ≈ 0: "
            "Cramer's rule (7-20)/(7-21) cannot solve the elbow (use the robust solver)"
        )
    A = ((m2 if printed_m2 else m3) * K0 - L3 * m3 * nC - mC * (z - L3 * n3)) / Delta
    B = (m2 * z - m3 * y + L3 * (m3 * n2 - m2 * n3)) / Delta
    Cc = (mC * (x - L3 * n1) + L3 * m1 * nC - m1 * K0) / Delta
    D = (m1 * y - m2 * x + L3 * (m2 * n1 - m1 * n2)) / Delta
    E = B * B + D * D + 1
    F = 2 * (A * B + Cc * D)
    G = A * A + Cc * Cc - L1**2
    disc = F * F - 4 * E * G
    if disc < 0:
        return [], "no elbow position: F² − 4EG < 0 in (7-22)"
    xW, yW, zW = x - L3 * n1, y - L3 * n2, z - L3 * n3
    c4 = (xW**2 + yW**2 + zW**2 - (L1**2 + L2**2)) / (2 * L1 * L2)
    if abs(c4) > 1:
        return [], "outside workspace: |cos θ4| > 1 in (7-24)"
    th4 = np.arccos(c4)
    sols = []
    for sgn in (1.0, -1.0):
        yE = (-F + sgn * np.sqrt(disc)) / (2 * E)
        xE, zE = A + B * yE, Cc + D * yE
        th1 = np.arctan2(yE, xE)
        th2 = np.arccos(np.clip(-zE / L1, -1, 1))
        c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
        s4 = np.sin(th4)
        if abs(s2 * s4) < 1e-12:
            return [], "singular: s2·s4 = 0 in (7-27) (arm vertical or straight)"
        th3 = np.arcsin(np.clip((zW + L2 * c2 * c4 + L1 * c2) / (L2 * s2 * s4), -1, 1))
        c3, s3 = np.cos(th3), np.sin(th3)
        P1 = l1_ * c1 + l2_ * s1
        Q1 = l1_ * s1 - l2_ * c1
        r1 = P1 * (s2 * s4 - c2 * s3 * c4) - l3_ * (s2 * s3 * c4 + c2 * s4) + c3 * c4 * Q1
        r2 = -c2 * c3 * P1 - l3_ * s2 * c3 - s3 * Q1
        r3 = P1 * (c2 * s3 * s4 + s2 * c4) + l3_ * (s2 * s3 * s4 - c2 * c4) - c3 * s4 * Q1
        th6 = np.arcsin(np.clip(r3, -1, 1))
        th5 = np.arctan2(r2, r1)
        sols.append(np.array([th1, th2, th3, th4, th5, th6]))
    return sols, None


def book_result(robot, T, prm, tol):
    sols, reason = prosthetic_book_procedure(T, prm["L1"], prm["L2"], prm["L3"])
    if not sols:
        return AnalyticIKResult(np.zeros((0, robot.nq)), [], reason, model=robot.name)
    Q = np.array(sols)
    Qw, inside = _geo.wrap_into_limits(Q, robot.lower, robot.upper)
    res = fk_residual(robot, Qw[None], T[None], False)[0]
    ok = inside & (res <= tol)
    labels = ["elbow_root=+", "elbow_root=-"]
    if not ok.any():
        why = (
            "the book's asin-based θ3/θ6 (7-27)/(7-30) give no FK-consistent solution inside the limits "
            f"(residuals {', '.join(f'{r:.3g}' for r in res)}); use method='robust'"
        )
        return AnalyticIKResult(
            np.zeros((0, robot.nq)), [], why, residuals=np.zeros(0), model=robot.name
        )
    return AnalyticIKResult(
        Qw[ok], [lb for lb, k in zip(labels, ok) if k], None, residuals=res[ok], model=robot.name
    )
