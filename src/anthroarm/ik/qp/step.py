"""One step of QP differential IK: the joint velocity that best achieves the tasks within limits::

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

Speed: a step allocates almost nothing.  The tasks add their (H, c) into preallocated arrays
(``Task._accumulate``; the built-in frame, posture and damping tasks in place, any other task
through its ``compute_qp_objective``), the limits write the box [lo; −hi] in place
(:func:`~anthroarm.ik.qp.limits.base.combine_into`, which falls back to ``combine`` whenever the
priority rule or the start-outside branch applies) and the backends take the arrays as they are
(:meth:`~anthroarm.ik.qp.backends.Backend.solve_ws`).  tests/ik_qp/test_ik_qp_fast.py checks each
of these against the general code; benchmarks/bench_qp_step.py times the step against pink.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

import numpy as np

from .backends import make_backend
from .configuration import IKConfiguration
from .limits import ConfigurationLimit, VelocityLimit
from .limits.base import BIG, combine_into
from .tasks.base import Task


@dataclass
class StepResult:
    """Output of :func:`step` with ``full=True``.

    Attributes
    ----------
    v : (nv,) array
        Joint velocity (rad/s, m/s); zero when ``status`` is not ``"optimal"``.
    status : str
        ``"optimal"``, ``"infeasible"`` (hard constraints cannot hold inside the limits)
        or ``"failed"`` (solver error).
    lo, hi : (nv,) arrays
        The combined box on Δq that the step respected.
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


class _Workspace:
    """Preallocated arrays of one step (per IKConfiguration / robot): the tasks add their
    objective into ``H``, ``c`` in place (``Hc`` holds both, so one dot product checks them for
    NaN/inf), the limits write ``B = [lo; −hi]`` (the quadprog form), and ``hi``."""

    __slots__ = (
        "n",
        "Hc",
        "H",
        "c",
        "Hd",
        "B",
        "Bm",
        "lo",
        "mhi",
        "hi",
        "box2",
        "tmp2",
        "nc",
        "dt",
        "dtv",
    )

    def __init__(self, n: int):
        self.n = n
        self.Hc = np.zeros(n * n + n)
        self.H = self.Hc[: n * n].reshape(n, n)
        self.c = self.Hc[n * n :]
        self.Hd = np.einsum("ii->i", self.H)  # writable view of diag(H)
        self.B = np.zeros(2 * n)
        self.Bm = self.B.reshape(2, n)
        self.lo = self.B[:n]
        self.mhi = self.B[n:]
        self.hi = np.zeros(n)
        self.box2 = np.zeros((2, n))
        self.tmp2 = np.zeros((2, n))
        self.nc = np.zeros(n)  # scratch for backends (e.g. −c)
        self.dt = None  # dt held in dtv (nv,)
        self.dtv = np.zeros(n)


def _conf_state(conf) -> dict:
    """The step state of an IKConfiguration: its backends, default limits and workspace."""
    st = conf.__dict__.get("_qp_state")
    if st is None:
        st = conf.__dict__["_qp_state"] = {"backends": {}}
    return st


def _robot_state(robot) -> dict:
    """The step state of ``step(robot, q, ...)`` for the calling thread: its own
    IKConfiguration (hence ``pin.Data``), workspace and backends, kept in a ``threading.local``
    on the Robot itself, so that threads never share them and nothing outlives the Robot."""
    local = robot.__dict__.get("_qp_local")
    if local is None:
        local = robot.__dict__.setdefault("_qp_local", threading.local())  # atomic: one wins
    st = getattr(local, "state", None)
    if st is None:
        st = local.state = {"backends": {}}
    return st


def _configuration(robot, q):
    """(IKConfiguration at ``q``, its Robot, the step's state) for :func:`step`'s ``robot``: an
    IKConfiguration (``q`` None keeps its q), or a Robot (the calling thread's configuration,
    kept on the Robot)."""
    if isinstance(robot, IKConfiguration):
        conf = robot
        st = conf.__dict__.get("_qp_state")
        if st is None:
            st = _conf_state(conf)
        if q is not None:
            conf.update(q)
        return conf, conf.robot, st
    st = _robot_state(robot)
    conf = st.get("conf")
    if conf is None:
        conf = st["conf"] = IKConfiguration(robot, q)
    else:
        conf.update(q)
    return conf, robot, st


