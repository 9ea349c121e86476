"""The book's iterative inverse-kinematics methods (Ch. 7 §7-4 二, §7-5, §7-6).

Every method works on a *task*: an object with ``error(q)`` → δr (m, the target minus the
current value, (7-66)) and ``jacobian(q)`` → J (m × n) with δr(q + dq) ≈ δr − J dq, plus
``value(q)`` (r = F(q), (7-50)) and, for tracking, ``jacobian_dot(q, qd)`` (K = J̇, (7-51)).
:class:`PositionTask` (selected components of a frame position, world axes) and
:class:`PoseTask` (position and orientation, LOCAL_WORLD_ALIGNED) build them from a Robot
with Pinocchio.

* :func:`newton` — feedback compensation for a static target (ṙ* = 0, q̇ = 0, so K drops out):
  Q ← Q + P⁻¹ δR, Eqs. (7-55)–(7-57), i.e. Newton–Raphson q ← q + J⁻¹ δr.
* :func:`feedback_compensation` — tracking r*(t): predictor (7-52)/(7-53) and Newton corrector
  on (q, q̇) with P = [[J, 0], [K, J]] (7-55)–(7-57), Fig. 7-11; ``K="book_zero"`` uses the
  book's K ≡ 0 (7-65), which is false (see :mod:`anthroarm.ik.book_jacobians`).
* :func:`steepest_descent` — f = δRᵀδR (7-71), p = 2PᵀδR (7-74), step ω1 =
  pᵀp / (2 pᵀPᵀPp) (7-82): one Newton step of the line function from ω = 0.
* :func:`conjugate_direction` — Fletcher–Reeves (7-83) with the same ω1 estimate and restarts.
* :func:`penalty_minimize` — exterior penalty φ = f + μ Σ min(0, g_i)² (7-84)–(7-86), minimised
  by steepest descent or Fletcher–Reeves on the stacked residual.
* :func:`gradual_approach` — (7-33)–(7-49): the Cartesian error is made to follow c·μ(t),
  μ(0) = 1, μ(∞) = 0, by joint increments δq = J⁻¹ u δx with u = diag(1 − μ(t+Δt)/μ(t)).

For a static target with q̇ = 0 the book's (q, q̇) formulation reduces to q alone (K = 0 when
q̇ = 0 and the q̇ part of the gradient vanishes), which is what these functions iterate.
Units: SI (m, rad).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin


# ---------------------------------------------------------------------------- tasks
class PositionTask:
    """r = selected components ``rows`` of the position (m, world axes) of ``frame``.

    ``target`` (len(rows),) is r*.  For the planar mechanism of Fig. 7-14 use rows (1, 2):
    r = (y, z)."""

    def __init__(self, robot, target, rows=(0, 1, 2), frame=None):
        self.robot = robot
        self.rows = list(rows)
        self.fid = robot.frame_id(frame)
        self.target = np.asarray(target, float)
        if self.target.shape != (len(self.rows),) or not np.isfinite(self.target).all():
            raise ValueError(
                f"target must be finite with shape ({len(self.rows)},), got {target!r}"
            )

    def value(self, q):
        return self.robot.fk(q, self.fid)[self.rows, 3]

    def error(self, q):
        return self.target - self.value(q)

    def jacobian(self, q):
        return self.robot.jacobian(q, self.fid)[self.rows]

    def jacobian_dot(self, q, qd):
        r = self.robot
        pin.computeJointJacobiansTimeVariation(
            r.model, r.data, np.asarray(q, float), np.asarray(qd, float)
        )
        pin.updateFramePlacements(r.model, r.data)
        dJ = pin.getFrameJacobianTimeVariation(
            r.model, r.data, self.fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        return dJ[self.rows]


class PoseTask:
    """Full pose of ``frame``: δr = (p* − p; log3(R* Rᵀ)) (m; rad, world axes), J = the
    LOCAL_WORLD_ALIGNED frame Jacobian (exact for the position rows, first order for the
    rotation rows)."""

    def __init__(self, robot, target, frame=None):
        self.robot = robot
        self.fid = robot.frame_id(frame)
        T = np.asarray(target, float)
        if T.shape != (4, 4) or not np.isfinite(T).all():
            raise ValueError(f"target must be a finite 4x4 pose, got shape {T.shape}")
        self.target = T

    def value(self, q):
        return self.robot.fk(q, self.fid)

    def error(self, q):
        T = self.value(q)
        return np.concatenate(
            [self.target[:3, 3] - T[:3, 3], pin.log3(self.target[:3, :3] @ T[:3, :3].T)]
        )

    def jacobian(self, q):
        return self.robot.jacobian(q, self.fid)


# ---------------------------------------------------------------------------- results
@dataclass
class IterResult:
    """``q`` final joints; ``iterates`` (k+1, n) including the start; ``errors`` ‖δr‖ per iterate;
    ``success`` ‖δr‖ ≤ tol; ``status`` a word: converged | max_iter | singular | stalled | diverged."""

    q: np.ndarray
    iterates: np.ndarray
    errors: np.ndarray
    success: bool
    status: str
    steps: list = field(default_factory=list)

    @property
    def iterations(self) -> int:
        return len(self.iterates) - 1


def _check_q0(q0, n=None):
    q = np.asarray(q0, float).copy()
    if q.ndim != 1 or not np.isfinite(q).all() or (n is not None and q.shape[0] != n):
        raise ValueError(
            f"q0 must be a finite vector{'' if n is None else f' of length {n}'}, got {q0!r}"
        )
    return q


def _finish(q, its, errs, tol, status, steps=()):
    ok = errs[-1] <= tol
    return IterResult(
        q, np.array(its), np.array(errs), bool(ok), "converged" if ok else status, list(steps)
    )


# ---------------------------------------------------------------------------- Newton / feedback compensation
def newton(task, q0, *, tol: float = 1e-10, max_iter: int = 50) -> IterResult:
    """Feedback compensation for a static target: q ← q + J⁻¹ δr (7-55)/(7-57) with q̇ = 0.

    Square J is inverted as in the book (status "singular" if it is singular); a non-square J
    uses least squares (the book restricts itself to n ≤ 6 and square J)."""
    q = _check_q0(q0)
    its, errs = [q.copy()], [float(np.linalg.norm(task.error(q)))]
    for _ in range(max_iter):
        e = task.error(q)
        if np.linalg.norm(e) <= tol:
            break
        J = task.jacobian(q)
        if J.shape[0] == J.shape[1]:
            if abs(np.linalg.det(J)) < 1e-12:
                return _finish(q, its, errs, tol, "singular")
            dq = np.linalg.solve(J, e)
        else:
            dq = np.linalg.lstsq(J, e, rcond=None)[0]
        q = q + dq
        its.append(q.copy())
        errs.append(float(np.linalg.norm(task.error(q))))
    return _finish(q, its, errs, tol, "max_iter")


@dataclass
class TrackingResult:
    """``t`` (NUM+1,), ``q``/``qd`` (NUM+1, n), ``err`` ‖δR‖ after correction per sample,
    ``err_predicted`` ‖δR‖ after the predictor (before correction), ``corrections`` Newton
    steps per sample, ``success`` every sample within ``eps``."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    err: np.ndarray
    err_predicted: np.ndarray
    corrections: np.ndarray
    success: bool


