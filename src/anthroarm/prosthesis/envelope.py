"""Joint torque, speed and power demands of a set of activities, and their envelope.

An activity is a joint trajectory q(t) of a person's arm model (rad, s).  :func:`activity_torques`
turns it into joint torques with :func:`anthroarm.dynamics.loads.inverse_dynamics` (held object:
a wrench at the hand, Eq. (8-5)) and :func:`envelope` summarises a set of them per joint:

* peak torque max |τ| (N·m), RMS torque (N·m; the RMS over each activity's own duration,
  ``sqrt(∫τ² dt / T)`` by the trapezoidal rule, and the largest over the set — the thermal load of
  repeating the hardest activity),
* peak speed max |q̇| (rad/s), peak power max |τ q̇| (W).

The samples themselves stay available (:attr:`ActivityTorques.tau` etc.): the sizing checks every
(torque, speed) point against a motor's torque–speed line, not the peaks alone.

An activity whose configurations leave the joint limits is kept with ``status =
"outside_limits"`` and a reason naming the joint, and is left out of the envelope.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..control.motor import rms
from ..dynamics.loads import HeldObject, generalized_forces, inverse_dynamics
from ..errors import ActivityError


@dataclass
class ActivityTorques:
    """One activity's trajectory and its joint demands (rows: samples; columns: joints, nv order).

    ``t`` s, ``q`` rad, ``qd`` rad/s, ``qdd`` rad/s², ``tau`` N·m the joint torques with the
    loads, ``tau_free`` without them, ``power`` = τ q̇ W, ``mass_in_hand`` (N,) kg and
    ``payload`` its largest value.  ``status`` "ok", "outside_limits" or a status given by
    whoever made the trajectory (e.g. "unreachable"); then ``reason`` says why."""

    name: str
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    tau_free: np.ndarray
    power: np.ndarray
    joint_names: list
    status: str = "ok"
    reason: str = ""
    payload: float = 0.0
    mass_in_hand: np.ndarray | None = None
    #: with residual muscles (:mod:`.residual`): the torque they cover (N, nv); ``tau`` is then
    #: what the motors must add (the demand is ``tau + muscle_tau``)
    muscle_tau: np.ndarray | None = None

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])


def derivatives(t, q):
    """(q̇, q̈) of samples ``q`` (N, n) at strictly increasing times ``t`` (N,) from a quintic
    interpolating spline (``scipy.interpolate.make_interp_spline``, k = 5; k = 3 below 6
    samples).  Exact for polynomials of degree ≤ 5 between the samples."""
    from scipy.interpolate import make_interp_spline

    t = np.asarray(t, float)
    q = np.asarray(q, float)
    k = 5 if len(t) >= 6 else 3
    spl = make_interp_spline(t, q, k=k, axis=0)
    return spl.derivative(1)(t), spl.derivative(2)(t)


def _check_time(t, n: int, name: str) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or len(t) != n:
        raise ActivityError(
            f"activity {name!r}: t must have one time per sample ({n}), got shape {t.shape}"
        )
    if n < 4:
        raise ActivityError(f"activity {name!r}: needs at least 4 samples, got {n}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ActivityError(f"activity {name!r}: times must be finite and strictly increasing (s)")
    return t


#: the held object's shape: a solid cylinder (a full cup or jug), axis along the hand frame's z,
#: centred on the hand point (m)
CUP_RADIUS, CUP_HEIGHT = 0.04, 0.10


def held_object(mass: float = 1.0, frame: str | None = None):
    """The held object of the reports: :data:`CUP_RADIUS`/:data:`CUP_HEIGHT` solid cylinder of
    ``mass`` kg at ``frame`` (default the tool), as :class:`anthroarm.dynamics.loads.HeldObject`."""
    return HeldObject.cylinder(mass, CUP_RADIUS, CUP_HEIGHT, frame=frame)


def activity_torques(
    robot,
    name: str,
    t,
    q,
    qd=None,
    qdd=None,
    loads=None,
    *,
    payload=0.0,
    dynamics=None,
    limit_tol: float = 1e-6,
) -> ActivityTorques:
    """Joint torques, speeds and powers of one activity.

    Parameters
    ----------
    robot : Robot
        The person's arm model.
    name : str
        Activity label.
    t : array, (N,)
        Times, s, strictly increasing.
    q : array, (N, nq)
        Joint positions, rad.
    qd, qdd : array, (N, nv), optional
        Joint velocities and accelerations; default: :func:`derivatives` of ``q``.
    loads : Wrench, HeldObject or sequence, optional
        Other loads on the arm (:mod:`anthroarm.dynamics.loads`).
    payload : float or array (N,)
        Mass in the hand, kg, constant or per sample (an object picked up and put down): the
        :func:`held_object` cylinder of that mass.  Its generalised forces are linear in the
        mass (the cylinder's inertia scales with it), so they are computed once for 1 kg and
        scaled per sample.
    dynamics : LagrangeDynamics, optional
        Reused generated Lagrange code of ``robot``.
    limit_tol : float
        Tolerance (rad) on the joint limits.

    Raises
    ------
    anthroarm.errors.ActivityError
        Malformed times or samples.
    """
    try:
        q = robot.check_q(q, f"q of activity {name!r}")
    except ValueError as exc:
        raise ActivityError(str(exc)) from None
    if q.ndim != 2:
        raise ActivityError(f"activity {name!r}: q must be (N, {robot.nq}) samples, got {q.shape}")
    t = _check_time(t, len(q), name)
    if qd is None or qdd is None:
        if robot.nq != robot.nv:
            raise ActivityError(
                f"activity {name!r}: give qd and qdd for a robot with continuous joints (nq != nv)"
            )
        d1, d2 = derivatives(t, q)
        qd = d1 if qd is None else qd
        qdd = d2 if qdd is None else qdd
    try:
        mass = np.asarray(payload, dtype=float)
    except (TypeError, ValueError):
        raise ActivityError(
            f"activity {name!r}: payload must be a mass in kg, got {payload!r}"
        ) from None
    mass = np.full(len(t), float(mass)) if mass.ndim == 0 else mass
    if mass.shape != (len(t),) or not np.all(np.isfinite(mass)) or np.any(mass < 0):
        raise ActivityError(
            f"activity {name!r}: payload must be a mass >= 0 kg, one or one per sample ({len(t)})"
        )
    try:
        res = inverse_dynamics(robot, q, qd, qdd, loads, dynamics=dynamics)
        tau = res.tau
        if np.any(mass > 0):
            unit = generalized_forces(robot, q, held_object(1.0), res.qd, qdd)  # Eq. (8-5), 1 kg
            tau = tau - mass[:, None] * unit
    except ValueError as exc:
        raise ActivityError(f"activity {name!r}: {exc}") from None
    status, reason = "ok", ""
    inside = robot.within_limits(q, tol=limit_tol)
    if not np.all(inside):
        k = int(np.argmin(inside))
        lo = q[k] < robot.lower - limit_tol
        j = int(np.argmax(lo | (q[k] > robot.upper + limit_tol)))
        status = "outside_limits"
        reason = (
            f"sample {k} (t = {t[k]:.3f} s): joint {robot.chain.q_names[j]!r} at {np.degrees(q[k, j]):.1f} deg is "
            f"outside [{np.degrees(robot.lower[j]):.1f}, {np.degrees(robot.upper[j]):.1f}] deg"
        )
    return ActivityTorques(
        name=name,
        t=t,
        q=q,
        qd=res.qd,
        qdd=np.asarray(qdd, float),
        tau=tau,
        tau_free=res.tau_free,
        power=tau * res.qd,
        joint_names=list(robot.joint_names),
        status=status,
        reason=reason,
        payload=float(np.max(mass)),
        mass_in_hand=np.array(mass),
    )


def _rms(t, x):
    """RMS over the time span of each column (:func:`anthroarm.control.motor.rms`)."""
    return np.array([rms(t, col) for col in np.asarray(x).T])


@dataclass
class Envelope:
    """Per joint (arrays of length nv, joint order ``joint_names``): ``peak_torque`` max |τ| N·m,
    ``rms_torque`` the largest per-activity RMS τ N·m, ``peak_speed`` max |q̇| rad/s,
    ``peak_power`` max |τ q̇| W; ``activities`` the activities used (status "ok"),
    ``skipped`` the others."""

    joint_names: list
    peak_torque: np.ndarray
    rms_torque: np.ndarray
    peak_speed: np.ndarray
    peak_power: np.ndarray
    activities: list
    skipped: list = field(default_factory=list)

    def rows(self) -> list[dict]:
        """One dict per joint (SI units) for tables."""
        return [
            dict(
                joint=n,
                peak_torque=float(self.peak_torque[j]),
                rms_torque=float(self.rms_torque[j]),
                peak_speed=float(self.peak_speed[j]),
                peak_power=float(self.peak_power[j]),
            )
            for j, n in enumerate(self.joint_names)
        ]


def envelope(activities) -> Envelope:
    """The envelope (module docstring) of a sequence of :class:`ActivityTorques`.

    Activities with a status other than "ok" are listed in ``skipped``.  Raises
    :class:`~anthroarm.errors.ActivityError` when no activity is usable or the joint names
    differ."""
    acts = list(activities)
    ok = [a for a in acts if a.status == "ok"]
    skipped = [a for a in acts if a.status != "ok"]
    if not ok:
        why = "; ".join(f"{a.name}: {a.reason}" for a in skipped) or "no activities given"
        raise ActivityError(f"no usable activity for an envelope ({why})")
    names = ok[0].joint_names
    for a in ok[1:]:
        if a.joint_names != names:
            raise ActivityError(
                f"activity {a.name!r} has joints {a.joint_names}, the first one {names}"
            )
    peak_t = np.max([np.max(np.abs(a.tau), axis=0) for a in ok], axis=0)
    rms_t = np.max([_rms(a.t, a.tau) for a in ok], axis=0)
    peak_w = np.max([np.max(np.abs(a.qd), axis=0) for a in ok], axis=0)
    peak_p = np.max([np.max(np.abs(a.power), axis=0) for a in ok], axis=0)
    return Envelope(list(names), peak_t, rms_t, peak_w, peak_p, ok, skipped)
