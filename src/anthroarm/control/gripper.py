"""Gripper behaviours with touch, pressure and slip feedback (§9-1 二.1–2, Fig. 9-11 … 9-14).

* **Tactile search** (Fig. 9-11): the hand advances by unit steps until a contact switch closes,
  then hands over to grasping — :func:`tactile_search`.
* **Position and attitude correction** (Fig. 9-12, arrows R1 and R2): when the object touches
  one jaw (or one end of a jaw pad) first, the hand moves (turns) by unit steps towards it until
  both touch together — :func:`correct_position`, :func:`correct_attitude`.
* **Hard, soft and zero grasp** (硬抓取 / 软抓取 / 零抓取) with the grip-force loop of Fig. 9-13:
  a DC motor closes the jaw at a constant speed, and from the contact on a force loop holds the
  grip at the motor's full force (hard), at a set force (soft) or at none (zero) —
  :func:`grasp`.
* **Slip control** (Fig. 9-14): a roller turned by the slipping object emits one pulse per unit
  angle; every pulse raises the grip by one step and the grip is held when the pulses stop —
  :class:`SlipController`, :func:`simulate_slip`.

The book gives these in words and (lost) figures only.  The planar contact geometry, the
closing resolution, the PI force loop and the Coulomb slip model are this module's assumptions,
each stated where it is used.  Units: m, rad, N, s, V.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError
from .motor import DCMotor

__all__ = [
    "CorrectionResult",
    "GraspResult",
    "SearchResult",
    "SlipController",
    "SlipResult",
    "correct_attitude",
    "correct_position",
    "grasp",
    "simulate_slip",
    "tactile_search",
    "GRASP_MODES",
]

GRASP_MODES = ("hard", "soft", "zero")


# ---------------------------------------------------------------------------- tactile search
@dataclass(frozen=True)
class SearchResult:
    """Result of :func:`tactile_search`.

    Attributes
    ----------
    found : bool
        A contact switch closed.
    position : numpy.ndarray
        The hand position where it closed (or the last one tried), m.
    steps : int
        Unit steps taken.
    status : str
        ``"contact"`` or ``"not found"`` (``max_steps`` reached).
    """

    found: bool
    position: np.ndarray
    steps: int
    status: str


def tactile_search(
    contact: Callable, start, direction, step: float, max_steps: int = 1000
) -> SearchResult:
    """Search by unit steps along ``direction`` until ``contact(position)`` is true (Fig. 9-11).

    Parameters
    ----------
    contact : callable
        ``contact(position) -> bool``: the touch sensor at a hand position (m).
    start : array_like
        First position, m (tested before any step).
    direction : array_like
        Search direction (normalised here).
    step : float
        Unit step, m (> 0).
    max_steps : int
        Give up after this many steps (status ``"not found"``).

    Returns
    -------
    SearchResult
    """
    p = _check.array(start, "start")
    d = _check.array(direction, "direction")
    if d.shape != p.shape or not np.any(d):
        raise ControlError(
            f"direction must be a nonzero vector of the shape of start {p.shape}, got {d.shape}"
        )
    d = d / np.linalg.norm(d)
    step = _check.positive(step, "step (m)")
    max_steps = _check.count(max_steps, "max_steps", maximum=_check.MAX_STEPS)
    if not callable(contact):
        raise ControlError(f"contact must be callable, got {_check.short(contact)}")
    with np.errstate(over="ignore", invalid="ignore"):
        far = p + float(max_steps) * step * d
    if not np.all(np.isfinite(far)):
        raise ControlError(
            f"max_steps x step = {max_steps} x {step:g} m from {p.tolist()} leaves the "
            "floating-point range"
        )
    for k in range(max_steps + 1):
        q = p + k * step * d
        if contact(q):
            return SearchResult(True, q, k, "contact")
    return SearchResult(False, q, int(max_steps), "not found")


# ---------------------------------------------------------------------------- corrections
@dataclass(frozen=True)
class CorrectionResult:
    """Result of :func:`correct_position` / :func:`correct_attitude`.

    Attributes
    ----------
    error : float
        The remaining offset (m) or angle (rad) between hand and object.
    corrections : int
        Unit corrections made.
    history : numpy.ndarray
        The error before each correction and after the last.
    status : str
        ``"aligned"`` (both contacts close on the same closing increment) or ``"limit"``.
    """

    error: float
    corrections: int
    history: np.ndarray
    status: str


def _increments(span: float, resolution: float, name: str) -> None:
    """The closing increments of a jaw that travels ``span`` must be countable exactly."""
    with np.errstate(over="ignore"):
        n = span / resolution
    if not n <= 2.0**53:
        raise ControlError(
            f"resolution = {resolution:g} m: the {name} of {span:g} m is {n:.3g} closing "
            "increments, beyond what floating point counts exactly (2**53); give a coarser "
            "resolution"
        )


def _touch_index(gap, resolution):
    """Closing increment (1-based) on which a contact with this gap closes."""
    return math.ceil(gap / resolution - 1e-12)


def _correct(error, unit, gaps, resolution, max_corrections):
    max_corrections = _check.count(max_corrections, "max_corrections", maximum=_check.MAX_STEPS)
    if error + unit == error or error - unit == error:
        raise ControlError(
            f"the correction step unit = {unit:g} is below the floating-point resolution of "
            f"the error {error:g}: no correction would change it"
        )
    hist = [error]
    for k in range(int(max_corrections) + 1):
        ga, gb = gaps(error)
        na, nb = _touch_index(ga, resolution), _touch_index(gb, resolution)
        if na == nb:
            return CorrectionResult(error, k, np.array(hist), "aligned")
        if k == max_corrections:
            break
        # the side that touches first (smaller gap) tells which way to move: reduce the error
        error = error - unit if nb < na else error + unit
        hist.append(error)
    return CorrectionResult(error, int(max_corrections), np.array(hist), "limit")


def correct_position(
    offset: float,
    width: float,
    opening: float,
    unit: float,
    resolution: float,
    max_corrections: int = 1000,
) -> CorrectionResult:
    """Position correction R1 of Fig. 9-12 (a) for a two-jaw gripper closing symmetrically.

    Model (assumed): jaws at ``±opening/2`` about the hand centre close in increments of
    ``resolution``; the object (``width``) sits at ``offset`` from the centre (positive towards
    jaw B).  Jaw A touches after ``(opening/2 − width/2 + offset)/resolution`` increments, jaw B
    after ``(opening/2 − width/2 − offset)/resolution`` (rounded up).  While one jaw touches
    first, the hand moves one ``unit`` towards it (re-opening between tries); it stops when both
    touch on the same increment, which guarantees ``|offset| < resolution``.

    Parameters
    ----------
    offset, width, opening : float
        Object offset, object width, jaw opening (m; ``width + 2|offset| < opening``).
    unit : float
        Correction step, m (> 0).
    resolution : float
        Closing increment, m (> 0).
    max_corrections : int
        Give up after this many corrections (status ``"limit"``).

    Returns
    -------
    CorrectionResult
    """
    offset = _check.scalar(offset, "offset (m)")
    width = _check.positive(width, "width (m)")
    opening = _check.positive(opening, "opening (m)")
    unit = _check.positive(unit, "unit (m)")
    resolution = _check.positive(resolution, "resolution (m)")
    if width + 2 * abs(offset) >= opening:
        raise ControlError(
            f"the object (width {width}, offset {offset}) does not fit between jaws {opening} m "
            "apart"
        )
    half = 0.5 * (opening - width)
    _increments(opening, resolution, "opening")
    return _correct(offset, unit, lambda d: (half + d, half - d), resolution, max_corrections)


def correct_attitude(
    angle: float,
    pad_length: float,
    gap: float,
    unit: float,
    resolution: float,
    max_corrections: int = 1000,
) -> CorrectionResult:
    """Attitude correction R2 of Fig. 9-12 (b): turn the hand until the jaw pad is parallel to
    the object's face.

    Model (assumed): contact switches at the two ends of a pad of length ``pad_length``; the face
    is at ``gap`` from the pad's middle and inclined by ``angle``, so the end gaps are
    ``gap ∓ (pad_length/2) tan(angle)``.  The jaw closes in increments of ``resolution``; while
    one end touches first the hand turns by ``unit`` towards it; it stops when both ends touch on
    the same increment (then ``pad_length |tan angle| < resolution``).

    Parameters
    ----------
    angle : float
        Initial inclination, rad (|angle| < π/2).
    pad_length, gap : float
        Pad length and mid gap, m (> 0; ``gap > (pad_length/2) |tan angle|``).
    unit : float
        Turning step, rad (> 0).
    resolution : float
        Closing increment, m (> 0).
    max_corrections : int
        Give up after this many corrections.

    Returns
    -------
    CorrectionResult
    """
    angle = _check.scalar(angle, "angle (rad)")
    pad = _check.positive(pad_length, "pad_length (m)")
    gap = _check.positive(gap, "gap (m)")
    unit = _check.positive(unit, "unit (rad)")
    resolution = _check.positive(resolution, "resolution (m)")
    if abs(angle) >= 0.5 * math.pi or 0.5 * pad * abs(math.tan(angle)) >= gap:
        raise ControlError(
            f"angle {angle} rad: the pad would already cut into the face (gap {gap} m)"
        )
    _increments(gap + 0.5 * pad * abs(math.tan(angle)), resolution, "gap")
    return _correct(
        angle,
        unit,
        lambda a: (gap + 0.5 * pad * math.tan(a), gap - 0.5 * pad * math.tan(a)),
        resolution,
        max_corrections,
    )


# ---------------------------------------------------------------------------- grasp modes
@dataclass(frozen=True)
class GraspResult:
    """Result of :func:`grasp`; arrays of the shape of ``t``.

    Attributes
    ----------
    mode : str
        ``"hard"``, ``"soft"`` or ``"zero"``.
    t : numpy.ndarray
        Times, s.
    x : numpy.ndarray
        Jaw travel from its start, m.
    force : numpy.ndarray
        Grip force on the object, N.
    V : numpy.ndarray
        Motor voltage, V.
    contact_time : float
        When the jaw reached the object, s (NaN if it did not).
    """

    mode: str
    t: np.ndarray
    x: np.ndarray
    force: np.ndarray
    V: np.ndarray
    contact_time: float


def grasp(
    motor: DCMotor,
    mode: str,
    *,
    gap: float,
    stiffness: float,
    lead: float,
    duration: float,
    approach_speed: float = 0.01,
    set_force: float = 5.0,
    jaw_mass: float = 0.05,
    k_v: float = 100.0,
    k_p: float = 2.0,
    k_i: float = 10.0,
    k_x: float = 2000.0,
    n: int = 2001,
) -> GraspResult:
    """Grip-force control of Fig. 9-13: approach at constant speed, then, from the contact on,
    a force loop ("once it touches the object, the grip-force feedback loop closes").

    Model (assumed): one jaw of mass ``jaw_mass`` driven by ``motor`` (torque–speed line of
    Eq. (9-1) through its gearbox, efficiency η taken in both directions) via a lead of ``lead``
    metres of jaw travel per joint radian, so the jaw force is ``η i τ_m / lead`` and the
    equivalent mass
    ``jaw_mass + i² J_m / lead²``.  The object is a spring of ``stiffness`` (N/m) whose surface
    is ``gap`` ahead of the jaw.

    * before contact: a speed loop with feed-forward, ``V = V_0 + k_v (approach_speed − ẋ)``
      with ``V_0`` the steady voltage of the free jaw at that speed;
    * hard grasp: from contact ``V = V_nom``: the jaw squeezes with the motor's full force,
      at rest the stall force ``η i k_m V_nom / (R lead)``;
    * soft grasp: a PI force loop, ``V = k_p (F_set − F) + k_i ∫(F_set − F) dt``, at rest
      ``F = F_set``;
    * zero grasp: the jaw is held where it touched, ``V = k_x (x_c − x) − k_v ẋ``: it holds the
      object without force (to feel its position or shape).

    V is clipped to ``±V_nom`` throughout.  The phases switch once, at the first contact
    (latched).  Integration: classical Runge–Kutta with a fixed step that resolves the fastest
    linearised mode at the contact.

    Parameters
    ----------
    motor : DCMotor
        The gripper motor (``V_nom`` required).
    mode : str
        ``"hard"``, ``"soft"`` or ``"zero"``.
    gap : float
        Distance to the object, m (> 0).
    stiffness : float
        Object stiffness, N/m (> 0).
    lead : float
        Jaw travel per joint radian, m/rad (> 0).
    duration : float
        Simulated time, s.
    approach_speed, set_force, jaw_mass : float
        Approach speed (m/s), soft-grasp force (N), jaw mass (kg).
    k_v, k_p, k_i, k_x : float
        Speed-loop gain (V·s/m), force-loop gains (V/N, V/(N·s)), position-hold gain (V/m).
    n : int
        Number of output samples.

    Returns
    -------
    GraspResult
    """
    if mode not in GRASP_MODES:
        raise ControlError(f"mode must be one of {GRASP_MODES}, got {mode!r}")
    if not isinstance(motor, DCMotor) or motor.V_nom is None:
        raise ControlError("grasp needs a DCMotor with V_nom")
    gap = _check.positive(gap, "gap (m)")
    K = _check.positive(stiffness, "stiffness (N/m)")
    lead = _check.positive(lead, "lead (m/rad)")
    duration = _check.positive(duration, "duration (s)")
    v0 = _check.positive(approach_speed, "approach_speed (m/s)")
    F_set = _check.nonnegative(set_force, "set_force (N)")
    jaw_mass = _check.positive(jaw_mass, "jaw_mass (kg)")
    with np.errstate(over="ignore", under="ignore"):
        lead2 = lead * lead
        m_eq = jaw_mass + (motor.reflected_inertia / lead2 if lead2 > 0.0 else math.inf)
    if not math.isfinite(m_eq):
        raise ControlError(
            f"lead = {lead:g} m/rad makes the equivalent jaw mass jaw_mass + i^2 J_m / lead^2 "
            "leave the floating-point range; give a physical lead"
        )
    k_v, k_p, k_i, k_x = (
        _check.nonnegative(v, nm)
        for v, nm in ((k_v, "k_v"), (k_p, "k_p"), (k_i, "k_i"), (k_x, "k_x"))
    )
    n = _check.count(n, "n", 2)
    _check.samples(n, 4, f"grasp(n={n})", "give a smaller n")
    Vmax = motor.V_nom
    V0 = float(motor.voltage(0.0, v0 / lead))
    if abs(V0) > Vmax:
        raise ControlError(f"approach_speed {v0} m/s needs {V0:.3g} V, above V_nom = {Vmax} V")

    def force(x):
        return np.where(x > gap, K * (x - gap), 0.0)

    def volts(x, v, z, touching):
        if not touching:
            V = V0 + k_v * (v0 - v)
        elif mode == "hard":
            V = np.full(np.shape(x), Vmax)
        elif mode == "soft":
            V = k_p * (F_set - force(x)) + k_i * z
        else:
            V = k_x * (gap - x) - k_v * v
        return np.clip(V, -Vmax, Vmax)

    def f(s, touching):
        x, v, z = s
        # motoring efficiency in both directions: a smooth model (the power-flow switch of
        # DCMotor.joint_torque is discontinuous at zero speed, where a grasp comes to rest)
        F_m = (
            motor.eta
            * motor.i
            * float(motor.motor_torque(volts(x, v, z, touching), motor.i * v / lead))
            / lead
        )
        Fo = float(force(x))
        return np.array([v, (F_m - Fo) / m_eq, (F_set - Fo) if touching else 0.0])

    # fixed-step classical Runge-Kutta; the step resolves the fastest linearised mode at contact
    s_c = np.array([gap * (1 + 1e-3), 0.0, 0.0])
    eps = np.array([gap * 1e-6, v0 * 1e-6, 1e-6])
    J = np.column_stack(
        [(f(s_c + e, True) - f(s_c - e, True)) / (2 * e.sum()) for e in np.diag(eps)]
    )
    J0 = np.column_stack(
        [(f(s_c + e, False) - f(s_c - e, False)) / (2 * e.sum()) for e in np.diag(eps)]
    )
    lam = max(np.max(np.abs(np.linalg.eigvals(J))), np.max(np.abs(np.linalg.eigvals(J0))), 1e-9)
    t = np.linspace(0.0, duration, int(n))
    sub = max(1, int(np.ceil((t[1] - t[0]) * lam / 0.2)))
    if (n - 1) * sub > 5_000_000:
        raise ControlError(
            f"the grasp needs {(n - 1) * sub} integration steps (stiff object or motor); "
            "shorten the duration or soften the gains"
        )
    h = (t[1] - t[0]) / sub
    X = np.empty((3, t.size))
    touching = np.zeros(t.size, dtype=bool)
    st, on, tc = np.zeros(3), False, float("nan")
    X[:, 0] = st
    for k in range(1, t.size):
        for j in range(sub):
            k1 = f(st, on)
            k2 = f(st + 0.5 * h * k1, on)
            k3 = f(st + 0.5 * h * k2, on)
            k4 = f(st + h * k3, on)
            st = st + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            if not on and st[0] >= gap:  # the contact closes the force loop (latched)
                on, tc = True, float(t[k - 1] + (j + 1) * h)
        if not np.all(np.isfinite(st)):
            raise ControlError(f"the {mode} grasp simulation diverged at t = {t[k]:g} s")
        X[:, k] = st
        touching[k] = on
    x, v, z = X
    V = np.where(touching, volts(x, v, z, True), volts(x, v, z, False))
    return GraspResult(mode, t, x, force(x), V, tc)


# ---------------------------------------------------------------------------- slip control
@dataclass
class SlipController:
    """The slip controller of Fig. 9-14: ``grip += step`` for every roller pulse, capped at
    ``grip_max``; with no pulses the grip is held.

    Parameters
    ----------
    grip : float
        Present grip force, N (≥ 0).
    step : float
        Grip increase per pulse, N (> 0).
    grip_max : float
        Largest grip the hand can give, N.
    """

    grip: float
    step: float
    grip_max: float = math.inf

    def __post_init__(self):
        self.grip = _check.nonnegative(self.grip, "grip (N)")
        self.step = _check.positive(self.step, "step (N)")
        if not (
            isinstance(self.grip_max, (float, np.floating)) and self.grip_max == math.inf
        ):  # +inf (no cap) is the one non-finite value allowed
            self.grip_max = _check.positive(self.grip_max, "grip_max (N)")

    def update(self, pulses: int) -> float:
        """Take ``pulses`` new roller pulses (≥ 0) and return the new grip force, N."""
        pulses = _check.count(pulses, "pulses")
        try:
            grip = self.grip + float(pulses) * self.step
        except OverflowError:
            grip = math.inf
        grip = min(grip, self.grip_max)
        if not math.isfinite(grip):
            raise ControlError(
                f"pulses = {pulses} x step = {self.step:g} N takes the grip beyond the "
                "floating-point range (set grip_max)"
            )
        self.grip = grip
        return self.grip


@dataclass(frozen=True)
class SlipResult:
    """Result of :func:`simulate_slip`.

    Attributes
    ----------
    grip : float
        Final grip force, N.
    pulses : int
        Roller pulses emitted.
    slip : float
        Distance the object slid, m.
    pulse_times : numpy.ndarray
        When each pulse came, s.
    stop_time : float
        When the object stopped, s (inf if it did not).
    status : str
        ``"held"`` or ``"dropped"`` (still sliding at ``grip_max`` after ``max_slip``).
    """

    grip: float
    pulses: int
    slip: float
    pulse_times: np.ndarray
    stop_time: float
    status: str


def simulate_slip(
    mass: float,
    mu: float,
    controller: SlipController,
    unit: float,
    *,
    n_jaws: int = 2,
    g: float = 9.81,
    max_slip: float = 0.1,
) -> SlipResult:
    """An object held by friction slides down until the slip controller's grip holds it.

    Model (assumed): Coulomb friction, static = kinetic coefficient ``mu`` on ``n_jaws`` jaws;
    while sliding ``m a = m g − n μ F``; the roller emits a pulse at every ``unit`` of slide
    (roller radius × unit angle) and the controller raises the grip at once.  Between pulses
    the acceleration is constant, so the motion is integrated exactly, event by event.

    Parameters
    ----------
    mass : float
        Object mass, kg.
    mu : float
        Friction coefficient (> 0).
    controller : SlipController
        Its ``grip`` is the initial grip (changed in place).
    unit : float
        Slide per roller pulse, m (> 0).
    n_jaws : int
        Friction surfaces.
    g : float
        Gravity, m/s².
    max_slip : float
        Give up (``"dropped"``) after this slide, m.

    Returns
    -------
    SlipResult
    """
    m = _check.positive(mass, "mass (kg)")
    mu = _check.positive(mu, "mu")
    unit = _check.positive(unit, "unit (m)")
    g = _check.positive(g, "g (m/s^2)")
    max_slip = _check.positive(max_slip, "max_slip (m)")
    n_jaws = _check.count(n_jaws, "n_jaws", 1, maximum=1000)
    if max_slip / unit > 1e7:
        raise ControlError(
            f"max_slip / unit = {max_slip / unit:.3g} pulses is too many to simulate (at most 1e7)"
        )
    if not isinstance(controller, SlipController):
        raise ControlError("controller must be a SlipController")
    t, s, v = 0.0, 0.0, 0.0
    times: list[float] = []
    while True:
        a = g - n_jaws * mu * controller.grip / m
        if v <= 0.0 and a <= 0.0:
            return SlipResult(controller.grip, len(times), s, np.array(times), t, "held")
        target = (len(times) + 1) * unit
        d = target - s
        if a < 0.0 and v * v / (-2.0 * a) < d:  # stops before the next pulse
            tau = v / (-a)
            return SlipResult(
                controller.grip,
                len(times),
                s + v * tau + 0.5 * a * tau * tau,
                np.array(times),
                t + tau,
                "held",
            )
        # time to slide d: 0.5 a τ² + v τ − d = 0 (the positive root, written without cancellation)
        disc = v * v + 2.0 * a * d
        tau = 2.0 * d / (v + math.sqrt(max(disc, 0.0)))
        t, s, v = t + tau, target, v + a * tau
        times.append(t)
        controller.update(1)
        if s >= max_slip:
            a = g - n_jaws * mu * controller.grip / m
            if a > 0.0:
                return SlipResult(
                    controller.grip, len(times), s, np.array(times), math.inf, "dropped"
                )