def feedback_compensation(
    task,
    reference,
    q0,
    qd0,
    dt: float,
    num: int,
    *,
    eps: float = 1e-9,
    max_corrections: int = 20,
    K: str = "exact",
) -> TrackingResult:
    """Track r*(t) by the feedback-compensation method, Fig. 7-11 / Eqs. (7-52)–(7-57).

    ``reference(t) -> (r*, ṙ*, r̈*)``.  For k = 0 … num−1: q̈ = J⁻¹(r̈* − K q̇) (7-52), predict
    (7-53), then correct Q = (q, q̇) by Q ← Q + P⁻¹ δR with P = [[J, 0], [K, J]] and
    δR = (r* − F(q), ṙ* − J q̇) (7-55)–(7-57, 7-66) until ‖δR‖ ≤ ``eps`` (at most
    ``max_corrections``; 0 disables the compensation: open-loop integration).
    ``K="exact"`` uses J̇ (``task.jacobian_dot``); ``K="book_zero"`` the book's K ≡ 0."""
    if K not in ("exact", "book_zero"):
        raise ValueError(f"K must be 'exact' or 'book_zero', got {K!r}")
    if not (0 < dt < np.inf and num >= 1):
        raise ValueError(f"need a finite dt > 0 and num >= 1, got dt={dt}, num={num}")
    q = _check_q0(q0)
    qd = _check_q0(qd0, q.shape[0])
    n = q.shape[0]

    def Kmat(q, qd):
        return task.jacobian_dot(q, qd) if K == "exact" else np.zeros((len(task.error(q)), n))

    def dR(q, qd, t):
        r, rd, _ = reference(t)
        task.target = np.asarray(r, float)
        return np.concatenate([task.error(q), np.asarray(rd, float) - task.jacobian(q) @ qd])

    ts = [0.0]
    Q, QD = [q.copy()], [qd.copy()]
    errs, pred, corr = [float(np.linalg.norm(dR(q, qd, 0.0)))], [0.0], [0]
    for k in range(num):
        t = k * dt
        _, _, rdd = reference(t)
        J = task.jacobian(q)
        qdd = np.linalg.solve(J, np.asarray(rdd, float) - Kmat(q, qd) @ qd)  # (7-52)
        q = q + qd * dt + 0.5 * qdd * dt * dt  # (7-53)
        qd = qd + qdd * dt
        t1 = t + dt
        e = dR(q, qd, t1)
        pred.append(float(np.linalg.norm(e)))
        c = 0
        while np.linalg.norm(e) > eps and c < max_corrections:
            J = task.jacobian(q)
            P = np.block([[J, np.zeros_like(J)], [Kmat(q, qd), J]])
            dQ = np.linalg.solve(P, e)  # (7-55)
            q, qd = q + dQ[:n], qd + dQ[n:]  # (7-57)
            e = dR(q, qd, t1)
            c += 1
        ts.append(t1)
        Q.append(q.copy())
        QD.append(qd.copy())
        errs.append(float(np.linalg.norm(e)))
        corr.append(c)
    errs = np.array(errs)
    return TrackingResult(
        np.array(ts),
        np.array(Q),
        np.array(QD),
        errs,
        np.array(pred),
        np.array(corr),
        bool((errs <= eps).all()),
    )


