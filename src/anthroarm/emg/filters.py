r"""Band-pass filters of the EMG chain: the conditioning band and the book's filter banks.

Book §9-2 (二, 三; Table 9.1): the surface EMG spans 0–1000 Hz with its main power in
30–300 Hz (10–200 Hz for a flexor/extensor pair, weak above 300 Hz); the Kanagawa
multi-DOF forearm-hand simulation separates motions by **band-pass filter banks** with the
printed centre frequencies **40, 100, 160, 360 Hz** (方式1, 2 channels) and **70, 160, 360 Hz**
(方式2, 3 channels).  The book prints neither the filter type, the order nor the bandwidth;
the choices below are assumptions, stated where they are made:

* every filter is a digital **Butterworth** band-pass (maximally flat; the usual choice in
  surface EMG, Merletti & Parker 2004, *Electromyography*, ch. 5) of order 2 per edge
  (a 4th-order band-pass, 12 dB/octave skirts), in second-order sections (``scipy.signal``
  SOS form), run causally (``sosfilt``: what an analog or embedded filter does);
* the **conditioning band** is 20–450 Hz: a 20 Hz high-pass corner removes movement artefact
  and baseline drift (De Luca, Gilmore, Kuznetsov & Roy 2010, "Filtering the surface EMG
  signal: movement artifact and baseline noise contamination", *J. Biomech.* 43:1573), and
  450 Hz keeps the band the book says carries the signal (SENIAM recommends a low-pass near
  500 Hz, Hermens et al. 2000);
* a **bank band** centred at :math:`f_c` has its −3 dB edges half an octave apart in the
  pre-warped (bilinear) frequency axis :math:`\Omega = 2 f_s \tan(\pi f / f_s)`, symmetric
  about :math:`f_c` there (:math:`\Omega_c 2^{\pm 1/4}`), so the digital filter has unit gain
  exactly at :math:`f_c` and −3 dB exactly at its two edges; for :math:`f_c \ll f_s` the
  edges are :math:`f_c 2^{\pm 1/4}`.  The bands of the printed centres do not overlap; at
  2 kHz: 40 → 33.6–47.5 Hz, 100 → 84.3–118.5 Hz, 160 → 135.4–188.7 Hz, 360 → 312.1–411.6 Hz
  (70 → 58.9–83.1 Hz).

Every design checks the sampling rate: it must exceed twice the highest band edge, otherwise
:class:`~anthroarm.errors.SamplingRateError` says which band and the smallest usable rate.
Frequencies are in Hz, signals in volts, time along the last axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError, SamplingRateError
from ._checks import positive, signal

#: band-pass centre frequencies of Table 9.1, 方式1 (2 EMG channels), Hz
BOOK_BANK_2CH = (40.0, 100.0, 160.0, 360.0)
#: band-pass centre frequencies of Table 9.1, 方式2 (3 EMG channels), Hz
BOOK_BANK_3CH = (70.0, 160.0, 360.0)
#: conditioning band of the chain, Hz (an assumption after De Luca et al. 2010 and SENIAM)
CONDITIONING_BAND = (20.0, 450.0)
#: default bank bandwidth, octaves between the −3 dB edges (assumption, see the module text)
BANK_BANDWIDTH_OCTAVES = 0.5
#: the widest bank band accepted, octaves (a band-pass wider than this is not a bank band)
MAX_BANDWIDTH_OCTAVES = 10.0


def _bandwidth(bandwidth_octaves) -> float:
    b = positive(bandwidth_octaves, "bandwidth_octaves", "octaves")
    if b > MAX_BANDWIDTH_OCTAVES:
        raise EMGError(
            f"bandwidth_octaves {b:g} is wider than {MAX_BANDWIDTH_OCTAVES:g} octaves: not a bank "
            "band"
        )
    return b


def check_sampling_rate(fs, highest_edge_hz: float, what: str) -> float:
    """``fs`` (Hz) as a float; :class:`~anthroarm.errors.SamplingRateError` unless it exceeds
    twice ``highest_edge_hz`` (the Nyquist condition of the band ``what``)."""
    fs = positive(fs, "sampling rate fs", "Hz")
    need = 2.0 * highest_edge_hz
    if not fs > need:
        raise SamplingRateError(
            f"sampling rate {fs:g} Hz is not above twice the highest edge of {what} "
            f"({highest_edge_hz:.4g} Hz): use fs > {need:.4g} Hz or lower the band",
            fs=fs,
            required=need,
        )
    return fs


def band_edges(
    centre_hz: float, fs: float, bandwidth_octaves: float = BANK_BANDWIDTH_OCTAVES
) -> tuple[float, float]:
    r"""The −3 dB edges (Hz) of a bank band centred at ``centre_hz``.

    Nominal edges :math:`f_c 2^{\pm b/2}` (``b`` = ``bandwidth_octaves``) taken in the
    pre-warped axis :math:`\Omega = 2 f_s \tan(\pi f / f_s)`, so the bilinear design has unit
    gain at :math:`f_c` and −3 dB at both returned edges (assumption of this module, see above).
    ``fs`` must exceed :math:`2 f_c 2^{b/2}` (:class:`~anthroarm.errors.SamplingRateError`)."""
    fc = positive(centre_hz, "band centre", "Hz")
    b = _bandwidth(bandwidth_octaves)
    check_sampling_rate(fs, fc * 2.0 ** (b / 2), f"the band centred at {fc:g} Hz")
    fs = float(fs)
    # the pre-warped axis in units of 2 fs (tan, arctan of f/fs), so that no product with fs
    # overflows at extreme rates: fs = 1e308 gives the edges, not NaN
    tc = np.tan(np.pi * (fc / fs))
    lo = fs / np.pi * np.arctan(tc * 2.0 ** (-b / 2))
    hi = fs / np.pi * np.arctan(tc * 2.0 ** (b / 2))
    return float(lo), float(hi)


def bandpass_sos(low_hz: float, high_hz: float, fs: float, order: int = 2) -> np.ndarray:
    """Butterworth band-pass, −3 dB at ``low_hz`` and ``high_hz`` (Hz), ``order`` per edge, as
    second-order sections (``scipy.signal.butter(..., output="sos")``).  ``fs`` must exceed
    ``2 * high_hz``; ``0 < low_hz < high_hz``."""
    from scipy import signal as sps

    lo = positive(low_hz, "low edge", "Hz")
    hi = positive(high_hz, "high edge", "Hz")
    if not lo < hi:
        raise EMGError(f"band edges must satisfy low < high, got {lo:g} Hz and {hi:g} Hz")
    fs = check_sampling_rate(fs, hi, f"the band {lo:g}–{hi:g} Hz")
    if not (isinstance(order, (int, np.integer)) and 1 <= order <= 8):
        raise EMGError(f"filter order must be an integer 1..8, got {order!r}")
    return sps.butter(int(order), [lo, hi], btype="bandpass", fs=fs, output="sos")


def notch_sos(mains_hz: float, fs: float, q: float = 30.0) -> np.ndarray:
    """A second-order IIR notch at the mains frequency (``scipy.signal.iirnotch``, quality
    factor ``q``: −3 dB width mains/q Hz), as one SOS row.  The book names 50 Hz mains as the
    main interference (§9-2 二 1); the notch is optional, the differential front end is the
    book's remedy (:mod:`.frontend`)."""
    from scipy import signal as sps

    f0 = positive(mains_hz, "mains frequency", "Hz")
    fs = check_sampling_rate(fs, f0, f"the {f0:g} Hz notch")
    b, a = sps.iirnotch(f0, positive(q, "notch quality factor q"), fs=fs)
    return sps.tf2sos(b, a)


