"""One step of QP differential IK: the joint velocity that best achieves the tasks within limits.

    min_Δq  Σ_tasks ½‖W(J Δq + α e)‖² + ½ μ‖Δq‖² + ½ λ‖Δq‖²
    s.t.    lo(q, dt) ≤ Δq ≤ hi(q, dt)        (limits, combined by priority: always feasible)
            J_c Δq = −α_c e_c                  (optional hard ``constraints``)

and v = Δq / dt.  With one square, well-conditioned task, α = 1 and λ, μ → 0 this is the
Newton–Raphson step Δq = −J⁻¹e of the book's feedback compensation (Ch. 7 §7-5, notes §6.2);
the LM term μ = λ_LM‖We‖² is Sugihara's damping that keeps steps bounded near singularities
(pink#59).  The velocity control of Ch. 7 §7-7 (θ̇ = J⁻¹ṡ, Eq. (7-89)) is one step with a
FrameTask whose target moves along the commanded twist.

A bad QP (inconsistent hard constraints, solver failure) gives ``status != "optimal"`` and the
safe zero velocity instead of an exception; ``step(..., full=True)`` returns the status.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from .backends import make_backend
from .configuration import IKConfiguration
from .limits import ConfigurationLimit, VelocityLimit, combine

_ROBOT_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@dataclass
class StepResult:
    """Output of :func:`step` with ``full=True``.

    v : (nv,) joint velocity (rad/s, m/s); zero when ``status`` is not ``"optimal"``.
    status : ``"optimal"``, ``"infeasible"`` (hard constraints cannot hold inside the limits)
        or ``"failed"`` (solver error).
    lo, hi : the combined box on Δq that the step respected.
    """

    v: np.ndarray
    status: str
    solver: str
    lo: np.ndarray
    hi: np.ndarray
    info: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "optimal"


def default_limits(robot) -> list:
    """The model's configuration (gain 0.5) and velocity limits, as pink applies by default."""
    return [ConfigurationLimit(robot), VelocityLimit(robot)]


def _state(owner, robot):
    """Per-robot (or per-IKConfiguration) cache of backends, default limits and a configuration."""
    if isinstance(owner, IKConfiguration):
        st = owner.__dict__.get("_qp_state")
        if st is None:
            st = owner.__dict__["_qp_state"] = {"backends": {}}
        return st
    st = _ROBOT_CACHE.get(robot)
    if st is None:
        st = _ROBOT_CACHE[robot] = {"backends": {}}
    return st


def step(robot, q, tasks, dt: float, limits="default", solver: str = "osqp", damping: float = 1e-12,
         constraints=(), full: bool = False):
    """Joint velocity v (nv,) of one differential-IK step from ``q``.

    Parameters
    ----------
    robot : Robot or IKConfiguration
        With a Robot, a cached IKConfiguration is updated to ``q``.  With an IKConfiguration,
        ``q`` may be ``None`` (use its current q, whose kinematics are already computed).
    q : array (nq,) or None
    tasks : sequence of :class:`~anthroarm.ik.qp.tasks.Task`
    dt : float
        Step duration, s (> 0).
    limits : ``"default"`` (configuration + velocity limits of the model), a sequence of
        :class:`~anthroarm.ik.qp.limits.Limit`, or ``None`` / ``[]`` for none.
    solver : ``"osqp"`` (persistent workspace), ``"daqp"``, ``"quadprog"``, ``"proxqp"`` or
        ``"qpsolvers:NAME"``; :class:`~anthroarm.errors.SolverNotAvailableError` lists the
        installed ones otherwise.
    damping : float
        Tikhonov weight λ on ‖Δq‖² ([cost]²), keeps the QP strictly convex.
    constraints : sequence of tasks held exactly (J Δq = −α e).
    full : bool
        Return a :class:`StepResult` (velocity, status, box) instead of the bare velocity.
    """
    if isinstance(robot, IKConfiguration):
        conf = robot
        rb = conf.robot
        st = _state(robot, rb)
        if q is not None:
            conf.update(q)
    else:
        rb = robot
        st = _state(robot, robot)
        conf = st.get("conf")
        if conf is None:
            conf = st["conf"] = IKConfiguration(robot, q)
        else:
            conf.update(q)
    if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive finite number of seconds, got {dt!r}")
    nv = conf.nv
    if isinstance(limits, str):
        if limits != "default":
            raise ValueError(f"limits must be 'default', None or a list of Limit objects, got {limits!r}")
        limits = st.get("default_limits")
        if limits is None:
            limits = st["default_limits"] = default_limits(rb)
    elif limits is None:
        limits = ()

    # Σ tasks (tasks may return cached arrays: never modify them in place)
    H = c = None
    own = False
    for t in tasks:
        Ht, ct = t.compute_qp_objective(conf)
        if H is None:
            H, c = Ht, ct
        else:
            H = H + Ht
            c = c + ct
            own = True
    if H is None:
        H, c, own = np.zeros((nv, nv)), np.zeros(nv), True
    if damping:
        if not own:
            H = H.copy()
        H.flat[:: nv + 1] += float(damping)
    lo, hi = combine(limits, conf, dt)

    A = b = None
    if constraints:
        A = np.vstack([t.compute_jacobian(conf) for t in constraints])
        b = np.concatenate([-t.gain * t.compute_error(conf) for t in constraints])
    n_eq = 0 if A is None else len(A)
    backends = st["backends"]
    backend = backends.get((solver, nv, n_eq))
    if backend is None:
        backend = backends[(solver, nv, n_eq)] = make_backend(solver, nv, n_eq)
    Hr = H.ravel()
    if not math.isfinite(Hr @ Hr + c @ c):
        x, status = None, "failed"
        backend.last_info = {"error": "non-finite task objective"}
    else:
        x, status = backend.solve(H, c, lo, hi, A, b)
    v = np.zeros(nv) if x is None else x / dt
    for lim in limits:
        lim.after_step(v, dt)
    if full:
        return StepResult(v, status, backend.name, lo, hi, dict(backend.last_info))
    return v