# ---------------------------------------------------------------------------- optimisation
def _omega1(Jp, e):
    """Step along p minimising the Gauss–Newton model |δr − ω J p|²: ω = (Jp)ᵀδr / |Jp|².
    For p = 2Jᵀδr this is (7-82): ω1 = pᵀp / (2 pᵀJᵀJp)."""
    den = float(Jp @ Jp)
    return (float(Jp @ e) / den) if den > 0 else 0.0


def steepest_descent(task, q0, *, tol: float = 1e-10, max_iter: int = 10000) -> IterResult:
    """Steepest descent with the book's step estimate ω1 (7-72)–(7-82): p = 2Jᵀδr (7-74),
    q ← q + ω1 p.  Linear convergence; needs no J inverse."""
    return _descent(task, q0, tol=tol, max_iter=max_iter, conjugate=False)


def conjugate_direction(
    task, q0, *, tol: float = 1e-10, max_iter: int = 10000, restart: int | None = None
) -> IterResult:
    """Fletcher–Reeves conjugate directions (7-83) with the ω1 step of (7-82).

    p_0 = −∇f, p_k = −∇f_k + (|∇f_k|² / |∇f_{k−1}|²) p_{k−1}; restarted with −∇f every
    ``restart`` iterations (default n, the number of joints) and whenever p is not a descent
    direction.  Without restarts the crude ω1 step makes FR slow (notes §4 E3: 249 iterations)."""
    return _descent(task, q0, tol=tol, max_iter=max_iter, conjugate=True, restart=restart)


def _descent(task, q0, *, tol, max_iter, conjugate, restart=None, residual=None):
    q = _check_q0(q0)
    n = q.shape[0]
    restart = n if restart is None else int(restart)
    res = residual or (lambda q: (task.error(q), task.jacobian(q)))
    e, J = res(q)
    its, errs, steps = [q.copy()], [float(np.linalg.norm(e))], []
    g_prev = p = None
    k_since = 0
    for _ in range(max_iter):
        if errs[-1] <= tol:
            break
        g = -2.0 * J.T @ e  # ∇f (7-73)
        if not np.any(g):
            return _finish(q, its, errs, tol, "stalled", steps)
        if conjugate and p is not None and k_since < restart:
            p = -g + (g @ g) / (g_prev @ g_prev) * p  # (7-83)
            if p @ g >= 0:
                p, k_since = -g, 0
        else:
            p, k_since = -g, 0
        w = _omega1(J @ p, e)  # (7-82)
        if w <= 0:
            p, k_since = -g, 0
            w = _omega1(J @ p, e)
        q = q + w * p
        if not np.isfinite(q).all():
            return _finish(its[-1], its, errs, tol, "diverged", steps)
        steps.append(w)
        g_prev = g
        k_since += 1
        e, J = res(q)
        its.append(q.copy())
        errs.append(float(np.linalg.norm(e)))
    return _finish(q, its, errs, tol, "max_iter", steps)


