"""The damped Gauss–Newton (Levenberg–Marquardt) step of :func:`anthroarm.ik.solve` in NumPy,
for the lockstep batch (a leading batch axis) and the null-space phases
(:mod:`anthroarm.ik.solve.nullspace`, which reuse the factorisation), the one-target attempt
over any workspace (:func:`attempt`: a model whose kinematics are not a serial chain's, an
OpenSim model with couplings, :mod:`.coupled`), and the constants of the compiled attempt on a
chain (:mod:`.lm`)::

    Δθ = Jᵀ (J Jᵀ + λ I)⁻¹ e = (JᵀJ + λ I)⁻¹ Jᵀe,   λ = λ₀ + k ‖e‖²   (Sugihara 2011 damping),
    θ ← clip(θ + Δθ, θ_min, θ_max).

This is the book's feedback-compensation Newton step Δq = J⁻¹ e (Ch. 7 §7-5) made robust: the
damping blends toward the steepest-descent direction Jᵀe of §7-6 (A9) when the error is large
or J is singular and vanishes near the solution (quadratic convergence).  Joint ranges (the
penalty constraints g_i(Q) ≥ 0 of (7-84)–(7-85)) are enforced exactly by an active set: a
joint whose step would cross its limit is frozen for that step (its column of J zeroed) and the
step recomputed with the others, then clipped.

θ is the vector of the independent joints' positions in Pinocchio's v order (rad or m); a
continuous joint's angle is unbounded (its limits are ±inf), so iterating in θ and mapping to
(cos θ, sin θ) only for Pinocchio integrates on the circle (θ ⊕ Δθ = θ + Δθ).  Columns of joints
off the frame's path are zero: those joints keep their seed values.

Written for the cost of each call from Python (~0.1–0.5 µs per NumPy or Pinocchio call at these
sizes): J Jᵀ + λI is built in a preallocated array of the calling thread's workspace and
factorised in place by LAPACK ``dposv``; limit hits are detected by comparing bytes.
"""

from __future__ import annotations

import gc
import math
import threading
import time

import numpy as np
from scipy.linalg.lapack import dposv


def clip(x, lo, hi):
    """x clipped to [lo, hi] elementwise: two ufunc calls (~0.4 µs for 7 joints), not
    ``np.clip``'s Python wrapper (~1.3 µs) nor NumPy's private ``_core.umath.clip``."""
    return np.minimum(np.maximum(x, lo), hi)


LAMBDA0 = 1e-10  # floor of the damping (keeps JJᵀ + λI positive definite at singularities)
K_DAMP = 0.01  # λ grows with the squared error: large errors -> short, gradient-like steps
MAX_ITER = 60  # iterations per attempt (before the stall test ends it earlier)
STALL = 3  # an attempt ends after STALL iterations without a 10 % error decrease


class _GcTime(threading.local):
    """Per thread: when its current collection began, and the CPU time spent in collections."""

    began = 0.0
    spent = 0.0


_gc = _GcTime()


def _on_gc(phase, info, _now=time.thread_time) -> None:
    """``gc.callbacks`` hook: adds each collection's CPU time to the collecting thread's total."""
    if phase == "start":
        _gc.began = _now()
    else:
        _gc.spent += _now() - _gc.began


gc.callbacks.append(_on_gc)


def clock(_now=time.thread_time) -> float:
    """The clock of the budget ``max_time``: CPU time of the calling thread less the time it
    spent in Python's garbage collector.

    Not wall-clock time: on a busy machine a wall-clock budget turns into failures that depend on
    the load; with a CPU-time budget (and the fixed restart seed) the same call gives the same
    answer.  Not the collector either: a full collection is charged to whichever thread's
    allocation triggered it, and in a session that has imported OpenSim, Dask and Matplotlib one
    takes ~90 ms (2-core EPYC), more than the default 50 ms budget of a solve that needs 1 ms —
    a target solved in one run failed in the next (CI, test_ik_solve_any_robot[z1]).  The
    collector's time is measured through ``gc.callbacks`` (public; ~1 µs per collection)."""
    return _now() - _gc.spent


def damping(E):
    """λ = λ₀ + k ‖e‖² (float, or (N,) for a batch of ‖e‖²)."""
    return LAMBDA0 + K_DAMP * E


