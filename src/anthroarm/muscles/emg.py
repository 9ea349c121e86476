r"""EMG-driven muscles: a surface-EMG recording → neural excitation → muscle activation →
Hill-type forces → joint torques, and beside them the torque an activity needs.

The chain (Lloyd & Besier, *An EMG-driven musculoskeletal model to estimate muscle forces and
knee joint moments in vivo*, J Biomech 36 (2003) 765-776; Buchanan, Lloyd, Manal & Besier,
*Neuromusculoskeletal modeling: estimation of muscle forces and joint moments and movements
from measurements of neural command*, J Appl Biomech 20 (2004) 367-395):

1. **Excitation** e(t) ∈ [0, 1] (:func:`excitation`): the raw EMG band-passed (Butterworth,
   20–450 Hz, :func:`anthroarm.emg.bandpass_sos`), full-wave rectified and low-passed (6 Hz)
   by the book's Chapter 9 linear envelope (:func:`anthroarm.emg.lowpass_envelope`, causal),
   divided by the envelope of a maximum voluntary contraction (``mvc``; default: the
   recording's own peak — an assumption: the recording carries no MVC trial).
2. **Neural activation** u(t) (:func:`neural_activation`): first-order activation dynamics,
   with the activation-level-dependent time constants of Thelen (2003, Eq. 7; J Biomech Eng 125
   70-77) as OpenSim's ``MuscleFirstOrderActivationDynamicModel`` evaluates them:

   .. math::
      \dot u = \frac{e - u}{\tau(e, u)}, \qquad
      \tau = \begin{cases} \tau_{act}\,(0.5 + 1.5u) & e > u \\
                           \tau_{deact} / (0.5 + 1.5u) & e \le u \end{cases}

   (τ_act = 15 ms, τ_deact = 50 ms, OpenSim's defaults).  The excitation is held constant
   between samples and each step is integrated **exactly**: with c = 0.5 + 1.5e and
   w = |e − u|, deactivation gives w/(c + 1.5w) = w₀/(c + 1.5w₀)·exp(−c Δt/τ_deact) (explicit)
   and activation c ln(w/w₀) − 1.5(w − w₀) = −Δt/τ_act, solved by Lambert's W:
   w = −(c/1.5) W₀(−(1.5/c) w₀ exp(−1.5w₀/c − Δt/(c τ_act))).  u stays in [0, 1].
3. **Muscle activation** a(t) (:func:`activation_shape`): the nonlinear EMG-to-activation
   relation of Lloyd & Besier (2003, Eq. 4) and Buchanan et al. (2004, Eq. 12),
   a = (e^{A u} − 1)/(e^{A} − 1), shape factor −3 < A < 0 (A → 0: linear).
4. **Forces and torques** (:func:`drive`): the Thelen2003 muscles at static equilibrium with
   activation a (:func:`anthroarm.muscles.equilibrium`, the muscle's length from its path),
   joint torques τ = R(q)ᵀ f (:func:`anthroarm.muscles.joint_torques`).  Static: the fibre
   velocity is taken as zero (force–velocity 1).

:func:`needed_torques` gives the torque the activity needs (inverse dynamics of the motion with
a held load, :func:`anthroarm.dynamics.loads.inverse_dynamics`), and :func:`plot` the two side
by side with the difference a motor must add.

Bad input — EMG with NaN, a time gap, unsorted times, excitations or activations outside
[0, 1] — raises :class:`~anthroarm.errors.EMGError` or :class:`~anthroarm.errors.MuscleError`;
a torque is never NaN.

The shipped recording :data:`SAMPLE` is one surface electrode on a right biceps brachii
(Kinetics Toolkit, Apache-2.0; see ``data/emg/CREDITS.md``): :func:`read_recording`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.special import lambertw

from .._io import read_bounded
from ..dynamics.loads import HeldObject, inverse_dynamics
from ..emg import bandpass_sos, lowpass_envelope
from ..errors import EMGError, MuscleError
from .hill import check_activation, joint_torques
from .paths import muscle_set

#: the shipped surface EMG of a right biceps brachii (see ``data/emg/CREDITS.md``)
SAMPLE = Path(__file__).resolve().parents[1] / "data" / "emg" / "emg_biceps_brachii.csv"
#: a time step longer than this many median steps is a gap in the recording
MAX_GAP = 1.5
#: the largest recording file read (bytes)
MAX_RECORDING_BYTES = 256 * 2**20
#: OpenSim's ``MuscleFirstOrderActivationDynamicModel`` defaults (s)
TAU_ACT, TAU_DEACT = 0.015, 0.050


@dataclass(frozen=True)
class Recording:
    """A surface-EMG recording: times ``t`` (N,) s, ``emg`` (C, N) V (channels, samples),
    ``channels`` names, sampling rate ``fs`` Hz (1 / the median step)."""

    t: np.ndarray
    emg: np.ndarray
    channels: list
    fs: float
    name: str = ""


def check_recording(t, emg) -> float:
    """The sampling rate (Hz) of times ``t`` (N,) s and ``emg`` (N,) or (C, N) V;
    :class:`~anthroarm.errors.EMGError` for NaN or infinite values (naming the sample), times
    not strictly increasing, or a gap (a step over :data:`MAX_GAP` median steps)."""
    t = np.asarray(t, dtype=float)
    x = np.atleast_2d(np.asarray(emg, dtype=float))
    if t.ndim != 1 or t.size < 8 or x.ndim != 2 or x.shape[-1] != t.size:
        raise EMGError(
            f"a recording needs times (N,) with N >= 8 and EMG (N,) or (channels, N); got "
            f"{t.shape} and {np.shape(emg)}"
        )
    for what, arr in (("time", t[None]), ("EMG", x)):
        bad = ~np.isfinite(arr)
        if bad.any():
            k = int(np.argwhere(bad)[0][-1])
            raise EMGError(
                f"{what} sample {k} (t = {t[k] if np.isfinite(t[k]) else 'nan'}) is not a "
                "number: fill or cut the gap before the envelope"
            )
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise EMGError(f"times must increase strictly: t[{k + 1}] = {t[k + 1]} after {t[k]}")
    step = float(np.median(dt))
    if dt.max() > MAX_GAP * step:
        k = int(np.argmax(dt))
        raise EMGError(
            f"a gap of {dt[k]:.4g} s after t = {t[k]:.6g} s (the median step is {step:.3g} s): "
            "the filters assume evenly spaced samples; cut the recording or fill the gap"
        )
    return 1.0 / step


def read_recording(path=SAMPLE) -> Recording:
    """A CSV recording: a header ``Time,<channel>,...`` (s, V), one sample per line; checked by
    :func:`check_recording`.  Default: the shipped biceps brachii (:data:`SAMPLE`)."""
    path = Path(path)

    def bad(problem):
        return EMGError(f"{path}: {problem}")

    text = read_bounded(path, MAX_RECORDING_BYTES, error=bad, what="EMG recording")
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    if len(lines) < 2:
        raise bad("no samples: a header 'Time,<channel>...' and one sample per line")
    header = [h.strip() for h in lines[0].split(",")]
    if len(header) < 2 or header[0].lower() not in ("time", "t"):
        raise bad(f"the header must start with 'Time' then channel names, got {header}")
    rows = []
    for k, ln in enumerate(lines[1:], start=2):
        fields = ln.split(",")
        if len(fields) != len(header):
            raise bad(f"line {k}: {len(fields)} values, the header has {len(header)}")
        try:
            rows.append([float(v) if v.strip() else np.nan for v in fields])
        except ValueError:
            raise bad(f"line {k}: a value is not a number: {ln.strip()!r}") from None
    data = np.array(rows)
    t, x = data[:, 0], data[:, 1:].T
    try:
        fs = check_recording(t, x)
    except EMGError as exc:
        raise bad(str(exc)) from None
    return Recording(t, x, header[1:], fs, path.stem)


def excitation(emg, fs: float, *, band=(20.0, 450.0), cutoff: float = 6.0, mvc=None):
    """Neural excitation e ∈ [0, 1] of raw EMG (N,) or (C, N) V at ``fs`` Hz (module step 1):
    band-pass ``band`` Hz, the linear envelope at ``cutoff`` Hz, divided by ``mvc`` (V, the
    envelope of a maximum voluntary contraction, per channel; default the recording's peak).
    The envelope's small undershoots below zero (the low-pass's ringing) are set to 0; an
    envelope above ``mvc`` is an :class:`~anthroarm.errors.EMGError` (give the true MVC)."""
    from scipy import signal as sps

    x = np.atleast_2d(np.asarray(emg, dtype=float))
    if not np.all(np.isfinite(x)):
        raise EMGError("EMG contains NaN or infinite samples: fill or cut the gap first")
    lo, hi = band
    hi = min(float(hi), 0.45 * float(fs))  # a band edge below Nyquist for slow recordings
    y = sps.sosfilt(bandpass_sos(lo, hi, fs), x, axis=-1)
    env = np.maximum(lowpass_envelope(y, fs, cutoff), 0.0)
    peak = env.max(axis=-1, keepdims=True)
    ref = peak if mvc is None else np.broadcast_to(np.asarray(mvc, float), peak.shape)
    if not np.all(np.isfinite(ref)) or np.any(ref <= 0):
        raise EMGError(f"mvc must be a positive envelope value (V) per channel, got {mvc!r}")
    if np.any(peak > ref * (1 + 1e-12)):
        raise EMGError(
            f"the envelope reaches {float((peak / ref).max()):.3g} x the given mvc: the MVC "
            "envelope must be the largest (give the envelope of a maximal contraction)"
        )
    e = np.minimum(env / ref, 1.0)
    return e[0] if np.ndim(emg) == 1 else e


def _check_unit(x, what: str) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(a)):
        raise MuscleError(f"{what} must be finite numbers")
    if np.any((a < 0.0) | (a > 1.0)):
        raise MuscleError(f"{what} {a[(a < 0) | (a > 1)].ravel()[0]} is outside [0, 1]")
    return a


def neural_activation(e, fs: float, *, tau_act=TAU_ACT, tau_deact=TAU_DEACT, u0=None):
    """First-order activation dynamics (module step 2) of excitations ``e`` ∈ [0, 1] ((N,) or
    (C, N), sampled at ``fs`` Hz, held between samples), integrated exactly; ``u0`` the
    activation at the first sample (default: e there).  Returns u of e's shape."""
    E = np.atleast_2d(_check_unit(e, "excitation"))
    for nm, v in (("fs", fs), ("tau_act", tau_act), ("tau_deact", tau_deact)):
        if not (np.isfinite(v) and v > 0):
            raise MuscleError(f"{nm} must be positive, got {v!r}")
    dt = 1.0 / float(fs)
    u = np.empty_like(E)
    u[:, 0] = E[:, 0] if u0 is None else np.broadcast_to(_check_unit(u0, "u0"), E[:, 0].shape)
    for k in range(1, E.shape[1]):
        u[:, k] = step(u[:, k - 1], E[:, k - 1], dt, tau_act, tau_deact)
    return u[0] if np.ndim(e) == 1 else u


