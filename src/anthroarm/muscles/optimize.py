"""Static optimisation: per frame, the muscle activations that produce given joint torques
with the least Σ aᵢ² (Crowninshield & Brand, *A physiologically based criterion of muscle force
prediction in locomotion*, J Biomech 14 (1981) 793-801; Anderson & Pandy, *Static and dynamic
optimization solutions for gait are practically equivalent*, J Biomech 34 (2001) 153-161), as
OpenSim's ``StaticOptimization`` analysis poses it:

    min Σ aᵢ² + Σ ρₖ²   s.t.   Rᵀ (a ⊙ F_A + F_P) + ρ ⊙ F_R = τ,   0 ≤ a ≤ 1,

with the muscles' forces along the path at an inextensible tendon (the tendon at its slack
length, fibre force–velocity 1: ``Thelen2003Muscle::calcInextensibleTendonActiveFiberForce`` at
rest), F_A the active force per unit activation, F_P the passive force, and reserve actuators ρ
of strength F_R on every coordinate (their torques ρ ⊙ F_R are reported: where they are not
zero the muscles cannot produce τ).  Solved by the QP layer's backends
(:func:`anthroarm.ik.qp.make_backend`).
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


def force_coefficients(muscles, lengths):
    """(F_A, F_P): the active force along the tendon per unit activation and the passive force
    along the tendon (N), inextensible tendon, at rest; ``lengths`` ``(N, M)``."""
    ones = np.ones_like(np.asarray(lengths, dtype=float))
    full = equilibrium(muscles, lengths, ones, rigid_tendon=True)
    c = np.cos(full.pennation_angle)
    # active force at a = 1 (the activation floor does not scale a linear model)
    return full.active_fiber_force * c, full.passive_fiber_force * c


def static_optimization(
    robot,
    muscles=None,
    q=None,
    tau=None,
    *,
    reserve: float = 1.0,
    solver: str = "quadprog",
    wrap: bool = True,
) -> StaticOptimization:
    """Activations minimising Σ a² with Rᵀ f(a) + reserves = ``tau`` per frame (see the module
    docstring).  ``q`` and ``tau`` ``(N, nq)`` (or one frame ``(nq,)``); ``reserve``: the
    strength F_R of each coordinate's reserve actuator (N m per unit reserve activation: small
    values make reserves expensive)."""
    ms = muscle_set(robot, muscles)
    q = robot.check_q(q)
    one = q.ndim == 1
    Q = np.atleast_2d(q)
    T = np.atleast_2d(np.asarray(tau, dtype=float))
    if T.shape != Q.shape or not np.all(np.isfinite(T)):
        raise MuscleError(f"tau must be finite with the shape of q {Q.shape}, got {T.shape}")
    if not (np.isfinite(reserve) and reserve > 0):
        raise MuscleError(f"reserve strength {reserve} must be positive")
    L, R = lengths_and_moment_arms(robot, ms, Q, wrap=wrap)
    FA, FP = force_coefficients(ms, L)
    n, M, nq = Q.shape[0], len(ms), robot.nq
    backend = make_backend(solver, M + nq, nq)
    H = 2.0 * np.eye(M + nq)
    c = np.zeros(M + nq)
    lo = np.concatenate([np.zeros(M), np.full(nq, -BIG)])
    hi = np.concatenate([np.ones(M), np.full(nq, BIG)])
    A = np.zeros((n, M))
    status = []
    for k in range(n):
        Aeq = np.hstack([R[k].T * FA[k], reserve * np.eye(nq)])
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
