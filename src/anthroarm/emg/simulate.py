r"""Closed-loop simulation of the book's 3-DOF EMG upper-arm hand (§9-2 三 2, Fig. 9-25).

EMG (2 channels, flexor and extensor) → :class:`~anthroarm.emg.processor.EMGProcessor`
(envelopes, thresholds, codes 00/01/10/11) → :class:`~anthroarm.emg.codes.CodeMachine`
(modes, commands, vibrators) → **set-points** → one analog **position servo** per joint
(:class:`anthroarm.control.servo.PositionServo`, Eqs. (9-1)–(9-8)) → the joints of an arm
(Pinocchio's ``aba`` with the motors' reflected inertia as armature, integrated by
:func:`anthroarm.dynamics.simulate.simulate`) and a one-DOF hand that can close on an object.

How a command moves a joint (assumptions; the book prints the codes, not the drive law):

* a command ±1 moves the selected joint's **set-point** at ``speed`` rad/s (default 1.5)
  inside the joint's limits; 0 holds it.  The servo tracks the set-point; its loop is closed
  by the potentiometer and tachogenerator of Eq. (9-4), its torque limited by the amplifier
  limit ``V_max`` (the battery);
* the servo of each arm joint is tuned critically damped (ζ = 1) for the joint's inertia at
  the start, ``M(q0)[j, j]``, with ω_n the larger of 20 rad/s and what the motor's own
  back-EMF damping allows (:meth:`~anthroarm.control.servo.PositionServo.tuned`); the motor is a
  16 mm coreless DC micromotor (:func:`prosthesis_motor`, illustrative values: no-load speed
  ≈ 9550 r/min, inside the 4700–13550 r/min of the book's coreless motors, §9-3) behind a
  gearbox of :data:`DEFAULT_RATIOS`, raised where needed so that the stall torque is at least
  twice the joint's gravity load at ``q0`` (a sizing margin);
* the joints of the arm that are not driven are **locked** where ``q0`` puts them (the
  wearer's own shoulder holds the socket still); the driven joints start at rest at ``q0``,
  their servos settled there (set-point ``q0 + g(q0)/K_s``, Eq. (9-8), with Pinocchio's gravity
  torque ``g``);
* the hand ("fingers") is a one-DOF servo joint with its own inertia
  (:class:`HandModel`) when the arm has no finger joint: closing on an object at
  ``object_angle`` meets a Kelvin–Voigt contact (stiffness and damping, assumptions).  Its
  set-point stops ``max_lead`` rad ahead of the measured angle (anti-windup), so the hand opens
  at once when told to.  **Grasp** (the middle vibrator, book §9-2) is the book's other
  servo idea: at rest (|θ̇| small) the servo error reveals the load torque, Eq. (9-8)
  (:meth:`~anthroarm.control.servo.PositionServo.estimate_load_torque`); above
  ``grasp_torque`` the hand holds an object; fully closed counts as "gripped tight" too.
  While the amplifier is saturated (squeezing at the battery voltage) the linear estimate
  overstates the load; a threshold is all the vibrator needs.

The algorithm reads joints by the names given in ``joints`` (mode → a joint name of
``robot.chain``, several names that move together — the finger joints of a hand model — or
``None`` for the built-in hand); it never looks at the arm's name.  SI
units: V, s, rad, N·m.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..control.motor import DCMotor
from ..control.servo import PositionServo
from ..dynamics.simulate import simulate
from ..errors import EMGError, ParameterError, UnsupportedModelError
from ..robot import Robot, load
from ._checks import signal
from .codes import VIBRATORS, CodeMachine, CodeTrace, vibrators_with_grasp
from .processor import EMGProcessor, ProcessedEMG

#: default speed of a commanded set-point, rad/s (assumption)
DEFAULT_SPEED = 1.5
#: gear ratio per mode of the default motors (assumption)
DEFAULT_RATIOS = {"elbow": 500.0, "wrist": 100.0, "fingers": 200.0}
#: the most arm integration steps one run may take (t_end / dt)
MAX_STEPS = 1_000_000


def prosthesis_motor(i: float = 200.0, eta: float = 0.7):
    """A 16 mm coreless DC micromotor behind a gearbox of ratio ``i`` and efficiency ``eta``
    (:class:`anthroarm.control.motor.DCMotor`): R = 5 Ω, k_m = 6 mN·m/A, J_m = 0.6 g·cm²,
    6 V (a prosthesis battery).  Illustrative values in the range of such motors' data
    sheets, an assumption; no-load speed V/k_m = 1000 rad/s ≈ 9550 r/min."""
    return DCMotor(
        R=5.0, k_m=6e-3, J_m=6e-8, i=float(i), eta=float(eta), V_nom=6.0, name="16 mm coreless"
    )


def joint_servo(motor, J_L: float, omega_n_min: float = 20.0):
    """A critically damped :class:`~anthroarm.control.servo.PositionServo` of ``motor`` for a
    load inertia ``J_L`` (kg·m²), amplifier limited to ``motor.V_nom``: ω_n is the larger of
    ``omega_n_min`` and 1.05 × the motor's own damping limit (below it no tachogenerator gain
    gives ζ = 1)."""
    bare = PositionServo.from_motor(
        motor, J_L, k_a=1.0, k_p=1.0
    )  # k_s = 0: the motor's damping only
    omega_n = max(float(omega_n_min), 1.05 * bare.Kv / (2.0 * bare.J0))
    return PositionServo.tuned(motor, J_L, omega_n=omega_n, zeta=1.0, V_max=motor.V_nom)


@dataclass(frozen=True)
class HandModel:
    """The one-DOF hand used when the arm has no finger joint (assumptions, SI units).

    ``J_L`` hand-mechanism inertia at the output (kg·m²); ``lower``/``upper`` open and
    closed angles (rad); ``object_angle`` where the fingers touch an object (rad, ``None``:
    nothing to grasp); ``contact_stiffness`` (N·m/rad) and ``contact_damping`` (N·m·s/rad) of
    the object; ``max_lead`` the set-point's largest lead on the measured angle (rad);
    ``grasp_torque`` (N·m) the estimated load that counts as a grasp; ``still`` (rad/s) the
    speed below which the servo error is read as a load."""

    J_L: float = 1e-4
    lower: float = 0.0
    upper: float = 1.4
    object_angle: float | None = 0.9
    contact_stiffness: float = 5.0
    contact_damping: float = 0.02
    max_lead: float = 0.3
    grasp_torque: float = 0.1
    still: float = 0.05

    def __post_init__(self):
        vals = {
            k: getattr(self, k)
            for k in (
                "J_L",
                "lower",
                "upper",
                "contact_stiffness",
                "contact_damping",
                "max_lead",
                "grasp_torque",
                "still",
            )
        }
        for k, v in vals.items():
            if not (isinstance(v, (int, float, np.floating, np.integer)) and np.isfinite(v)):
                raise ParameterError(f"HandModel.{k} must be a finite number, got {v!r}")
        for k in ("J_L", "max_lead", "grasp_torque", "still"):
            if vals[k] <= 0:
                raise ParameterError(f"HandModel.{k} must be > 0, got {vals[k]!r}")
        for k in ("contact_stiffness", "contact_damping"):
            if vals[k] < 0:
                raise ParameterError(f"HandModel.{k} must be >= 0, got {vals[k]!r}")
        if not self.lower < self.upper:
            raise ParameterError(
                f"HandModel: lower ({self.lower}) must be below upper ({self.upper}) rad"
            )
        oa = self.object_angle
        if oa is not None and not (
            isinstance(oa, (int, float, np.floating)) and self.lower <= oa <= self.upper
        ):
            raise ParameterError(
                f"HandModel.object_angle must be None or in [lower, upper] = "
                f"[{self.lower}, {self.upper}] rad, got {oa!r}"
            )

    def contact_torque(self, theta, omega):
        """Load torque of the object on the closing fingers (N·m, ≥ 0)."""
        if self.object_angle is None:
            return np.zeros_like(np.asarray(theta, dtype=float))
        pen = np.asarray(theta, dtype=float) - self.object_angle
        return np.where(
            pen > 0,
            np.maximum(self.contact_stiffness * pen + self.contact_damping * omega, 0.0),
            0.0,
        )


@dataclass
class PoweredHandResult:
    """Everything of one run, per control frame (``t`` s) unless said otherwise.

    ``processed`` (:class:`~anthroarm.emg.processor.ProcessedEMG`) and ``trace``
    (:class:`~anthroarm.emg.codes.CodeTrace`) are the signal chain; ``modes`` the mode names,
    ``joint_names`` the driven joint of each (``"hand"`` for the built-in hand);
    ``setpoint``/``angle`` (frames, n_modes) rad (of each mode's first joint); ``q`` (frames,
    robot.nq) the whole arm's configuration; ``grasped`` (frames,) bool; ``load_estimate`` (frames,) N·m the hand
    servo's load estimate (Eq. (9-8)); ``vibrators`` (frames, 3) left/right/middle;
    ``emg`` (channels, samples) and ``t_emg`` the input; ``servos`` mode →
    :class:`~anthroarm.control.servo.PositionServo` of its (first) joint, ``joint_servos`` joint
    name → servo for every driven joint of the arm; ``hand`` the :class:`HandModel`
    (``None`` without a built-in hand); ``status`` "ok" or what went wrong (the dynamics' or
    the hand integrator's status)."""

    t: np.ndarray
    processed: ProcessedEMG
    trace: CodeTrace
    modes: tuple
    joint_names: tuple
    setpoint: np.ndarray
    angle: np.ndarray
    q: np.ndarray
    grasped: np.ndarray
    load_estimate: np.ndarray
    vibrators: np.ndarray
    emg: np.ndarray
    t_emg: np.ndarray
    robot: object = field(repr=False, default=None)
    servos: dict = field(default_factory=dict)
    joint_servos: dict = field(default_factory=dict)
    hand: HandModel | None = None
    status: str = "ok"

    def plot(self, fig=None):
        """EMG, envelopes with thresholds, codes, mode and commands, joint angles (set-point
        dashed) and vibrators on one time axis; returns the matplotlib figure."""
        import matplotlib.pyplot as plt

        if fig is None:
            fig = plt.figure(figsize=(9, 9.5))
        ax = fig.subplots(
            5, 1, sharex=True, gridspec_kw=dict(height_ratios=[1.2, 1.2, 0.7, 0.8, 1.5])
        )
        names = ("flexor", "extensor")
        for c in range(self.emg.shape[0]):
            ax[0].plot(
                self.t_emg,
                self.emg[c] * 1e6,
                lw=0.4,
                alpha=0.8,
                label=names[c] if c < 2 else f"ch {c}",
            )
        ax[0].set_ylabel("EMG [µV]")
        ax[0].legend(fontsize=7, loc="upper right")
        p = self.processed
        for c in range(p.envelope_pp.shape[0]):
            (line,) = ax[1].plot(
                self.t, p.envelope_pp[c] * 1e6, label=f"{names[c] if c < 2 else c} envelope"
            )
            ax[1].axhline(p.on_pp[c] * 1e6, color=line.get_color(), ls="--", lw=0.8)
            ax[1].axhline(p.off_pp[c] * 1e6, color=line.get_color(), ls=":", lw=0.8)
        ax[1].set_ylabel("p-p [µV]")
        ax[1].legend(
            fontsize=7, loc="upper right", title="-- on, ··· off threshold", title_fontsize=7
        )
        ax[2].step(self.t, p.code, where="post", color="0.6", lw=0.8, label="raw")
        ax[2].step(self.t, self.trace.code, where="post", color="k", label="debounced")
        ax[2].set_yticks([0, 1, 2, 3], ["00", "01", "10", "11"])
        ax[2].set_ylabel("code")
        ax[2].legend(fontsize=7, loc="upper right")
        ax[3].step(self.t, self.trace.mode, where="post", label="mode")
        ax[3].step(self.t, self.trace.command, where="post", label="command")
        ax[3].set_yticks(
            range(-1, len(self.modes)),
            ["−1"] + [f"{i}: {m}" if i else f"0: {m}" for i, m in enumerate(self.modes)],
        )
        for k, col in enumerate(VIBRATORS):
            on = self.vibrators[:, k]
            if on.any():
                ax[3].fill_between(
                    self.t,
                    -1,
                    len(self.modes) - 1,
                    where=on,
                    step="post",
                    alpha=0.15,
                    label=f"{col} vibrator",
                )
        ax[3].set_ylabel("mode / command")
        ax[3].legend(fontsize=7, loc="upper right", ncol=2)
        for j, m in enumerate(self.modes):
            (line,) = ax[4].plot(self.t, self.angle[:, j], label=f"{m} ({self.joint_names[j]})")
            ax[4].plot(self.t, self.setpoint[:, j], ls="--", lw=0.8, color=line.get_color())
        ax[4].set_ylabel("angle [rad]")
        ax[4].set_xlabel("t [s]")
        ax[4].legend(fontsize=7, loc="upper right")
        fig.suptitle(f"EMG-driven hand: {self.status}", fontsize=10)
        fig.tight_layout()
        return fig


def _setpoints(
    trace: CodeTrace, j: int, speed: float, lo: float, hi: float, start: float
) -> np.ndarray:
    """The set-point of mode ``j`` per frame: it moves at ``speed`` while ``trace`` commands
    this mode, clipped to [lo, hi]."""
    step = speed * trace.frame_s * trace.command * (trace.mode == j)
    out = np.empty(step.size)
    s, last = start, 0
    for k in np.flatnonzero(step):  # only frames that move; the rest hold
        out[last:k] = s
        s = min(max(s + step[k], lo), hi)
        last = k
    out[last:] = s
    return out


def simulate_powered_hand(
    robot,
    emg,
    fs: float,
    joints: dict,
    *,
    q0=None,
    processor: EMGProcessor | None = None,
    machine: CodeMachine | None = None,
    servos: dict | None = None,
    speeds: dict | None = None,
    hand: HandModel | None = None,
    dt: float = 1e-3,
) -> PoweredHandResult:
    """Run EMG → codes → servos → arm and hand (see the module text).

    Parameters
    ----------
    robot
        An :class:`~anthroarm.robot.Robot` (or anything :func:`anthroarm.load` takes).
    emg
        (2, samples) volts at the electrodes: channel 0 flexor, channel 1 extensor.
    fs
        Sampling rate, Hz.
    joints
        Mode name → joint name of ``robot.chain``, a list of joint names that move together
        (e.g. the finger flexion joints of a hand model) or ``None`` (the built-in hand), in the
        mode cycle order, e.g. ``{"elbow": "elbow_flexion", "wrist": "forearm_rotation",
        "fingers": None}``.
    q0
        Initial configuration (robot.nq); non-driven joints stay locked there.  Default: the
        driven joints at the middle of [max(lower, 0), upper] clipped to their limits, the
        others at 0 clipped to their limits.
    processor, machine
        The signal chain and state machine (defaults: ``EMGProcessor(fs)``,
        ``CodeMachine(frame_s, modes=tuple(joints))``).  Both are reset at the start of the run;
        they are stateful, so do not share them between threads or concurrent runs.
    servos
        Mode → :class:`~anthroarm.control.servo.PositionServo` for each joint of the mode
        (default: :func:`joint_servo` of :func:`prosthesis_motor` per joint).  A given servo's ``J_L`` is only used for its gains; the
        arm's inertia is the dynamics'.
    speeds
        Mode → set-point speed, rad/s (default :data:`DEFAULT_SPEED`).
    hand
        :class:`HandModel` of the built-in hand.
    dt
        Integration step of the arm (s).

    Returns
    -------
    PoweredHandResult
    """
    from scipy.integrate import solve_ivp

    robot = robot if isinstance(robot, Robot) else load(robot)
    if not isinstance(joints, dict) or not joints:
        raise ParameterError(
            "joints maps each mode name to a joint name of the robot or None, e.g. "
            "{'elbow': 'elbow_flexion', 'wrist': 'forearm_rotation', 'fingers': None}"
        )
    modes = tuple(joints)
    if sum(v is None for v in joints.values()) > 1:
        raise ParameterError("at most one mode can be the built-in hand (None)")
    processor = processor if processor is not None else EMGProcessor(fs, 2)
    if processor.n_channels != 2 or abs(processor.fs - float(fs)) > 1e-9 * float(fs):
        raise EMGError(
            f"the processor must take 2 channels at fs = {fs} Hz (has {processor.n_channels} at "
            f"{processor.fs} Hz)"
        )
    machine = machine if machine is not None else CodeMachine(processor.frame_s, modes=modes)
    if machine.modes != modes:
        raise ParameterError(
            f"the machine's modes {machine.modes} differ from the joints' modes {modes}"
        )
    hand = hand if hand is not None else HandModel()
    if not isinstance(hand, HandModel):
        raise ParameterError(f"hand must be a HandModel, got {type(hand).__name__}")
    speeds = {m: DEFAULT_SPEED for m in modes} | dict(speeds or {})
    for m, v in speeds.items():
        if m not in modes or not (
            isinstance(v, (int, float, np.integer, np.floating)) and np.isfinite(v) and v > 0
        ):
            raise ParameterError(
                f"speeds: mode {m!r} must be one of {modes} with a finite speed > 0 rad/s, got {v!r}"
            )
    for m, sv in (servos or {}).items():
        if m not in modes or not isinstance(sv, PositionServo):
            raise ParameterError(
                f"servos: mode {m!r} must be one of {modes} with a PositionServo, got {sv!r}"
            )
    if not (
        isinstance(dt, (int, float, np.integer, np.floating))
        and np.isfinite(dt)
        and 0 < dt <= processor.frame_s
    ):
        raise ParameterError(
            f"dt must be a finite step > 0 s and at most one control frame ({processor.frame_s:g} s), "
            f"got {dt!r}"
        )

    chain = robot.chain
    names = {}
    for m, v in joints.items():
        seq = () if v is None else ((v,) if isinstance(v, str) else tuple(v))
        if v is not None and (not seq or not all(isinstance(n, str) for n in seq)):
            raise ParameterError(
                f"joints[{m!r}] must be a joint name, a list of joint names or None, got {v!r}"
            )
        names[m] = seq
    drives = [(m, chain.joint(n)) for m in modes for n in names[m]]  # (mode, joint), mode order
    seen = [jt.name for _, jt in drives]
    if len(set(seen)) != len(seen):
        raise ParameterError(
            f"a joint is driven by two modes: {sorted(n for n in set(seen) if seen.count(n) > 1)}"
        )
    for m, jt in drives:
        if jt.kind == "continuous" or jt.is_mimic:
            raise UnsupportedModelError(
                f"joint {jt.name!r} ({m}) is {jt.kind}{' mimic' if jt.is_mimic else ''}; "
                "a driven joint must be a revolute or prismatic joint with its own q"
            )
    if q0 is None:
        q0 = np.zeros(robot.nq)
        for jt in chain.joints:
            if jt.nq == 1:
                q0[jt.idx_q] = np.clip(0.0, jt.lower, jt.upper)
        for _, jt in drives:
            lo = max(jt.lower, 0.0) if np.isfinite(jt.lower) else 0.0
            hi = jt.upper if np.isfinite(jt.upper) else lo + 1.0
            q0[jt.idx_q] = 0.5 * (lo + hi)
    q0 = robot.check_q(q0, "q0")
    if q0.ndim != 1:
        raise ParameterError(f"q0 must be one configuration ({robot.nq},), got {q0.shape}")

    # ---- signal chain
    x = signal(emg, "emg", 2, bytes_per_value=40.0)  # complex, gaps, budget: refused here
    proc = processor.process(x)  # reset=True: the run starts from rest
    machine.reset()  # so does the state machine (a reused one kept its mode)
    trace = machine.run(proc.code)
    t = proc.t_frames
    n_f = t.size
    if n_f < 2:
        raise EMGError(f"the EMG is shorter than two control frames ({processor.frame_s} s each)")
    if drives and t[-1] / dt > MAX_STEPS:
        raise ParameterError(
            f"{t[-1]:g} s of EMG at dt = {dt:g} s is {t[-1] / dt:.3g} integration steps, more than "
            f"{MAX_STEPS:.0e}: raise dt or cut the recording"
        )

    # ---- the arm: driven joints free, the others locked at q0
    locked = {
        jt.name: float(q0[jt.idx_q]) for jt in chain.joints if jt.nq == 1 and jt.name not in seen
    }
    setpoint = np.zeros((n_f, len(modes)))
    angle = np.zeros((n_f, len(modes)))
    q_out = np.repeat(q0[None, :], n_f, axis=0)
    status = "ok"
    used, per_joint = {}, {}
    if drives:
        red = load(robot.model, locked=locked, tool=robot.tool) if locked else robot
        rq0 = np.array([q0[chain.joint(red.chain.joints[k].name).idx_q] for k in range(red.nq)])
        M0 = pin.crba(red.model, red.model.createData(), rq0)
        col = [red.chain.joint(jt.name).idx_v for _, jt in drives]
        g0 = pin.computeGeneralizedGravity(red.model, red.model.createData(), rq0)
        per_ratio = prosthesis_motor(1.0).stall_torque()  # N m of stall torque per unit of i
        srv = []
        for (m, jt), c in zip(drives, col):
            given = (servos or {}).get(m)
            # the gearbox: the mode's default ratio, raised (in steps of 50) until the stall torque is
            # at least twice the gravity load at q0 (a sizing margin, an assumption)
            i = max(
                DEFAULT_RATIOS.get(m, 200.0),
                50.0 * np.ceil(2.0 * abs(float(g0[c])) / per_ratio / 50.0),
            )
            srv.append(given or joint_servo(prosthesis_motor(i), float(M0[c, c])))
            per_joint[jt.name] = srv[-1]
            used.setdefault(m, srv[-1])  # a mode's first joint
        model = red.model.copy()
        for c, sv in zip(col, srv):
            model.armature[c] += sv.J0 - sv.J_L  # reflected motor inertia, eta i^2 J_m
        # the servos have settled at q0: each set-point starts at q0 + M_L / K_s, Eq. (9-8),
        # with M_L the gravity torque Pinocchio gives there
        start = [
            float(q0[jt.idx_q]) + float(g0[c]) / sv.Ks for (_, jt), c, sv in zip(drives, col, srv)
        ]
        sp = [
            _setpoints(trace, modes.index(m), speeds[m], jt.lower, jt.upper, s0)
            for (m, jt), s0 in zip(drives, start)
        ]

        def tau(tt, q, qd):
            k = min(max(int(np.searchsorted(t, tt, side="right")) - 1, -1), n_f - 1)
            out = np.zeros(red.nv)
            for c, sv, spi, s0 in zip(col, srv, sp, start):
                ti = spi[k] if k >= 0 else s0
                # the servo's output torque eta i M_m of Eqs. (9-1)-(9-4): J_0 * theta_ddot at zero load
                out[c] = sv.J0 * sv.rhs(np.array([q[c], qd[c]]), ti, 0.0)[1]
            return out

        sim = simulate(
            red, rq0, np.zeros(red.nv), float(t[-1]), dt=dt, tau=tau, engine="pin", pin_model=model
        )
        status = sim.status
        first = set()
        for (m, jt), c, spi in zip(drives, col, sp):
            a = np.interp(t, sim.t, sim.q[:, c])
            q_out[:, jt.idx_q] = a
            if m not in first:  # the mode's columns: its first joint
                first.add(m)
                j = modes.index(m)
                angle[:, j], setpoint[:, j] = a, spi

    # ---- the built-in hand
    grasped = np.zeros(n_f, dtype=bool)
    load_est = np.zeros(n_f)
    hand_modes = [m for m in modes if not names[m]]
    if hand_modes:
        m = hand_modes[0]
        j = modes.index(m)
        hs = (servos or {}).get(m) or joint_servo(
            prosthesis_motor(DEFAULT_RATIOS.get(m, 200.0)), hand.J_L
        )
        used[m] = hs
        cmd = trace.command * (trace.mode == j)
        v = speeds[m]

        def rhs(tt, s):
            th, om, ti = s
            k = int(np.searchsorted(t, tt, side="right")) - 1
            c = cmd[k] if k >= 0 else 0
            rate = 0.0
            if c > 0 and ti < hand.upper and ti - th < hand.max_lead:
                rate = v
            elif c < 0 and ti > hand.lower and th - ti < hand.max_lead:
                rate = -v
            d = hs.rhs(np.array([th, om]), ti, float(hand.contact_torque(th, om)))
            return [d[0], d[1], rate]

        th0 = float(hand.lower)
        sol = solve_ivp(
            rhs,
            (0.0, float(t[-1])),
            [th0, 0.0, th0],
            t_eval=t,
            max_step=processor.frame_s,
            rtol=1e-6,
            atol=1e-9,
        )
        if not sol.success:
            status = f"hand: {sol.message}"
        th, om, ti = sol.y
        angle[:, j], setpoint[:, j] = th, np.clip(ti, hand.lower, hand.upper)
        load_est = hs.estimate_load_torque(hs.k_p * (ti - th))
        grasped = ((load_est >= hand.grasp_torque) & (np.abs(om) < hand.still)) | (
            th >= hand.upper - 0.02
        )
    vib = vibrators_with_grasp(trace, grasped)
    return PoweredHandResult(
        t=t,
        processed=proc,
        trace=trace,
        modes=modes,
        joint_names=tuple(n if n is not None else "hand" for n in joints.values()),
        setpoint=setpoint,
        angle=angle,
        q=q_out,
        grasped=grasped,
        load_estimate=load_est,
        vibrators=vib,
        emg=x,
        t_emg=np.arange(x.shape[1]) / fs,
        robot=robot,
        servos=used,
        joint_servos=per_joint,
        hand=hand if hand_modes else None,
        status=status,
    )