def step(u, e, dt: float, tau_act=TAU_ACT, tau_deact=TAU_DEACT):
    """The exact solution after ``dt`` s of u̇ = (e − u)/τ(e, u) from ``u`` at constant
    excitation ``e`` (module step 2)."""
    u, e = np.asarray(u, float), np.asarray(e, float)
    c = 0.5 + 1.5 * e
    w0 = np.abs(e - u)
    # deactivation (u >= e): w/(c + 1.5 w) = K, K = w0/(c + 1.5 w0) exp(-c dt / tau_deact)
    K = w0 / (c + 1.5 * w0) * np.exp(-c * dt / tau_deact)
    w_down = c * K / (1.0 - 1.5 * K)
    # activation (u < e): c ln(w/w0) - 1.5 (w - w0) = -dt/tau_act, by Lambert's W
    with np.errstate(divide="ignore", invalid="ignore"):
        z = -(1.5 / c) * w0 * np.exp(-1.5 * w0 / c - dt / (c * tau_act))
        w_up = np.where(w0 > 0, -(c / 1.5) * np.real(lambertw(z, 0)), 0.0)
    w = np.where(u < e, w_up, w_down)
    return np.clip(np.where(u < e, e - w, e + w), 0.0, 1.0)


def activation_shape(u, A: float = -1.5):
    """Lloyd & Besier (2003) Eq. 4 / Buchanan et al. (2004) Eq. 12: a = (e^{Au} − 1)/(e^A − 1)
    for neural activation u ∈ [0, 1] and shape factor −3 ≤ A ≤ 0 (A = 0: a = u)."""
    u = _check_unit(u, "neural activation")
    if not (np.isfinite(A) and -3.0 <= A <= 0.0):
        raise MuscleError(f"shape factor A must lie in [-3, 0] (Buchanan et al. 2004), got {A!r}")
    if abs(A) < 1e-12:
        return u.copy()
    return np.expm1(A * u) / np.expm1(A)