@dataclass(frozen=True, eq=False)
class FilterBank:
    """A bank of Butterworth band-pass filters (one per centre frequency), designed once.

    Parameters
    ----------
    centres_hz
        Centre frequencies, Hz (the book's sets: :data:`BOOK_BANK_2CH`, :data:`BOOK_BANK_3CH`).
    fs
        Sampling rate, Hz; must exceed twice the highest band edge.
    bandwidth_octaves
        Octaves between each band's −3 dB edges (assumption; default 0.5).
    order
        Butterworth order per edge (default 2).

    Attributes
    ----------
    edges : numpy.ndarray
        (n_bands, 2) −3 dB edges in Hz (:func:`band_edges`).
    sos : numpy.ndarray
        (n_bands, order, 6) second-order sections.
    """

    centres_hz: tuple
    fs: float
    bandwidth_octaves: float = BANK_BANDWIDTH_OCTAVES
    order: int = 2

    def __post_init__(self):
        try:
            c = np.atleast_1d(np.asarray(self.centres_hz, dtype=float))
        except (TypeError, ValueError):
            c = np.zeros((0, 0))
        if c.ndim != 1 or c.size == 0 or not np.all(np.isfinite(c)) or np.any(c <= 0):
            raise EMGError(
                f"centres_hz must be a non-empty list of finite frequencies > 0 (Hz), got "
                f"{self.centres_hz!r}"
            )
        b = _bandwidth(self.bandwidth_octaves)
        check_sampling_rate(
            self.fs, c.max() * 2.0 ** (b / 2), f"the band centred at {c.max():g} Hz"
        )
        edges = np.array([band_edges(f, self.fs, b) for f in c])
        sos = np.stack([bandpass_sos(lo, hi, self.fs, self.order) for lo, hi in edges])
        object.__setattr__(self, "centres_hz", tuple(float(f) for f in c))
        object.__setattr__(self, "fs", float(self.fs))
        object.__setattr__(self, "edges", edges)
        object.__setattr__(self, "sos", sos)

    def apply(self, x) -> np.ndarray:
        """Filter ``x`` (channels, samples) volts through every band (causal ``sosfilt`` from
        rest); returns (channels, n_bands, samples) volts."""
        from scipy import signal as sps

        a = signal(x, "emg", bytes_per_value=8.0 + 16.0 * len(self.sos))
        return np.stack([sps.sosfilt(s, a, axis=-1) for s in self.sos], axis=1)

    def gains(self, freqs_hz) -> np.ndarray:
        """|H(f)| of every band at ``freqs_hz`` (Hz), shape (n_bands, n_freqs) (``sosfreqz``)."""
        from scipy import signal as sps

        try:
            f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
        except (TypeError, ValueError):
            raise EMGError(f"freqs_hz must be frequencies in Hz, got {freqs_hz!r}") from None
        if not np.all(np.isfinite(f)):
            raise EMGError("freqs_hz contains NaN/inf")
        return np.stack([np.abs(sps.sosfreqz(s, worN=f, fs=self.fs)[1]) for s in self.sos])
