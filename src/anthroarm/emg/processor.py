r"""The EMG signal chain of the book's powered hands, built once and run on blocks.

Book §9-2 (三; Figs. 9-23, 9-25): amplifier → band-pass → detection and integration
(rectify, envelope) → **amplitude threshold** discrimination → logic.  :class:`EMGProcessor`
holds the precomputed filters and runs the whole chain vectorised over all channels:

1. conditioning band-pass (:data:`~anthroarm.emg.filters.CONDITIONING_BAND`, optional mains
   notch), causal ``sosfilt``;
2. envelope: causal moving RMS (default 100 ms) or rectified low-pass
   (:mod:`~anthroarm.emg.envelope`);
3. decimation to control frames (default every 5 ms);
4. per-channel **Schmitt trigger** (on / off thresholds, sine-equivalent peak-to-peak volts at
   the electrodes): a channel switches on when its envelope reaches the on-threshold and off
   when it falls to the off-threshold (hysteresis against chatter; assumption: the book's
   "threshold discriminator" block does not say whether it has hysteresis);
5. for an antagonist pair, the 2-bit **code** ``2·flexor + extensor``: 0 = "00" rest,
   1 = "01" extensor, 2 = "10" flexor, 3 = "11" both (§9-2 三 2, Fig. 9-25).

**Sensitivity** (book §9-2 三): a 50–100 µV input must operate the hand.  The default
thresholds (on 35 µV, off 25 µV p-p) switch at 50 µV; :meth:`Thresholds.check` refuses
thresholds that can never switch on (at or beyond the largest unclipped input, ``2 rail /
gain`` of the amplifier) or never off (at or below the noise floor).

The processor keeps its filter states between calls of :meth:`EMGProcessor.process` with
``reset=False``, so a recording split into blocks gives the same result as in one piece
(real-time use).  It is not thread-safe: one processor per stream.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError, ThresholdError
from ._checks import MAX_VOLTS, budget, count, nonnegative, number, positive, signal
from .envelope import PP_PER_MAV, PP_PER_RMS, lowpass_sos, running_rms, window_samples
from .filters import CONDITIONING_BAND, bandpass_sos, check_sampling_rate, notch_sos

#: code values of an antagonist pair, flexor bit first as printed ("10" is the flexor)
REST, EXTENSOR, FLEXOR, BOTH = 0, 1, 2, 3
CODE_NAMES = ("00", "01", "10", "11")
#: the most channels one processor takes (its filter states are per channel)
MAX_CHANNELS = 1024


@dataclass(frozen=True)
class Thresholds:
    """Schmitt-trigger thresholds per channel: sine-equivalent peak-to-peak volts referred to
    the electrodes (book §9-2 三: sensitivity 50–100 µV; defaults on 35 µV, off 25 µV, an
    assumption that switches at the book's 50 µV).  Scalars apply to every channel."""

    on_pp: float | tuple = 35e-6
    off_pp: float | tuple = 25e-6

    def arrays(self, n_channels: int) -> tuple[np.ndarray, np.ndarray]:
        """(on, off) as (n_channels,) arrays; :class:`~anthroarm.errors.ThresholdError` if a
        value is not finite and > 0, the shape is wrong or off > on."""
        try:
            on = np.broadcast_to(np.asarray(self.on_pp, dtype=float), (n_channels,)).copy()
            off = np.broadcast_to(np.asarray(self.off_pp, dtype=float), (n_channels,)).copy()
        except (TypeError, ValueError):
            raise ThresholdError(
                f"thresholds must be a number or one per channel ({n_channels}), "
                f"got on_pp={self.on_pp!r}, off_pp={self.off_pp!r}"
            ) from None
        for name, v in (("on_pp", on), ("off_pp", off)):
            if not np.all(np.isfinite(v)) or np.any(v <= 0):
                raise ThresholdError(
                    f"{name} must be finite and > 0 (V peak-to-peak), got {v.tolist()}"
                )
        if np.any(off > on):
            i = int(np.argmax(off > on))
            raise ThresholdError(
                f"channel {i}: off-threshold {off[i]:.3g} V is above the on-threshold "
                f"{on[i]:.3g} V (hysteresis needs off <= on)"
            )
        return on, off

    def check(
        self, n_channels: int, max_input_pp: float = float("inf"), noise_pp: float = 0.0
    ) -> None:
        """Refuse thresholds that can never switch (:class:`~anthroarm.errors.ThresholdError`):
        an on-threshold at or above ``max_input_pp`` (the largest input the front end passes
        unclipped, V p-p) can never switch on; an off-threshold at or below ``noise_pp`` (the
        noise floor's sine-equivalent p-p) can never switch off."""
        on, off = self.arrays(n_channels)
        if np.any(on >= max_input_pp):
            i = int(np.argmax(on >= max_input_pp))
            raise ThresholdError(
                f"channel {i}: on-threshold {on[i] * 1e6:.4g} µV p-p is at or above the largest "
                f"input the amplifier passes unclipped ({max_input_pp * 1e6:.4g} µV p-p = 2 rail / "
                "gain): it can never switch on; lower it or the gain"
            )
        if np.any(off <= noise_pp):
            i = int(np.argmax(off <= noise_pp))
            raise ThresholdError(
                f"channel {i}: off-threshold {off[i] * 1e6:.4g} µV p-p is at or below the noise "
                f"floor ({noise_pp * 1e6:.4g} µV p-p): it can never switch off; raise it"
            )


@dataclass(frozen=True)
class ProcessedEMG:
    """Output of :meth:`EMGProcessor.process` (volts referred to the electrodes, seconds).

    ``filtered``: (channels, samples) conditioned EMG; ``envelope_pp``: (channels, frames)
    sine-equivalent p-p envelope at the control frames; ``active``: (channels, frames) bool
    Schmitt-trigger states; ``code``: (frames,) int 0..3 for an antagonist pair (``None`` for
    other channel counts); ``t_frames``: (frames,) s, the time of each frame's last sample
    (from the start of the stream); ``on_pp``/``off_pp``: thresholds per channel."""

    filtered: np.ndarray
    envelope_pp: np.ndarray
    active: np.ndarray
    code: np.ndarray | None
    t_frames: np.ndarray
    on_pp: np.ndarray
    off_pp: np.ndarray
    fs: float
    frame_s: float


class EMGProcessor:
    """The signal chain of §9-2, designed once (see the module text).

    Parameters
    ----------
    fs
        Sampling rate, Hz (must exceed twice the highest filter edge).
    n_channels
        Channels per sample (2 for the book's antagonist pair: channel 0 flexor, 1 extensor).
    band
        Conditioning band-pass (low, high) Hz.
    notch_hz
        Mains notch frequency (Hz) or ``None``.
    envelope
        ``"rms"`` (moving RMS over ``window_s``) or ``"lowpass"`` (rectified, Butterworth
        low-pass at ``cutoff_hz``).
    window_s, cutoff_hz
        Envelope window (s) / cutoff (Hz).
    frame_s
        Control frame period (s): envelopes and codes are produced every ``frame_s``.
    thresholds
        :class:`Thresholds` (input-referred p-p volts).
    gain
        Gain between the electrodes and ``emg`` (V/V): 1 for input-referred signals, the
        amplifier's gain for its output.
    max_input_pp, noise_rms
        Largest unclipped input (V p-p, e.g. ``DifferentialAmplifier.max_input_pp``) and
        baseline noise (V RMS) for :meth:`Thresholds.check`.
    """

    def __init__(
        self,
        fs: float,
        n_channels: int = 2,
        *,
        band=CONDITIONING_BAND,
        notch_hz: float | None = None,
        envelope: str = "rms",
        window_s: float = 0.1,
        cutoff_hz: float = 5.0,
        frame_s: float = 0.005,
        thresholds: Thresholds | None = None,
        gain: float = 1.0,
        max_input_pp: float = float("inf"),
        noise_rms: float | None = None,
    ):
        self.n_channels = count(n_channels, "n_channels", 1, MAX_CHANNELS)
        try:
            lo, hi = (float(b) for b in band)
        except (TypeError, ValueError):
            raise EMGError(f"band must be (low, high) in Hz, got {band!r}") from None
        self.fs = check_sampling_rate(fs, hi, f"the conditioning band {lo:g}–{hi:g} Hz")
        sos = [bandpass_sos(lo, hi, self.fs)]
        if notch_hz is not None:
            sos.append(notch_sos(notch_hz, self.fs))
        self.sos = np.vstack(sos)
        if envelope not in ("rms", "lowpass"):
            raise EMGError(f"envelope must be 'rms' or 'lowpass', got {envelope!r}")
        self.envelope = envelope
        if envelope == "rms":
            self.window = window_samples(window_s, self.fs)
            budget(self.n_channels * self.window, 16.0, "the moving-RMS window of every channel")
            self._pp = PP_PER_RMS
        else:
            self.env_sos = lowpass_sos(self.fs, cutoff_hz)
            self._pp = PP_PER_MAV
        self.hop = window_samples(frame_s, self.fs)
        self.frame_s = self.hop / self.fs
        self.gain = positive(gain, "gain", "V/V")
        self.thresholds = thresholds if thresholds is not None else Thresholds()
        if not isinstance(self.thresholds, Thresholds):
            raise ThresholdError(
                f"thresholds must be a Thresholds(on_pp, off_pp), got {thresholds!r}"
            )
        noise_pp = (
            0.0 if noise_rms is None else PP_PER_RMS * nonnegative(noise_rms, "noise_rms", "V")
        )
        mx = (
            float("inf")
            if max_input_pp == float("inf")
            else positive(max_input_pp, "max_input_pp", "V")
        )
        # no accepted signal exceeds MAX_VOLTS at the processor, 2 MAX_VOLTS / gain p-p at the
        # electrodes
        reach = min(mx, 2.0 * MAX_VOLTS / self.gain)
        self.thresholds.check(self.n_channels, reach, noise_pp)
        self.on, self.off = self.thresholds.arrays(self.n_channels)
        # thresholds in the units of the envelope before the p-p factor and the gain
        self._on_raw = self.on / self._pp * self.gain
        self._off_raw = self.off / self._pp * self.gain
        self.reset()

    def reset(self) -> None:
        """Forget the stream: filters at rest, all channels off, time back to 0."""
        n = self.n_channels
        self._zi = np.zeros((self.sos.shape[0], n, 2))
        if self.envelope == "rms":
            self._tail = np.zeros((n, self.window))  # last `window` squared samples
        else:
            self._zi_env = np.zeros((self.env_sos.shape[0], n, 2))
        self._state = np.zeros(n, dtype=bool)
        self._count = 0  # samples seen so far

    def process(self, emg, reset: bool = True) -> ProcessedEMG:
        """Run the chain on ``emg`` (channels, samples) volts; ``reset=False`` continues the
        stream of the previous call (blocks of any length, frames aligned to the stream)."""
        from scipy import signal as sps

        x = signal(emg, "emg", self.n_channels, bytes_per_value=40.0)
        if reset:
            self.reset()
        y, self._zi = sps.sosfilt(self.sos, x, axis=-1, zi=self._zi)
        n = x.shape[1]
        first = (-self._count - 1) % self.hop  # index of the first frame's last sample
        idx = np.arange(first, n, self.hop)
        if self.envelope == "rms":
            e, self._tail = running_rms(y, self.window, self._tail, idx)
        else:
            full, self._zi_env = sps.sosfilt(self.env_sos, np.abs(y), axis=-1, zi=self._zi_env)
            e = full[:, idx]
        active = self._schmitt(e)
        t = (self._count + idx + 1) / self.fs
        self._count += n
        code = (2 * active[0] + active[1]).astype(np.int8) if self.n_channels == 2 else None
        return ProcessedEMG(
            filtered=y / self.gain,
            envelope_pp=e * (self._pp / self.gain),
            active=active,
            code=code,
            t_frames=t,
            on_pp=self.on,
            off_pp=self.off,
            fs=self.fs,
            frame_s=self.frame_s,
        )

    def _schmitt(self, e: np.ndarray) -> np.ndarray:
        """Vectorised hysteresis: on at >= on, off at <= off, else hold the previous state."""
        n, m = e.shape
        if m == 0:
            return np.zeros((n, 0), dtype=bool)
        mark = np.where(e >= self._on_raw[:, None], 1, np.where(e <= self._off_raw[:, None], 0, -1))
        pos = np.where(mark >= 0, np.arange(m), -1)
        last = np.maximum.accumulate(pos, axis=1)
        held = np.take_along_axis(mark, np.maximum(last, 0), axis=1) == 1
        out = np.where(last >= 0, held, self._state[:, None])
        self._state = out[:, -1].copy()
        return out


#: book §9-2 三 sensitivity, the smallest input (V p-p) that must operate the hand
BOOK_SENSITIVITY_PP = 50e-6


@dataclass(frozen=True)
class Calibration:
    """Thresholds calibrated on a rest recording (:func:`calibrate_thresholds`).

    ``thresholds`` the :class:`Thresholds`; ``rest_mean_pp`` / ``rest_sd_pp`` the mean and
    standard deviation of each channel's rest envelope (V p-p, sine-equivalent); ``status``
    ``"ok"`` or, per channel, why the book's sensitivity cannot be met (the on-threshold above
    50 µV: the rest noise is too high)."""

    thresholds: Thresholds
    rest_mean_pp: np.ndarray
    rest_sd_pp: np.ndarray
    status: str


def calibrate_thresholds(
    rest,
    fs: float,
    *,
    k: float = 5.0,
    off_fraction: float = 0.5,
    settle_s: float = 0.3,
    **processor_kw,
) -> Calibration:
    """On/off thresholds from a recording of the relaxed muscles (``rest``, (channels, samples)
    V at the electrodes), through the same chain as ``EMGProcessor(fs, **processor_kw)``.

    The on-threshold is the rest envelope's mean plus ``k`` standard deviations, the rule of
    Hodges & Bui 1996 ("A comparison of computer-based methods for the determination of onset
    of muscle contraction using electromyography", *Electroencephalogr. Clin. Neurophysiol.*
    101:511).  Their common k = 3 leaves about 2 % of the rest frames active with this chain's
    smooth 100 ms RMS envelope (white rest noise, 5 recordings, even after the code machine's
    debounce), so the default here is k = 5 (an assumption: no false activity in those
    recordings).  The off-threshold is the mean plus ``off_fraction`` of that margin
    (hysteresis, an assumption).  The first ``settle_s`` seconds (the filters'
    and the window's start-up) are left out; at least one second must remain.  The status
    compares the on-threshold with the book's sensitivity (:data:`BOOK_SENSITIVITY_PP`)."""
    x = signal(rest, "rest", processor_kw.get("n_channels"), bytes_per_value=40.0)
    kk = positive(k, "k (standard deviations)")
    frac = number(off_fraction, "off_fraction")
    if not 0.0 <= frac <= 1.0:
        raise EMGError(f"off_fraction must be in [0, 1], got {off_fraction!r}")
    settle = nonnegative(settle_s, "settle_s", "s")
    kw = dict(processor_kw)
    kw["n_channels"] = x.shape[0]
    out = EMGProcessor(fs, **kw).process(x)
    keep = out.t_frames > settle
    if out.t_frames[keep].size == 0 or out.t_frames[-1] - settle < 1.0 - 1e-9:
        raise EMGError(
            f"the rest recording must last at least {settle + 1.0:g} s "
            f"({settle:g} s to settle + 1 s), got {x.shape[1] / out.fs:g} s"
        )
    e = out.envelope_pp[:, keep]
    mean, sd = e.mean(axis=1), e.std(axis=1)
    on = mean + kk * sd
    off = mean + frac * kk * sd
    off = np.where(off > 0, off, 0.5 * on)
    if not np.all(on > 0):
        raise EMGError("the rest recording is silent (envelope 0): record with the electrodes on")
    bad = [
        f"channel {c}: on-threshold {on[c] * 1e6:.3g} µV p-p is above the book's "
        f"{BOOK_SENSITIVITY_PP * 1e6:g} µV sensitivity (rest noise too high: check the electrodes)"
        for c in range(on.size)
        if on[c] > BOOK_SENSITIVITY_PP
    ]
    return Calibration(
        Thresholds(tuple(on.tolist()), tuple(off.tolist())), mean, sd, "; ".join(bad) or "ok"
    )