def solve_damped(ws, J, e, lam, step=True):
    """The damped least-squares step Δθ = Jᵀ(JJᵀ + λI)⁻¹e = (JᵀJ + λI)⁻¹Jᵀe (equal by the
    push-through identity), or with ``step=False`` x = (JJᵀ + λI)⁻¹e itself; None where the
    system is not positive definite (NaN/inf).

    One target (J (m, n), e (m,), λ float): the m × m system is built in ``ws.lin[m]`` and
    factorised in place by LAPACK ``dposv``; its Cholesky factor stays in ``ws.lin[m][1]`` for
    null-space projections (``dpotrs``) until the next call.  Where the arm has fewer joints
    than the task (n < m: JJᵀ is singular and its form would lose digits) the step is solved in
    the n × n form.  A batch (J (N, m, n), e (N, m), λ (N,)): ``np.linalg.solve``."""
    if J.ndim == 2:
        m = len(J)
        if m <= ws.n or not step:
            A, AF, Ad = ws.lin[m]
            J.dot(J.T, out=A)  # the method: np.dot goes through a Python dispatcher
            Ad += lam  # the diagonal of A (a view)
            x, info = dposv(AF, e, overwrite_a=1)[1:]
            return None if info else (x.dot(J) if step else x)
        A, AF, Ad = ws.lin[ws.n]
        J.T.dot(J, out=A)
        Ad += lam
        dq, info = dposv(AF, e.dot(J), overwrite_a=1)[1:]
        return None if info else dq
    N, m, n = J.shape
    Jt = J.transpose(0, 2, 1)
    rhs = e
    if m <= n:
        A = np.matmul(J, Jt)
    else:
        A = np.matmul(Jt, J)
        rhs = np.matmul(e[:, None, :], J)[:, 0]
    A.reshape(N, -1)[:, :: A.shape[1] + 1] += lam[:, None]
    try:
        x = np.linalg.solve(A, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return None
    return np.matmul(x[:, None, :], J)[:, 0] if m <= n else x


def damped_step(ws, th, J, e, lam):
    """θ after one damped step with the joint limits (see the module docstring); θ (n,) with
    J (m, n), e (m,), λ float — or a batch with a leading axis N.  None where the system is not
    positive definite."""
    dq = solve_damped(ws, J, e, lam)
    if dq is None:
        return None
    lo, hi = ws.lo, ws.hi
    tn = th + dq
    tc = clip(tn, lo, hi)
    if tc.tobytes() != tn.tobytes():  # (byte comparison: ~20× cheaper than (tc != tn).any())
        # active set: the joints the step pushes past a limit stay where they are, the others
        # take the step recomputed without them, then it is clipped
        dq = solve_damped(ws, J * (tc == tn)[..., None, :], e, lam)
        if dq is not None:
            tc = clip(th + dq, lo, hi)
    return tc


def attempt(ws, tg, th, deadline):
    """Damped Gauss–Newton from θ until the target's tolerances are met, the error stops
    falling by 10 % for :data:`STALL` iterations, :data:`MAX_ITER` or the deadline, on any
    workspace ``ws`` whose target ``tg`` gives the residual and Jacobian (the chains' compiled
    form is :func:`.lm.attempt`, the same iteration).

    Returns (θ, converged, iterations, pos_err², rot_err², best θ, best ‖e‖²): the last iterate
    with its squared errors, and the iterate of least ‖e‖² seen."""
    ref_E = best_E = math.inf
    best = th
    stall = it = 0
    pe2 = re2 = 0.0
    tp2, tr2 = tg.tp2, tg.tr2
    residual, jacobian = tg.residual, tg.jacobian
    while it < MAX_ITER:
        it += 1
        e, E, pe2, re2 = residual(ws, th)
        if pe2 <= tp2 and re2 <= tr2:
            return th, True, it, pe2, re2, th, E
        if E < best_E:
            best_E, best = E, th
        if E < 0.9 * ref_E:
            ref_E, stall = E, 0
        else:
            stall += 1
            if stall >= STALL:
                break
        if not it & 7 and clock() > deadline:  # every 8th iteration: the CPU clock costs ~1 µs
            break
        tn = damped_step(ws, th, jacobian(ws), e, LAMBDA0 + K_DAMP * E)
        if tn is None:
            break
        th = tn
    return th, False, it, pe2, re2, best, best_E
