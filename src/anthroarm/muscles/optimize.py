"""Static optimisation: per frame, the muscle activations that produce given joint torques
with the least Σ aᵢ² (Crowninshield & Brand, *A physiologically based criterion of muscle force
prediction in locomotion*, J Biomech 14 (1981) 793-801; Anderson & Pandy, *Static and dynamic
optimization solutions for gait are practically equivalent*, J Biomech 34 (2001) 153-161), as
OpenSim's ``StaticOptimization`` analysis poses it:

    min Σ aᵢ² + Σ ρₖ²   s.t.   Rᵀ (a ⊙ F_A + F_P) + ρ ⊙ F_R = τ,   0 ≤ a ≤ 1,

with the muscles' forces along the path at an inextensible tendon (the tendon at its slack
length: ``Thelen2003Muscle::calcInextensibleTendonActiveFiberForce``), F_A the active force per
unit activation, F_P the passive force, and reserve actuators ρ of strength F_R on every
coordinate (their torques ρ ⊙ F_R are reported: where they are not zero the muscles cannot
produce τ).  Solved by the QP layer's backends (:func:`anthroarm.ik.qp.make_backend`).

Without joint velocities the fibres are at rest (force–velocity multiplier 1).  With them
(``qd``), the fibre velocity of the inextensible tendon is v = L̇ cos φ with L̇ = −r(q)·q̇
(``MuscleFixedWidthPennationModel::calcFiberVelocity``), and F_A carries Thelen's force–velocity
multiplier f_V at full activation (Thelen 2003, Eqs. 6-7, with OpenSim's linear extrapolation
beyond ``fv_linear_extrap_threshold`` and below zero force: :func:`thelen_force_velocity`),
as OpenSim's ``StaticOptimization`` with ``use_muscle_physiology`` does.  OpenSim's analysis
overrides each muscle's whole force with a F_A (its actuation), so it has no passive force:
``passive=False`` poses that problem.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MuscleError
from ..ik.qp import make_backend
from .hill import equilibrium
from .paths import lengths_and_moment_arms, muscle_set

#: a finite stand-in for an unbounded reserve activation
BIG = 1e20


@dataclass(frozen=True)
class StaticOptimization:
    """Result per frame (arrays ``(N, ...)``): activations ``(N, M)``, muscle forces along
    the path ``(N, M)``, muscle torques ``(N, nq)``, reserve torques ``(N, nq)``, solver status
    per frame, and the moment arms used ``(N, M, nq)``."""

    activation: np.ndarray
    force: np.ndarray
    muscle_torque: np.ndarray
    reserve_torque: np.ndarray
    status: list
    moment_arms: np.ndarray


def thelen_force_velocity(v_norm, af=0.3, flen=1.8, threshold=0.95):
    """Thelen's force–velocity multiplier f_V at full activation (a = 1) for the normalised
    fibre velocity ``v_norm`` = v / (l₀ v_max) (lengthening positive): Eq. 6 of Thelen 2003
    solved for the force (Eq. 7's b), concentric f_V = (1 + v) / (1 − v / A_f) down to zero
    force at v = −1 (0 below, as ``Thelen2003Muscle::calcfvInv`` clamps), eccentric
    f_V = (1 + v k F_len) / (1 + v k) with k = (2 + 2/A_f) / (F_len − 1) up to
    ``threshold`` · F_len, linear beyond it (``Thelen2003Muscle::calcdlceN``'s extrapolation).
    Thelen, J Biomech Eng 125 (2003) 70-77."""
    v = np.asarray(v_norm, dtype=float)
    af, flen, threshold = (np.asarray(x, dtype=float) for x in (af, flen, threshold))
    k = (2.0 + 2.0 / af) / (flen - 1.0)
    fm0 = threshold * flen  # the last force on the curve (f_L = a = 1)
    b0 = k * (flen - fm0)
    v0 = (fm0 - 1.0) / b0  # its velocity, and dv/dFm there
    slope = 1.0 / b0 + (fm0 - 1.0) * k / (b0 * b0)
    with np.errstate(divide="ignore", invalid="ignore"):
        conc = (1.0 + v) / (1.0 - v / af)
        ecc = np.where(v < v0, (1.0 + v * k * flen) / (1.0 + v * k), fm0 + (v - v0) / slope)
    return np.where(v <= -1.0, 0.0, np.where(v <= 0.0, conc, ecc))


def force_coefficients(muscles, lengths, velocities=None):
    """(F_A, F_P): the active force along the tendon per unit activation and the passive force
    along the tendon (N), inextensible tendon; ``lengths`` ``(N, M)``.  ``velocities``: the
    musculotendon lengthening speeds L̇ ``(N, M)`` (m/s; None: at rest), which scale F_A by
    Thelen's f_V (:func:`thelen_force_velocity`, Thelen2003 muscles only)."""
    ones = np.ones_like(np.asarray(lengths, dtype=float))
    full = equilibrium(muscles, lengths, ones, rigid_tendon=True)
    c = np.cos(full.pennation_angle)
    # active force at a = 1 (the activation floor does not scale a linear model)
    fa, fp = full.active_fiber_force * c, full.passive_fiber_force * c
    if velocities is None:
        return fa, fp
    V = np.broadcast_to(np.asarray(velocities, dtype=float), fa.shape)
    if not np.all(np.isfinite(V)):
        raise MuscleError("musculotendon velocities must be finite")
    ms = muscles.muscles
    other = [m.name for m in ms if m.type != "Thelen2003Muscle"]
    if other:
        raise MuscleError(f"force-velocity is evaluated for Thelen2003 muscles only, not {other}")
    vmax = np.array([m.max_contraction_velocity * m.optimal_fiber_length for m in ms])
    par = {k: np.array([m.params[k] for m in ms]) for k in ("Af", "Flen")}
    thr = np.array([m.params.get("fv_linear_extrap_threshold", 0.95) for m in ms])
    fv = thelen_force_velocity(V * c / vmax, par["Af"], par["Flen"], thr)
    return fa * fv, fp


def static_optimization(
    robot,
    muscles=None,
    q=None,
    tau=None,
    *,
    reserve=1.0,
    solver: str = "quadprog",
    wrap: bool = True,
    qd=None,
    passive: bool = True,
    lower=0.0,
) -> StaticOptimization:
    """Activations minimising Σ a² with Rᵀ f(a) + reserves = ``tau`` per frame (see the module
    docstring).  ``q`` and ``tau`` ``(N, nq)`` (or one frame ``(nq,)``); ``reserve``: the
    strength F_R of each coordinate's reserve actuator (N m or N per unit reserve activation:
    small values make reserves expensive), one number or one per coordinate ``(nq,)``;
    ``qd``: joint velocities like ``q`` (the muscles' force–velocity; None: at rest);
    ``passive``: include the passive fibre forces (OpenSim's ``StaticOptimization`` does not);
    ``lower``: the activations' lower bound, one or one per muscle ``(M,)`` in [0, 1)
    (OpenSim's is each muscle's ``min_control``, a Thelen2003Muscle's ``minimum_activation``,
    0.01 by default)."""
    ms = muscle_set(robot, muscles)
    q = robot.check_q(q)
    one = q.ndim == 1
    Q = np.atleast_2d(q)
    T = np.atleast_2d(np.asarray(tau, dtype=float))
    if T.shape != Q.shape or not np.all(np.isfinite(T)):
        raise MuscleError(f"tau must be finite with the shape of q {Q.shape}, got {T.shape}")
    n, M, nq = Q.shape[0], len(ms), robot.nq
    res = np.asarray(reserve, dtype=float)
    if res.shape not in ((), (nq,)) or not np.all(np.isfinite(res) & (res > 0)):
        raise MuscleError(f"reserve strengths {reserve} must be positive, one or {nq}")
    res = np.broadcast_to(res, (nq,))
    low = np.asarray(lower, dtype=float)
    if low.shape not in ((), (M,)) or not np.all(np.isfinite(low) & (low >= 0) & (low < 1)):
        raise MuscleError(f"activation lower bounds {lower} must be in [0, 1), one or {M}")
    L, R = lengths_and_moment_arms(robot, ms, Q, wrap=wrap)
    V = None
    if qd is not None:
        QD = np.atleast_2d(np.asarray(qd, dtype=float))
        if QD.shape != Q.shape or not np.all(np.isfinite(QD)):
            raise MuscleError(f"qd must be finite with the shape of q {Q.shape}, got {QD.shape}")
        V = -np.einsum("nmk,nk->nm", R, QD)  # L̇ = (∂L/∂q) q̇ = −R q̇
    FA, FP = force_coefficients(ms, L, V)
    if not passive:
        FP = np.zeros_like(FP)
    backend = make_backend(solver, M + nq, nq)
    H = 2.0 * np.eye(M + nq)
    c = np.zeros(M + nq)
    lo = np.concatenate([np.broadcast_to(low, (M,)), np.full(nq, -BIG)])
    hi = np.concatenate([np.ones(M), np.full(nq, BIG)])
    A = np.zeros((n, M))
    status = []
    for k in range(n):
        Aeq = np.hstack([R[k].T * FA[k], np.diag(res)])
        b = T[k] - R[k].T @ FP[k]
        x, st = backend.solve(H, c, lo, hi, Aeq, b)
        status.append(st)
        A[k] = np.nan if x is None else x[:M]
    A = np.where(np.isfinite(A), A, 0.0)
    F = A * FA + FP
    mt = np.einsum("nmk,nm->nk", R, F)
    out = StaticOptimization(A, F, mt, T - mt, status, R)
    if one:
        return StaticOptimization(A[0], F[0], mt[0], (T - mt)[0], status, R[0])
    return out
