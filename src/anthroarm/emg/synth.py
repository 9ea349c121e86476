r"""Synthetic surface EMG at the book's amplitudes, for tests, demos and benchmarks.

Model (the usual one for myoelectric control, Hogan & Mann 1980, "Myoelectric signal
processing: optimal estimation applied to electromyography", *IEEE TBME* 27:382): the EMG is
zero-mean Gaussian noise whose **amplitude is modulated** by the muscle's activation,

.. math:: x(t) = \sigma\,a(t)\,n(t) + w(t),

with :math:`n(t)` unit-variance noise **band-limited** to the EMG band, :math:`a(t) \in [0, 1]`
the activation (bursts with smooth raised-cosine ramps), :math:`\sigma` the RMS at full
activation and :math:`w(t)` white baseline noise (electrode and amplifier).

Numbers from the book (§9-2 二 3): power mainly in **30–300 Hz** (the default band; a flat
spectrum there, so its mean and median frequency are both 165 Hz); **healthy** muscle
1–3 mV peak-to-peak (:data:`HEALTHY_PP`), a typical moderate contraction 100 µV, **amputees**
≥ 50 µV untrained (:data:`AMPUTEE_PP`).  Peak-to-peak is the sine-equivalent one of
:mod:`.envelope`: :math:`\sigma = \mathrm{pp} / (2\sqrt2)`.  The baseline noise default,
1 µV RMS, is an assumption (the order of a good surface-EMG amplifier's input noise,
Merletti & Parker 2004, ch. 5).  Volts, seconds, Hz; arrays (channels, samples).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError
from ._checks import MAX_VOLTS, MEMORY_BUDGET, count, nonnegative, number, positive, signal
from .envelope import PP_PER_RMS

#: healthy EMG, 1–3 mV peak-to-peak (V), book §9-2
HEALTHY_PP = (1e-3, 3e-3)
#: a typical moderate contraction of a healthy muscle, 100 µV (V), book §9-2
TYPICAL_PP = 100e-6
#: amputee EMG, at least 50 µV untrained, 100 µV trained (V, p-p), book §9-2
AMPUTEE_PP = 50e-6
AMPUTEE_TRAINED_PP = 100e-6
#: the band of the main spectral power (Hz), book §9-2
EMG_BAND = (30.0, 300.0)
#: the most samples (all channels together) the generator makes: its working memory is about 64
#: bytes a sample (noise, its spectrum, activation, envelope, output), so this keeps it within
#: :data:`~anthroarm.emg._checks.MEMORY_BUDGET` (2 GiB); a mistyped duration, rate or channel
#: count (10**8 samples) is refused instead of exhausting the memory
MAX_SAMPLES = MEMORY_BUDGET // 64


def _band(band, fs: float) -> tuple[float, float]:
    try:
        lo, hi = (float(b) for b in band)
    except (TypeError, ValueError):
        raise EMGError(f"band must be (low, high) in Hz, got {band!r}") from None
    if not (0 <= lo < hi < fs / 2):
        raise EMGError(
            f"band must satisfy 0 <= low < high < fs/2 = {fs / 2:g} Hz, got ({lo:g}, {hi:g})"
        )
    return lo, hi


def band_limited_noise(
    n_samples: int, fs: float, band=EMG_BAND, n_channels: int = 1, rng=None
) -> np.ndarray:
    """Gaussian noise with a flat spectrum inside ``band`` (Hz) and none outside (FFT brick-wall),
    scaled to unit sample variance per channel; shape (n_channels, n_samples).  ``band[1]``
    must be below fs/2; at most :data:`MAX_SAMPLES` samples in all."""
    fs = positive(fs, "sampling rate fs", "Hz")
    lo, hi = _band(band, fs)
    n_samples = count(n_samples, "n_samples", 16, MAX_SAMPLES)
    n_channels = count(n_channels, "n_channels", 1, MAX_SAMPLES // n_samples)
    rng = np.random.default_rng(rng)
    spec = np.fft.rfft(rng.standard_normal((n_channels, int(n_samples))), axis=-1)
    f = np.fft.rfftfreq(int(n_samples), 1.0 / fs)
    spec[:, (f < lo) | (f > hi)] = 0.0
    x = np.fft.irfft(spec, n=int(n_samples), axis=-1)
    x -= x.mean(axis=-1, keepdims=True)
    sd = x.std(axis=-1, keepdims=True)
    if not np.all(sd > 0):
        raise EMGError(
            f"the band {lo:g}-{hi:g} Hz holds no frequency bin of {n_samples} samples at "
            f"{fs:g} Hz (bin spacing {fs / n_samples:.3g} Hz): make the record longer or the band "
            "wider"
        )
    return x / sd


def activation(t, bursts, ramp_s: float = 0.05) -> np.ndarray:
    """Muscle activation :math:`a(t) \\in [0, 1]` at times ``t`` (s): a sum of bursts
    ``(onset_s, duration_s, level)`` (level in [0, 1]), each rising and falling with a
    raised-cosine ramp of ``ramp_s`` seconds inside its duration, clipped to 1."""
    try:
        t = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise EMGError(f"t must be times in s, got {type(t).__name__}") from None
    if not np.all(np.isfinite(t)):
        raise EMGError("t contains NaN/inf: activation needs finite times (s)")
    a = np.zeros_like(t)
    r = positive(ramp_s, "ramp_s", "s")
    try:
        bursts = list(bursts)
    except TypeError:
        raise EMGError(
            f"bursts is a list of (onset_s, duration_s, level), got {bursts!r}"
        ) from None
    for b in bursts:
        try:
            t0, dur, level = (float(v) for v in b)
        except (TypeError, ValueError):
            raise EMGError(f"a burst is (onset_s, duration_s, level), got {b!r}") from None
        if not (np.isfinite(t0) and np.isfinite(dur) and dur > 0 and 0 <= level <= 1):
            raise EMGError(
                f"a burst needs a finite onset, duration > 0 and a level in [0, 1], got {b!r}"
            )
        rr = min(r, dur / 2)
        with np.errstate(over="ignore"):  # ±inf clips to 0 or 1, the right limit
            up = np.clip((t - t0) / rr, 0.0, 1.0)
            down = np.clip((t0 + dur - t) / rr, 0.0, 1.0)
        a += level * 0.5 * (1 - np.cos(np.pi * np.minimum(up, down)))
    return np.minimum(a, 1.0)


@dataclass(frozen=True)
class SyntheticEMG:
    """A synthetic recording and its ground truth (volts, seconds).

    ``emg``: (channels, samples) differential EMG; ``t``: (samples,) s; ``activation``:
    (channels, samples) in [0, 1]; ``envelope_rms``: (channels, samples) the true RMS
    :math:`\\sigma a(t)` without the baseline noise; ``pp``: sine-equivalent p-p at full
    activation per channel; ``noise_rms``: baseline noise RMS; ``fs``: Hz."""

    t: np.ndarray
    emg: np.ndarray
    activation: np.ndarray
    envelope_rms: np.ndarray
    pp: np.ndarray
    noise_rms: float
    fs: float


def synthesize(
    duration_s: float,
    fs: float,
    bursts,
    pp=TYPICAL_PP,
    band=EMG_BAND,
    noise_rms: float = 1e-6,
    ramp_s: float = 0.05,
    rng=None,
) -> SyntheticEMG:
    """Generate EMG: one channel per entry of ``bursts`` (each a list of
    ``(onset_s, duration_s, level)``), full-activation amplitude ``pp`` (V sine-equivalent
    peak-to-peak, scalar or one per channel; e.g. :data:`HEALTHY_PP`, :data:`AMPUTEE_PP`),
    carrier band ``band`` (Hz), white baseline noise ``noise_rms`` (V).  ``rng``: seed or
    ``numpy.random.Generator``."""
    dur = positive(duration_s, "duration_s", "s")
    fs = positive(fs, "sampling rate fs", "Hz")
    bursts = list(bursts)
    if not bursts or not all(isinstance(b, (list, tuple)) for b in bursts):
        raise EMGError("bursts is a list with one list of (onset_s, duration_s, level) per channel")
    n_ch = len(bursts)
    if not 16 <= dur * fs * n_ch <= MAX_SAMPLES:
        raise EMGError(
            f"duration_s * fs * channels = {dur * fs * n_ch:.3g} samples; the generator makes "
            f"16..{MAX_SAMPLES:.0e}"
        )
    n = int(round(dur * fs))
    try:
        p = np.broadcast_to(np.asarray(pp, dtype=float), (n_ch,)).copy()
    except (TypeError, ValueError):
        raise EMGError(
            f"pp is one amplitude (V peak-to-peak) or one per channel ({n_ch}), got {pp!r}"
        ) from None
    if not np.all(np.isfinite(p)) or np.any(p <= 0):
        raise EMGError(f"pp must be finite and > 0 (V peak-to-peak), got {p.tolist()}")
    nr = nonnegative(noise_rms, "noise_rms", "V")
    rng = np.random.default_rng(rng)
    t = np.arange(n) / fs
    act = np.stack([activation(t, b, ramp_s) for b in bursts])
    sigma = p / PP_PER_RMS
    env = sigma[:, None] * act
    x = env * band_limited_noise(n, fs, band, n_ch, rng)
    if nr > 0:
        x = x + nr * rng.standard_normal(x.shape)
    return SyntheticEMG(t=t, emg=x, activation=act, envelope_rms=env, pp=p, noise_rms=nr, fs=fs)


def electrode_potentials(
    emg, fs: float, mains_pp: float = 0.0, mains_hz: float = 50.0, offset_v: float = 0.0
):
    """The two electrode potentials of a bipolar pair recording ``emg`` (V): the differential
    EMG split symmetrically, plus a **common-mode** mains hum of ``mains_pp`` volts
    peak-to-peak at ``mains_hz`` and a common DC ``offset_v`` (the interference the book's
    differential front end must reject, §9-2 三).  Returns ``(v_plus, v_minus)``."""
    x = signal(emg, "emg", bytes_per_value=32.0)
    fs = positive(fs, "sampling rate fs", "Hz")
    t = np.arange(x.shape[1]) / fs
    amp = nonnegative(mains_pp, "mains_pp", "V")
    f0 = positive(mains_hz, "mains_hz", "Hz")
    with np.errstate(over="ignore", invalid="ignore"):
        phase = 2 * np.pi * f0 * t
    if not np.all(np.isfinite(phase)):
        raise EMGError(
            f"mains_hz {mains_hz!r} Hz over {t[-1]:g} s overflows the phase: give Hz and an fs "
            "in Hz"
        )
    cm = 0.5 * amp * np.sin(phase) + number(offset_v, "offset_v", "V")
    if not np.all(np.isfinite(cm)) or amp + abs(float(offset_v)) > MAX_VOLTS:
        raise EMGError(
            f"mains_pp {mains_pp!r} V and offset_v {offset_v!r} V are beyond {MAX_VOLTS:.0e} V: "
            "not a voltage (wrong units?)"
        )
    return cm + 0.5 * x, cm - 0.5 * x
