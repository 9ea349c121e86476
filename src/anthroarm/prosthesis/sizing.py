"""Actuator sizing: the lightest catalogue motor + gearbox per joint that covers the activities.

Each (motor, gearbox) pair that mounts together (:mod:`.catalogue`) becomes the servo model of
:class:`anthroarm.control.motor.DCMotor` (Eq. (9-1): τ_m = (k_m/R) V − (k_m²/R) ω_m, gear ratio
i with θ_m = i θ, efficiency η).  The demand of a joint is every sample of every activity of an
:class:`~.envelope.Envelope`, scaled by ``1 + margin`` (torque, speed and acceleration).  A pair
covers the joint when all five utilisations are ≤ 1:

``voltage``
    max |V(τ, ω, α)| / V_nom, with V = R I + k_m i ω and I = (J_m i α + τ_gear)/k_m
    (:meth:`anthroarm.control.motor.DCMotor.voltage`): every (torque, speed) point lies under
    the torque–speed line at the nominal voltage, the rotor's inertia included;
``thermal``
    RMS of the motor torque over each activity / the rated continuous torque
    (:meth:`anthroarm.control.motor.DCMotor.thermal_check`), the largest over the activities;
``gear_peak``
    max |τ| / the gearbox's intermittent output torque;
``gear_rms``
    the largest per-activity RMS of τ / the gearbox's continuous output torque;
``speed``
    max |ω| i / min(motor's max speed, gearbox's max input speed).

Among the pairs that cover a joint the lightest (motor + gearbox mass) is chosen, ties broken by
the smaller largest utilisation.  When none does, the joint's status is "none" and ``reason``
names the pair that came closest and the limit it breaks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..control.motor import rms
from ..errors import ActivityError, ControlError

CHECKS = ("voltage", "thermal", "gear_peak", "gear_rms", "speed")
_LIMIT_TEXT = {
    "voltage": "torque-speed line at the nominal voltage",
    "thermal": "motor's continuous (thermal, RMS) torque",
    "gear_peak": "gearbox's intermittent output torque",
    "gear_rms": "gearbox's continuous output torque",
    "speed": "maximum motor/gearbox input speed",
}


@dataclass
class Candidate:
    """One motor + gearbox pair on one joint: its mass (kg), utilisations (≤ 1 is inside the
    limit, one per entry of :data:`CHECKS`) and whether it covers the joint."""

    motor: object
    gearbox: object
    mass: float
    utilisation: dict
    feasible: bool

    @property
    def name(self) -> str:
        return f"{self.motor.name} + {self.gearbox.name}"

    @property
    def limiting(self) -> str:
        """The check with the largest utilisation."""
        return max(self.utilisation, key=self.utilisation.get)

    @property
    def worst(self) -> float:
        return max(self.utilisation.values())

    def dc_motor(self):
        """The pair as :class:`anthroarm.control.motor.DCMotor`."""
        return self.motor.dc_motor(self.gearbox)


@dataclass
class JointSizing:
    """The result for one joint: ``status`` "ok" (``choice`` set) or "none" (``reason`` says
    why; ``closest`` the pair with the smallest largest utilisation)."""

    joint: str
    status: str
    choice: Candidate | None
    closest: Candidate | None
    reason: str
    candidates: int


@dataclass
class SizingResult:
    """Per joint :class:`JointSizing`; ``margin`` the demand factor − 1; ``drive_mass`` kg the
    sum of the chosen motors and gearboxes; ``unfit`` the joints without a pair."""

    joints: list
    margin: float
    drive_mass: float
    unfit: list = field(default_factory=list)

    def rows(self) -> list[dict]:
        """One dict per joint for tables (SI units)."""
        out = []
        for js in self.joints:
            c = js.choice
            out.append(
                dict(
                    joint=js.joint,
                    status=js.status,
                    motor=c.motor.name if c else "",
                    gearbox=c.gearbox.name if c else "",
                    ratio=c.gearbox.ratio if c else float("nan"),
                    mass=c.mass if c else float("nan"),
                    limiting=c.limiting if c else (js.closest.limiting if js.closest else ""),
                    utilisation=c.worst
                    if c
                    else (js.closest.worst if js.closest else float("nan")),
                    reason=js.reason,
                )
            )
        return out


def _utilisation(motor, gearbox, demands, scale: float) -> dict:
    """The five utilisations (module docstring) of one pair; a demand that overflows the pair's
    equations (absurd catalogue values) counts as infinite: the pair does not cover it."""
    dc = motor.dc_motor(gearbox)
    speed_limit = min(motor.max_speed, gearbox.max_input_speed)
    u = dict.fromkeys(CHECKS, 0.0)

    def worse(key, value):
        value = float(value)
        u[key] = max(u[key], value if np.isfinite(value) else np.inf)

    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for t, tau, w, a in demands:
            tau, w, a = scale * tau, scale * w, scale * a
            try:
                worse("voltage", np.max(np.abs(dc.voltage(tau, w, a))) / motor.V_nom)
            except ControlError:  # the motor model refuses a torque beyond float range
                worse("voltage", np.inf)
            try:
                worse("thermal", dc.thermal_check(t, tau, w, a).ratio)
            except ControlError:
                worse("thermal", np.inf)
            worse("gear_peak", np.max(np.abs(tau)) / gearbox.tau_max)
            worse("gear_rms", rms(t, tau) / gearbox.tau_cont)
            worse("speed", np.max(np.abs(w)) * gearbox.ratio / speed_limit)
    return u


def size_joint(envelope, joint, catalogue, margin: float = 0.2) -> JointSizing:
    """Size one joint (name or index in ``envelope.joint_names``); see the module docstring."""
    j = envelope.joint_names.index(joint) if isinstance(joint, str) else int(joint)
    name = envelope.joint_names[j]
    demands = [(a.t, a.tau[:, j], a.qd[:, j], a.qdd[:, j]) for a in envelope.activities]
    cands = []
    for m, g in catalogue.combinations():
        u = _utilisation(m, g, demands, 1.0 + margin)
        cands.append(Candidate(m, g, m.mass + g.mass, u, all(v <= 1.0 for v in u.values())))
    ok = [c for c in cands if c.feasible]
    closest = min(cands, key=lambda c: c.worst) if cands else None
    if ok:
        best = min(ok, key=lambda c: (c.mass, c.worst))
        return JointSizing(name, "ok", best, closest, "", len(cands))
    lim = closest.limiting
    reason = (
        f"none of {len(cands)} motor+gearbox pairs covers {name} with a {margin:.0%} margin "
        f"(peak {envelope.peak_torque[j]:.2f} N m, RMS {envelope.rms_torque[j]:.2f} N m, "
        f"{envelope.peak_speed[j]:.2f} rad/s); closest: {closest.name}, at {closest.utilisation[lim]:.2f}x "
        f"the {_LIMIT_TEXT[lim]}"
    )
    return JointSizing(name, "none", None, closest, reason, len(cands))


def size(envelope, catalogue, margin: float = 0.2, joints=None, progress=None) -> SizingResult:
    """Size every joint of ``envelope`` (or the listed ``joints``) from ``catalogue``.

    ``margin`` ≥ 0 multiplies the demand by ``1 + margin``.  ``progress``: an optional callable
    ``progress(joint_name)`` called before each joint (the CLI's progress bar)."""
    margin = float(margin)
    if not (np.isfinite(margin) and 0.0 <= margin <= 10.0):
        raise ActivityError(f"margin must be in [0, 10] (a fraction: 0.2 = 20 %), got {margin}")
    names = envelope.joint_names if joints is None else list(joints)
    out = []
    for n in names:
        if progress is not None:
            progress(n)
        out.append(size_joint(envelope, n, catalogue, margin))
    mass = float(sum(js.choice.mass for js in out if js.choice is not None))
    return SizingResult(out, margin, mass, [js.joint for js in out if js.status != "ok"])
