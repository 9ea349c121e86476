r"""Rectification and the amplitude envelope ("检波积分", detection and integration).

Book §9-2 (Fig. 9-25, block 3 "检波积分"): after amplification the EMG is rectified and
integrated, and the result is compared with amplitude thresholds.  Two standard envelopes
(De Luca 1997, "The use of surface electromyography in biomechanics", *J. Appl. Biomech.*
13:135; Merletti & Parker 2004, ch. 6):

* **moving RMS** over a window of :math:`W` samples, causal (the window ends at the current
  sample; before :math:`W` samples have arrived the missing ones count as zero, as in a
  filter started from rest):
  :math:`r[n] = \sqrt{\tfrac1W\sum_{k=n-W+1}^{n} x[k]^2}`;
* **linear envelope**: full-wave rectification :math:`|x|` followed by a low-pass Butterworth
  filter (order 2), its output the mean rectified value (MAV).

The book states amplitudes as **peak-to-peak** values (healthy 1–3 mV p-p, amputees ≥ 50 µV,
sensitivity 50–100 µV).  A random signal has no unique peak-to-peak; this module uses the
**sine-equivalent** peak-to-peak (assumption): the p-p of the sine with the same RMS,
:math:`2\sqrt2\,\mathrm{RMS}`, or with the same mean rectified value, :math:`\pi\,\mathrm{MAV}`.
For a sine both give its true p-p.  Volts, seconds, Hz; time along the last axis.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import EMGError
from ._checks import count, positive, signal
from .filters import check_sampling_rate

#: sine-equivalent peak-to-peak per volt RMS
PP_PER_RMS = 2.0 * math.sqrt(2.0)
#: sine-equivalent peak-to-peak per volt of mean rectified value
PP_PER_MAV = math.pi
#: the longest envelope window or control frame accepted (s)
MAX_WINDOW_S = 10.0
#: the most samples in one window (the moving RMS keeps a window of squares per channel)
MAX_WINDOW_SAMPLES = 10_000_000


def window_samples(window_s: float, fs: float) -> int:
    """The number of samples of a ``window_s`` (s) window at ``fs`` (Hz), at least 1."""
    w = positive(window_s, "envelope window", "s")
    f = positive(fs, "sampling rate fs", "Hz")
    if w > MAX_WINDOW_S:
        raise EMGError(f"window {w:g} s is longer than {MAX_WINDOW_S:g} s: not an envelope window")
    n = int(round(w * f))
    if n < 1:
        raise EMGError(f"envelope window {w:g} s is shorter than one sample at {f:g} Hz")
    if n > MAX_WINDOW_SAMPLES:
        raise EMGError(
            f"window {w:g} s at {f:g} Hz is {n:.3g} samples, more than {MAX_WINDOW_SAMPLES:.0e}: "
            "is fs in Hz?"
        )
    return n


def rectify(x) -> np.ndarray:
    """Full-wave rectification :math:`|x|` (volts)."""
    return np.abs(signal(x, "emg"))


def moving_rms(x, fs: float, window_s: float = 0.1) -> np.ndarray:
    """Causal moving RMS (V) of ``x`` (channels, samples) over ``window_s`` seconds (see the
    module text; default 100 ms, an assumption within the 100–125 ms controller delay that
    Farrell & Weir 2007, *IEEE TNSRE* 15:111, found best for myoelectric prostheses)."""
    a = signal(x, "emg", bytes_per_value=56.0)
    w = window_samples(window_s, fs)
    return running_rms(a, w, np.zeros((a.shape[0], w)), np.arange(a.shape[1]))[0]


def running_rms(
    y: np.ndarray, w: int, tail: np.ndarray, idx: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The moving RMS of a stream block: ``y`` (channels, n) the new samples, ``tail``
    (channels, w) the previous ``w`` squared samples (zeros at the start), ``idx`` the sample
    indices (in ``y``) where the RMS is wanted.  Returns (RMS at ``idx``, the new tail)."""
    sq = np.concatenate([tail, y * y], axis=1)
    c = np.cumsum(sq, axis=1)
    s = c[:, w + idx] - c[:, idx]  # sum of the w squares ending at each idx
    np.maximum(s, 0.0, out=s)  # rounding of the running sum never makes a negative power
    return np.sqrt(s / w), sq[:, -w:]


def lowpass_envelope(x, fs: float, cutoff_hz: float = 5.0, order: int = 2) -> np.ndarray:
    """Linear envelope (V, mean rectified value): :math:`|x|` through a causal Butterworth
    low-pass at ``cutoff_hz`` (default 5 Hz, an assumption: 3–10 Hz is the usual range,
    De Luca 1997).  ``fs`` must exceed twice the cutoff."""
    from scipy import signal as sps

    a = signal(x, "emg", bytes_per_value=32.0)
    return sps.sosfilt(lowpass_sos(fs, cutoff_hz, order), np.abs(a), axis=-1)


def lowpass_sos(fs: float, cutoff_hz: float, order: int = 2) -> np.ndarray:
    """The Butterworth low-pass of the linear envelope as second-order sections; ``fs`` (Hz)
    must exceed twice ``cutoff_hz``."""
    from scipy import signal as sps

    fc = positive(cutoff_hz, "envelope cutoff", "Hz")
    fs = check_sampling_rate(fs, fc, f"the {fc:g} Hz envelope low-pass")
    order = count(order, "envelope filter order", 1, 8)
    return sps.butter(order, fc, btype="lowpass", fs=fs, output="sos")


def rms(x) -> np.ndarray:
    """RMS of each channel (V) over the whole record."""
    a = signal(x, "emg")
    return np.sqrt(np.mean(a * a, axis=-1))


def peak_to_peak(x) -> np.ndarray:
    """Peak-to-peak of each channel (V) over the whole record (max − min)."""
    a = signal(x, "emg")
    return np.ptp(a, axis=-1)
