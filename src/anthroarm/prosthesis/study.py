"""The whole loop for one person: activities → joint demands with a held object → envelope →
motors and gearboxes → the book's weight rules.  :func:`run` returns a :class:`Study` that
:mod:`.report` turns into HTML.

An activity is given as a dict ``{"name", "t", "q"}`` (optionally ``"qd"``, ``"qdd"``,
``"payload"`` kg, ``"status"`` / ``"reason"`` when whoever made it already knows it is unusable,
e.g. a target outside the arm's reach), in SI units (s, rad).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ActivityError


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


def _held(payload: float, robot):
    from ..dynamics.loads import HeldObject

    if payload == 0:
        return None
    # a cup: solid cylinder, r 4 cm, h 10 cm, centred on the hand point, axis along the frame's z
    return HeldObject.cylinder(payload, 0.04, 0.10, com=(0.0, 0.0, 0.0))


def run(robot, activities, *, payload: float = 0.5, catalogue=None, margin: float = 0.2, person=None,
        progress=None) -> Study:
    """Run the loop (module docstring) on ``robot`` (the person's arm model).

    Parameters
    ----------
    robot : Robot
    activities : sequence of dict
        See the module docstring.
    payload : float
        Mass held in the hand during every activity, kg (a solid cylinder r = 4 cm, h = 10 cm
        centred on the tool frame; 0: none).  An activity's own ``"payload"`` overrides it.
    catalogue : Catalogue, optional
        Default: the shipped example (:func:`.catalogue.load`).
    margin : float
        Demand factor − 1 of the sizing.
    person : dict, optional
        height, mass, sex for the report (default: ``robot.spec.params``).
    progress : callable, optional
        ``progress(stage, name)`` before each activity and joint.
    """
    import time

    from ..dynamics.lagrange import load as load_dynamics
    from . import catalogue as cat_mod
    from . import envelope as env_mod
    from . import sizing, weight_rules

    payload = float(payload)
    if not (np.isfinite(payload) and 0.0 <= payload <= 50.0):
        raise ActivityError(f"payload must be in [0, 50] kg, got {payload}")
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
        name = str(spec.get("name", f"activity {len(acts) + 1}"))
        if progress is not None:
            progress("activity", name)
        m = float(spec.get("payload", payload))
        status = spec.get("status", "ok")
        if status != "ok":
            t = np.asarray(spec.get("t", np.zeros(0)), float)
            q = np.asarray(spec.get("q", np.zeros((0, robot.nq))), float)
            z = np.zeros((len(q), robot.nv))
            acts.append(env_mod.ActivityTorques(name, t, q, z, z, z, z, z, list(robot.joint_names), status,
                                                str(spec.get("reason", "")), m))
            continue
        acts.append(env_mod.activity_torques(robot, name, spec["t"], spec["q"], spec.get("qd"), spec.get("qdd"),
                                             _held(m, robot), dynamics=dyn, payload=m))
    timings["dynamics"] = time.perf_counter() - t0
    env = env_mod.envelope(acts)
    t0 = time.perf_counter()
    res = sizing.size(env, cat, margin, progress=None if progress is None else (lambda j: progress("joint", j)))
    timings["sizing"] = time.perf_counter() - t0
    rules = weight_rules.check(res.drive_mass, person.get("mass"), robot.nv, len(res.unfit))
    return Study(robot, person, acts, env, res, rules, payload, cat, timings)