@dataclass(frozen=True)
class EMGDrive:
    """The EMG-driven chain on N samples: ``t`` (N,) s, ``excitation``, ``neural`` and
    ``activation`` (C, N) of the channels, the muscles' ``activations`` (N, M) (the driven ones
    from their channel, the others at ``rest``), tendon ``force`` (N, M) N, joint ``torque``
    (N, nq) N m (τ = Rᵀ f), ``moment_arms`` (N, M, nq) m, the robot's ``joint_names`` and the
    muscles' ``muscle_names``."""

    t: np.ndarray
    excitation: np.ndarray
    neural: np.ndarray
    activation: np.ndarray
    activations: np.ndarray
    force: np.ndarray
    torque: np.ndarray
    moment_arms: np.ndarray
    joint_names: list
    muscle_names: list


def drive(
    robot,
    muscles,
    recording: Recording,
    q,
    driven: dict,
    *,
    rest: float = 0.0,
    strength=1.0,
    mvc=None,
    A: float = -1.5,
    tau_act=TAU_ACT,
    tau_deact=TAU_DEACT,
    wrap: bool = True,
    every: int = 1,
) -> EMGDrive:
    """The whole chain (module docstring) for ``recording`` and joint positions ``q`` (N, nq)
    at the recording's samples (or one (nq,) held throughout).  ``driven`` maps muscle names
    to the channel (name or index) that drives them (e.g. both heads of the biceps from one
    electrode: ``{"BIClong": 0, "BICshort": 0}``); the other muscles hold activation ``rest``.
    ``strength`` (> 0, one or one per muscle) scales every muscle's maximum isometric force (a
    weak residual muscle: 0.3); at static equilibrium the tendon force is proportional to it
    (both sides of the equilibrium are normalised by F_max), so the forces are scaled after
    the equilibrium.  ``every``: evaluate the muscles at every ``every``-th sample only (the
    excitation and activation dynamics run at the full rate; the result holds those samples):
    muscle paths over wrap objects cost milliseconds a state."""
    ms = muscle_set(robot, muscles)
    n = recording.t.size
    check_recording(recording.t, recording.emg)
    e = np.atleast_2d(excitation(recording.emg, recording.fs, mvc=mvc))
    u = np.atleast_2d(neural_activation(e, recording.fs, tau_act=tau_act, tau_deact=tau_deact))
    a = np.atleast_2d(activation_shape(u, A))
    act = np.array(check_activation(rest, (n, len(ms))))
    for name, ch in driven.items():
        if name not in ms.names:
            raise MuscleError(f"muscle {name!r} is not in the model; muscles: {ms.names}")
        k = recording.channels.index(ch) if isinstance(ch, str) else int(ch)
        if not 0 <= k < a.shape[0]:
            raise EMGError(f"channel {ch!r} not in the recording ({recording.channels})")
        act[:, ms.names.index(name)] = a[k]
    Q = robot.check_q(q)
    Q = np.broadcast_to(Q, (n, robot.nq)) if Q.ndim == 1 else Q
    if Q.shape[0] != n:
        raise MuscleError(f"q has {Q.shape[0]} samples, the recording {n}")
    if not (isinstance(every, (int, np.integer)) and 1 <= every <= n):
        raise MuscleError(f"every must be an integer in 1..{n}, got {every!r}")
    keep = np.arange(0, n, int(every))
    Q, act, e, u, a = Q[keep], act[keep], e[:, keep], u[:, keep], a[:, keep]
    k = np.broadcast_to(np.asarray(strength, dtype=float), (len(ms),))
    if not np.all(np.isfinite(k) & (k > 0)):
        raise MuscleError(f"strength must be a positive factor per muscle, got {strength!r}")
    _, eq, R = joint_torques(robot, ms, Q, act, wrap=wrap)
    force = eq.tendon_force * k
    tau = np.einsum("nmk,nm->nk", R, force)
    if not np.all(np.isfinite(tau)):
        raise MuscleError("joint torques are not finite: check the model's muscle parameters")
    return EMGDrive(
        recording.t[keep], e, u, a, act, force, tau, R, list(robot.joint_names), ms.names
    )


