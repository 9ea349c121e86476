"""The whole loop for one person: activities → joint demands with a held object → envelope →
motors and gearboxes → the book's weight rules.  :func:`run` returns a :class:`Study` that
:mod:`.report` turns into HTML.

An activity is given as a dict ``{"name", "t", "q"}`` (optionally ``"qd"``, ``"qdd"``,
``"payload"`` kg — one mass or one per sample —, ``"status"`` / ``"reason"`` when whoever made
it already knows it is unusable, e.g. a target outside the arm's reach), in SI units (s, rad).
:func:`adl_activities` makes them from the daily-living library of :mod:`anthroarm.motion`.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from ..dynamics.lagrange import load as load_dynamics
from ..errors import ActivityError
from ..motion import activities as adl
from . import catalogue as cat_mod
from . import envelope as env_mod
from . import residual as residual_mod
from . import sizing, weight_rules


@dataclass
class Study:
    """Everything a report shows.  ``person`` dict(height m, mass kg, sex); ``activities`` list of
    :class:`~.envelope.ActivityTorques` (the unusable ones with their status); ``envelope``,
    ``sizing`` (:class:`~.sizing.SizingResult`), ``rules`` (:class:`~.weight_rules.RuleCheck`
    list); ``payload`` kg; ``catalogue``; ``timings`` s per stage."""

    robot: object
    person: dict
    activities: list
    envelope: object
    sizing: object
    rules: list
    payload: float
    catalogue: object
    timings: dict = field(default_factory=dict)
    #: the person's residual muscles (:class:`.residual.ResidualMuscles`), if any
    residual: object = None

    def unfit(self) -> list[dict]:
        """What did not fit, the one list the report and ``anthroarm size``'s JSON both show:
        ``{"what": "joint" | "activity" | "rule", "name", "reason"}`` for each joint without a
        motor, each activity left out of the envelope, and each weight rule not met."""
        out = [
            {"what": "joint", "name": js.joint, "reason": js.reason}
            for js in self.sizing.joints
            if js.status != "ok"
        ]
        out += [
            {"what": "activity", "name": a.name, "reason": f"{a.status}: {a.reason}"}
            for a in self.activities
            if a.status != "ok"
        ]
        out += [
            {
                "what": "rule",
                "name": r.source,
                "reason": f"{r.rule} ({r.value:.2f} vs {r.limit:.2f} {r.unit})",
            }
            for r in self.rules
            if r.ok is False
        ]
        return out

    def muscles(self) -> list[dict]:
        """With residual muscles: per joint they act on, the peak demand, peak muscle and peak motor torque
        (N m) and the share of the demand the muscles cover (:func:`.residual.table`); else
        []."""
        if self.residual is None:
            return []
        rows = residual_mod.table(self.activities, list(self.robot.joint_names))
        return [r for r in rows if r["joint"] in self.residual.joints]

    def summary(self) -> dict:
        """The study in a few numbers (JSON-ready): drive mass, the motor + gearbox per joint,
        :meth:`unfit`, the activities left out and each rule's verdict (None: information);
        with residual muscles, ``muscles``: :meth:`muscles` by joint (rounded)."""
        extra = {}
        if self.muscles():
            extra["muscles"] = {
                r["joint"]: {k: round(v, 3) for k, v in r.items() if k != "joint"}
                for r in self.muscles()
            }
        return dict(
            drive_mass_kg=round(float(self.sizing.drive_mass), 4),
            joints={
                r["joint"]: (f"{r['motor']} + {r['gearbox']}" if r["status"] == "ok" else "none")
                for r in self.sizing.rows()
            },
            unfit=self.unfit(),
            skipped=[x.name for x in self.envelope.skipped],
            rules={r.source: r.ok for r in self.rules},
            **extra,
        )


def _payload(payload) -> float:
    """A held mass in [0, 50] kg, or an :class:`~anthroarm.errors.ActivityError`."""
    try:
        m = float(payload)
    except (TypeError, ValueError):
        m = float("nan")
    if not (np.isfinite(m) and 0.0 <= m <= 50.0):
        raise ActivityError(f"payload must be a mass in [0, 50] kg, got {payload!r}")
    return m


def run(
    robot,
    activities,
    *,
    payload: float = 0.5,
    catalogue=None,
    margin: float = 0.2,
    person=None,
    progress=None,
    residual=None,
) -> Study:
    """Run the loop (module docstring) on ``robot`` (the person's arm model).

    Parameters
    ----------
    robot : Robot
    activities : sequence of dict
        See the module docstring.
    payload : float
        Mass held in the hand during every activity that does not give its own ``"payload"``,
        kg (:func:`.envelope.held_object`: a solid cylinder r = 4 cm, h = 10 cm centred on the
        tool frame; 0: none).
    catalogue : Catalogue, optional
        Default: the shipped example (:func:`.catalogue.load`).
    margin : float
        Demand factor − 1 of the sizing.
    person : dict, optional
        height, mass, sex for the report (default: ``robot.spec.params``).
    progress : callable, optional
        ``progress(stage, name)`` before each activity and joint.
    residual : ResidualMuscles, optional
        The person's residual muscles (:class:`.residual.ResidualMuscles`): each activity's
        demand is split into the torque they cover (``muscle_tau``) and the torque the motors
        must add (``tau``, which the envelope and the sizing then use).
    """
    payload = _payload(payload)
    if person is None:
        p = dict(robot.spec.params) if robot.spec is not None else {}
        person = {k: p[k] for k in ("height", "mass", "sex") if k in p}
    timings = {}
    t0 = time.perf_counter()
    cat = catalogue if catalogue is not None else cat_mod.load()
    dyn = load_dynamics(robot)
    timings["setup"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    acts = []
    for spec in activities:
        if not isinstance(spec, dict):
            raise ActivityError(
                f"an activity is a dict with 't' (s) and 'q' (rad), got {type(spec).__name__}"
            )
        name = str(spec.get("name", f"activity {len(acts) + 1}"))
        if progress is not None:
            progress("activity", name)
        m = spec.get("payload", payload)
        status = spec.get("status", "ok")
        if status != "ok":
            try:
                t = np.asarray(spec.get("t", np.zeros(0)), float)
                q = np.asarray(spec.get("q", np.zeros((0, robot.nq))), float)
                held = float(np.max(np.asarray(m, float), initial=0.0))
            except (TypeError, ValueError):
                raise ActivityError(
                    f"activity {name!r} (status {status!r}): 't', 'q' and 'payload' must be "
                    "numbers (s, rad, kg)"
                ) from None
            if not (np.isfinite(held) and held >= 0.0):
                raise ActivityError(
                    f"activity {name!r} (status {status!r}): payload must be a mass >= 0 kg, got "
                    f"{m!r}"
                )
            z = np.zeros((len(q), robot.nv))
            acts.append(
                env_mod.ActivityTorques(
                    name,
                    t,
                    q,
                    z,
                    z,
                    z,
                    z,
                    z,
                    list(robot.joint_names),
                    status,
                    str(spec.get("reason", "")),
                    held,
                )
            )
            continue
        missing = [k for k in ("t", "q") if k not in spec]
        if missing:
            raise ActivityError(
                f"activity {name!r} has no {' and no '.join(repr(k) for k in missing)} "
                "(times in s, joint positions in rad)"
            )
        act = env_mod.activity_torques(
            robot,
            name,
            spec["t"],
            spec["q"],
            spec.get("qd"),
            spec.get("qdd"),
            payload=m,
            dynamics=dyn,
        )
        if residual is not None and act.status == "ok":
            mus, motor = residual.cover(robot.joint_names, act.q, act.tau)
            act = dataclasses.replace(act, tau=motor, power=motor * act.qd, muscle_tau=mus)
        acts.append(act)
    timings["dynamics"] = time.perf_counter() - t0
    env = env_mod.envelope(acts)
    t0 = time.perf_counter()
    res = sizing.size(
        env, cat, margin, progress=None if progress is None else (lambda j: progress("joint", j))
    )
    timings["sizing"] = time.perf_counter() - t0
    rules = weight_rules.check(res.drive_mass, person.get("mass"), robot.nv, len(res.unfit))
    return Study(robot, person, acts, env, res, rules, payload, cat, timings, residual)


def adl_activities(
    robot,
    payload: float | None = None,
    names=None,
    *,
    rate: float = 100.0,
    height: float | None = None,
) -> list[dict]:
    """The daily-living activities of :mod:`anthroarm.motion.activities` (all of them, or
    ``names``) for ``robot``, as activity dicts for :func:`run`.

    The mass in the hand per sample is the library's object (``object_mass`` while the
    activity holds it); with ``payload`` (kg) the hand carries at least ``payload`` all the
    time: ``max(payload, object mass while holding)``.  An activity with a keyframe out of the
    arm's reach gets status "unreachable" and a reason naming the keyframe and the distance.
    ``height`` (m): place the targets for a person of this stature (default: the model's)."""
    payload = None if payload is None else _payload(payload)
    out = []
    for name in adl.names() if names is None else list(names):
        tr = adl.activity_trajectory(robot, name, rate=rate, height=height)
        mass = tr.payload if payload is None else np.maximum(tr.payload, payload)
        spec = dict(
            name=name, t=tr.t, q=tr.q, qd=tr.qd, qdd=tr.qdd, payload=mass, title=tr.activity.title
        )
        if not tr.reachable:
            bad = [
                (n, e)
                for n, s, e in zip(tr.keyframe_names, tr.keyframe_status, tr.keyframe_error)
                if s != "ok"
            ]
            spec["status"] = "unreachable"
            spec["reason"] = "; ".join(
                f"keyframe {n!r} out of reach ({e * 1000:.0f} mm short)" for n, e in bad
            )
        out.append(spec)
    return out