def _limits(limits, robot, st):
    """(the limits, whether any keeps state between steps) of :func:`step`'s ``limits``."""
    if limits.__class__ is str:
        if limits != "default":
            raise ValueError(
                f"limits must be 'default', None or a list of Limit objects, got {limits!r}"
            )
        default = st.get("default_limits")
        if default is None:
            default = st["default_limits"] = default_limits(robot)
        return default, False  # configuration and velocity limits keep no state
    if limits is None:
        return (), False
    return limits, True


# long: the public docstring (25 lines: every argument); the body is the one hot path of a
# control step (tasks accumulated into one workspace, the limits, the QP), kept in one frame
def step(
    robot,
    q,
    tasks,
    dt: float,
    limits="default",
    solver: str = "osqp",
    damping: float = 1e-12,
    constraints=(),
    full: bool = False,
):
    """Joint velocity v (nv,) of one differential-IK step from ``q``: a tangent vector
    (``pin.integrate(model, q, v dt)`` applies it; see :meth:`IKConfiguration.integrate_inplace`).

    Parameters
    ----------
    robot : Robot or IKConfiguration
        With a Robot, the calling thread's own IKConfiguration (kept on the Robot) is updated
        to ``q``.  With an IKConfiguration, ``q`` may be ``None`` (use its current q, whose
        kinematics are already computed).
    q : array (nq,) or None
        Pinocchio's layout: a continuous joint takes (cos θ, sin θ).
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
    conf, rb, st = _configuration(robot, q)
    if not (dt.__class__ is float and 0.0 < dt < math.inf):  # the common case in one test
        if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive finite number of seconds, got {dt!r}")
    nv = conf.nv
    limits, stateful = _limits(limits, rb, st)
    ws = st.get("ws")
    if ws is None:
        ws = st["ws"] = _Workspace(nv)
    # Σ tasks, in place: each task adds its (H, c) into the workspace and returns the scalar
    # part of its diagonal (LM term, posture/damping weight), added once with the damping
    first = True
    diag = float(damping) if damping else 0.0
    if not (math.isfinite(diag) and diag >= 0.0):
        raise ValueError(
            f"damping must be a finite number >= 0 (a negative damping makes the QP "
            f"non-convex), got {damping!r}"
        )
    for t in tasks:
        try:
            acc = t._accumulate
        except AttributeError:  # a duck-typed task with compute_qp_objective only
            acc = Task._accumulate.__get__(t)
        diag += acc(conf, ws, first)
        first = False
    if first:
        ws.Hc.fill(0.0)
    if diag:
        np.add(ws.Hd, diag, out=ws.Hd)
    combine_into(limits, conf, dt, ws)

    A = b = None
    if constraints:
        A = np.vstack([t.compute_jacobian(conf) for t in constraints])
        b = np.concatenate([-t.gain * t.compute_error(conf) for t in constraints])
    n_eq = 0 if A is None else len(A)
    last = st.get("last")  # (solver, n_eq, backend) of the previous step
    if last is not None and last[0] is solver and last[1] == n_eq:
        backend = last[2]
    else:
        backends = st["backends"]
        backend = backends.get((solver, nv, n_eq))
        if backend is None:
            backend = backends[(solver, nv, n_eq)] = make_backend(solver, nv, n_eq)
        st["last"] = (solver, n_eq, backend)
    Hc = ws.Hc
    if not math.isfinite(Hc.dot(Hc)):
        x, status = None, "failed"
        backend.last_info = {"error": "non-finite task objective"}
    else:
        x, status = backend.solve_ws(ws, A, b)
    if x is None:
        v = np.zeros(nv)
    else:
        if ws.dt != dt:  # dt as an array: x / dt array-wise costs less
            ws.dtv.fill(dt)
            ws.dt = dt
        v = np.divide(x, ws.dtv, out=x)
    if stateful:
        for lim in limits:
            lim.after_step(v, dt)
    if full:  # the box as combine() gives it (±inf where unbounded, not the solvers' ±BIG)
        lo = np.where(ws.lo <= -BIG, -np.inf, ws.lo)
        hi = np.where(ws.hi >= BIG, np.inf, ws.hi)
        return StepResult(v, status, backend.name, lo, hi, dict(backend.last_info))
    return v