def joint_limit_constraints(robot, margin: float = 0.0):
    """Constraints g_i(q) ≥ 0 of (7-84) for the joint limits: q − lower − margin ≥ 0 and
    upper − margin − q ≥ 0 (finite limits only).  Returns a list of (g, grad_g) pairs."""
    out = []
    for i, (lo, hi) in enumerate(zip(robot.lower, robot.upper)):
        e = np.zeros(robot.nq)
        e[i] = 1.0
        if np.isfinite(lo):
            out.append((lambda q, i=i, lo=lo: q[i] - lo - margin, lambda q, e=e: e))
        if np.isfinite(hi):
            out.append((lambda q, i=i, hi=hi: hi - margin - q[i], lambda q, e=-e: e))
    return out


def penalty_minimize(
    task,
    q0,
    constraints,
    *,
    mu: float = 1e4,
    method: str = "fr",
    tol: float = 1e-12,
    max_iter: int = 5000,
) -> IterResult:
    """Exterior penalty (7-84)–(7-86): minimise φ(Q, μ) = δRᵀδR + μ Σ min(0, g_i(Q))².

    ``constraints`` is a list of (g, grad_g) callables (g(q) ≥ 0 wanted).  The stacked residual
    ρ = (δr; −√μ·min(0, g)) with Jacobian (J; √μ ∇g for active g) is minimised by
    steepest descent (``method="sd"``) or Fletcher–Reeves (``"fr"``) with the ω1 step.
    ``errors`` report ‖ρ‖ (so ``success`` means a feasible optimum within ``tol``)."""
    if method not in ("sd", "fr"):
        raise ValueError(f"method must be 'sd' or 'fr', got {method!r}")
    if not (mu >= 0 and np.isfinite(mu)):
        raise ValueError(f"mu must be >= 0, got {mu}")
    sm = np.sqrt(mu)

    def residual(q):
        e, J = task.error(q), task.jacobian(q)
        rows_e, rows_J = [e], [J]
        for g, dg in constraints:
            v = g(q)
            if v < 0:  # u_i = 1 when g_i < 0 (7-86)
                # ρ = −√μ g, ρ(q + dq) ≈ ρ − √μ ∇g·dq: Jacobian row +√μ ∇g in the δr convention
                rows_e.append(np.array([-sm * v]))
                rows_J.append(sm * np.asarray(dg(q), float)[None, :])
        return np.concatenate(rows_e), np.vstack(rows_J)

    return _descent(
        task, q0, tol=tol, max_iter=max_iter, conjugate=(method == "fr"), residual=residual
    )


# ---------------------------------------------------------------------------- gradual approach
@dataclass
class GradualResult:
    """``t`` (K,), ``q`` (K, n), ``x`` (K, m) task values, ``err`` (K, m) = x* − x."""

    t: np.ndarray
    q: np.ndarray
    x: np.ndarray
    err: np.ndarray


def gradual_approach(task, q0, *, mu=None, t_end: float = 10.0, dt: float = 0.05) -> GradualResult:
    """The gradual approach (逐渐逼近法), Eqs. (7-33)–(7-49), closed loop.

    The error x* − x(t) is prescribed as c·μ(t) (7-38), c = x* − x(0) (7-40), μ(0) = 1,
    μ(∞) = 0 (7-39); default μ(t) = 1/(1 + t) (l. 5302).  Recursion (7-49):
    δq(t+Δt) = J⁻¹[x(t)] u(t+Δt) δx(t), u = diag(1 − μ(t+Δt)/μ(t)), δx(t) = x* − x(t) the actual
    error (least squares for non-square J).  With one μ for every coordinate the path is the
    straight line of Fig. 7-9."""
    mu = mu or (lambda t: 1.0 / (1.0 + t))
    if abs(mu(0.0) - 1.0) > 1e-12:
        raise ValueError(f"mu(0) must be 1 (7-39), got {mu(0.0)}")
    if not (0 < dt < np.inf and 0 < t_end < np.inf):
        raise ValueError(f"need finite dt > 0 and t_end > 0, got dt={dt}, t_end={t_end}")
    q = _check_q0(q0)
    ts, Q, X, E = [0.0], [q.copy()], [task.value(q)], [task.error(q)]
    t = 0.0
    for _ in range(int(round(t_end / dt))):
        m0, m1 = mu(t), mu(t + dt)
        u = 1.0 - (m1 / m0 if m0 != 0 else 0.0)
        e = task.error(q)
        J = task.jacobian(q)
        if J.shape[0] == J.shape[1]:
            dq = np.linalg.solve(J, u * e)
        else:
            dq = np.linalg.lstsq(J, u * e, rcond=None)[0]
        q = q + dq
        t += dt
        ts.append(t)
        Q.append(q.copy())
        X.append(task.value(q))
        E.append(task.error(q))
    return GradualResult(np.array(ts), np.array(Q), np.array(X), np.array(E))