def needed_torques(robot, t, q, *, payload: float = 0.0, frame=None) -> np.ndarray:
    """The joint torques (N, nv) N m an activity needs: inverse dynamics of the motion q(t)
    ((N, nq) rad at times ``t`` s; velocities and accelerations from a quintic interpolating
    spline) with a point mass ``payload`` kg held at ``frame`` (default the tool)
    (:func:`anthroarm.dynamics.loads.inverse_dynamics`, Eq. (8-5))."""
    t = np.asarray(t, float)
    Q = robot.check_q(q)
    if Q.ndim != 2 or Q.shape[0] != t.size or t.size < 6 or np.any(np.diff(t) <= 0):
        raise MuscleError("needed_torques: t (N,) strictly increasing, N >= 6, q (N, nq)")
    from scipy.interpolate import make_interp_spline

    spl = make_interp_spline(t, Q, k=5, axis=0)
    loads = None if payload == 0 else HeldObject(payload, frame=frame)
    res = inverse_dynamics(
        robot, Q, spl.derivative(1)(t), spl.derivative(2)(t), loads, engine="pinocchio"
    )
    return res.tau


def plot(result: EMGDrive, needed, joint: str, *, title: str | None = None):
    """A matplotlib Figure: the excitation and activation of the driving channels (top), and
    about ``joint`` the torque the muscles produce, the torque the activity needs (``needed``
    (N, nv) N m at the result's samples: ``needed[::every]`` for :func:`drive`'s ``every``) and
    their difference, what a motor must add (bottom)."""
    import matplotlib.pyplot as plt  # optional: plotting

    k = result.joint_names.index(joint)
    t = result.t - result.t[0]
    need = np.asarray(needed, float)[:, k]
    if need.shape != t.shape:
        raise MuscleError(
            f"needed has {need.size} samples, the result {t.size}: pass needed[::every]"
        )
    mus = result.torque[:, k]
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for c in range(result.excitation.shape[0]):
        ax0.plot(t, result.excitation[c], lw=0.8, label="excitation e (envelope / MVC)")
        ax0.plot(t, result.activation[c], lw=1.5, label="activation a")
    ax0.set_ylabel("[0, 1]")
    ax0.set_ylim(0, 1.05)
    ax0.legend(loc="upper right", fontsize=8)
    ax1.plot(t, mus, label="muscles (EMG-driven)", color="C2")
    ax1.plot(t, need, label="activity needs (inverse dynamics)", color="k")
    ax1.plot(t, need - mus, label="motor must add", color="C3", ls="--")
    ax1.axhline(0, color="0.7", lw=0.5)
    ax1.set_xlabel("time (s)")
    ax1.set_ylabel(f"torque about {joint} (N m)")
    ax1.legend(loc="upper right", fontsize=8)
    ax0.set_title(title or "EMG → activation → muscle torque, and the motor's share")
    fig.tight_layout()
    return fig
