r"""Frequency-domain EMG features by the FFT.

Book §9-2 (二 2): besides the time-domain amplitude, EMG is described in the **frequency
domain** with the FFT ("FFT 实时分析仪"); the muscles of a pair differ in frequency content
and in the distribution of spectral power, which separates their signals.  This module gives
the one-sided power spectral density (Welch's averaged periodogram, Hann window, 50 %
overlap; Welch 1967) and the standard spectral descriptors of surface EMG (Merletti & Parker
2004, ch. 6):

* **mean frequency** (spectral centroid) :math:`f_{mean} = \int f P(f)\,df / \int P(f)\,df`;
* **median frequency** :math:`f_{med}`: :math:`\int_0^{f_{med}} P = \tfrac12\int_0^\infty P`;
* **peak frequency**: the frequency of the largest PSD bin;
* **band powers**: :math:`\int_{f_1}^{f_2} P(f)\,df` over given bands (e.g. the −3 dB bands of
  a :class:`~anthroarm.emg.filters.FilterBank`), the FFT counterpart of the book's filter bank.

PSD in V²/Hz, power in V², frequencies in Hz; time along the last axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError
from ._checks import positive, signal


def spectrum(x, fs: float, segment_s: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """One-sided PSD of every channel: ``(freqs_hz, psd)`` with ``psd`` (channels, n_freqs) in
    V²/Hz (Welch, Hann window, segments of ``segment_s`` seconds, 50 % overlap; the segment is
    the whole record when shorter).  Parseval: ``psd.sum(-1) * df`` is the variance."""
    from scipy import signal as sps

    a = signal(x, "emg", min_samples=8, bytes_per_value=40.0)
    fs = positive(fs, "sampling rate fs", "Hz")
    n = min(a.shape[1], max(8, int(round(positive(segment_s, "segment_s", "s") * fs))))
    try:  # a rate at the end of the float range overflows Welch's scaling 1 / (fs Σw²)
        with np.errstate(over="raise", under="ignore"):
            f, p = sps.welch(
                a, fs=fs, window="hann", nperseg=n, noverlap=n // 2, detrend="constant", axis=-1
            )
    except FloatingPointError:
        raise EMGError(
            f"sampling rate fs = {fs:g} Hz is beyond what a spectrum can be computed at "
            "(its scaling overflows); give the rate in Hz"
        ) from None
    if not (np.isfinite(f).all() and np.isfinite(p).all()):
        raise EMGError(f"the spectrum at fs = {fs:g} Hz is not finite; give the rate in Hz")
    return f, p


def _spectrum_arrays(freqs, psd) -> tuple[np.ndarray, np.ndarray]:
    """``freqs`` (n,) Hz and ``psd`` (channels, n) as finite float arrays, else EMGError."""
    try:
        f = np.asarray(freqs, dtype=float)
        p = np.atleast_2d(np.asarray(psd, dtype=float))
    except (TypeError, ValueError):
        raise EMGError("freqs and psd must be numeric arrays (the output of spectrum())") from None
    if f.ndim != 1 or p.ndim != 2 or p.shape[-1] != f.size:
        raise EMGError(
            f"psd (channels, n_freqs) must have one bin per entry of freqs (n_freqs,), got shapes "
            f"{p.shape} and {f.shape}"
        )
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(p))):
        raise EMGError("freqs or psd contains NaN/inf")
    return f, p


def _weights(freqs, psd, band):
    f, p = _spectrum_arrays(freqs, psd)
    if band is not None:
        try:
            lo, hi = (float(b) for b in band)
        except (TypeError, ValueError):
            raise EMGError(f"band must be (low, high) in Hz, got {band!r}") from None
        if not lo < hi:
            raise EMGError(f"band must be (low, high) with low < high, in Hz; got {band!r}")
        keep = (f >= lo) & (f <= hi)
        f, p = f[keep], p[:, keep]
    tot = p.sum(axis=-1)
    if np.any(tot <= 0):
        raise EMGError(
            "the spectrum has no power (a silent channel): no frequency descriptor exists"
        )
    return f, p, tot


def mean_frequency(freqs, psd, band=None) -> np.ndarray:
    """Spectral centroid (Hz) per channel, optionally within ``band`` = (low, high) Hz."""
    f, p, tot = _weights(freqs, psd, band)
    return (p @ f) / tot


def median_frequency(freqs, psd, band=None) -> np.ndarray:
    """Median frequency (Hz) per channel: half the power below, half above (each bin's power
    spread over its width, the cumulative power interpolated linearly between bin edges)."""
    f, p, tot = _weights(freqs, psd, band)
    df = f[1] - f[0] if f.size > 1 else 1.0
    edges = np.concatenate([[f[0] - df / 2], f + df / 2])
    c = np.concatenate([np.zeros((p.shape[0], 1)), np.cumsum(p, axis=-1) / tot[:, None]], axis=1)
    return np.array([np.interp(0.5, ci, edges) for ci in c])


def peak_frequency(freqs, psd) -> np.ndarray:
    """Frequency (Hz) of the largest PSD bin, per channel."""
    f, p, _ = _weights(freqs, psd, None)
    return f[np.argmax(p, axis=-1)]


def band_powers(freqs, psd, bands) -> np.ndarray:
    """Power (V²) per channel and band: the PSD integrated (trapezoid) over each
    ``(low, high)`` row of ``bands`` (Hz); shape (channels, n_bands)."""
    f, p = _spectrum_arrays(freqs, psd)
    try:
        b = np.atleast_2d(np.asarray(bands, dtype=float))
    except (TypeError, ValueError):
        raise EMGError(f"bands must be rows (low, high) in Hz, got {bands!r}") from None
    if b.ndim != 2 or b.shape[-1] != 2 or not np.all(np.isfinite(b)) or np.any(b[:, 0] >= b[:, 1]):
        raise EMGError(f"bands must be rows (low, high) with low < high, in Hz; got {b.tolist()}")
    out = np.empty((p.shape[0], b.shape[0]))
    for j, (lo, hi) in enumerate(b):
        grid = np.concatenate([[lo], f[(f > lo) & (f < hi)], [hi]])
        vals = np.stack([np.interp(grid, f, pi) for pi in p])
        out[:, j] = np.trapezoid(vals, grid, axis=-1)
    return out


@dataclass(frozen=True)
class SpectralFeatures:
    """FFT descriptors of a recording, one entry per channel (Hz, V²)."""

    freqs: np.ndarray  #: (n_freqs,) Hz
    psd: np.ndarray  #: (channels, n_freqs) V²/Hz
    mean_hz: np.ndarray  #: spectral centroid
    median_hz: np.ndarray  #: median frequency
    peak_hz: np.ndarray  #: frequency of the PSD maximum
    power: np.ndarray  #: total power (variance), V²
    band_power: np.ndarray | None = None  #: (channels, n_bands) V² over the given bands


def spectral_features(x, fs: float, bands=None, segment_s: float = 0.25) -> SpectralFeatures:
    """All descriptors of :func:`spectrum` at once; ``bands`` (n_bands, 2) Hz or a
    :class:`~anthroarm.emg.filters.FilterBank` (its −3 dB edges) adds the band powers."""
    f, p = spectrum(x, fs, segment_s)
    if bands is not None and hasattr(bands, "edges"):
        bands = bands.edges
    df = f[1] - f[0]
    return SpectralFeatures(
        freqs=f,
        psd=p,
        mean_hz=mean_frequency(f, p),
        median_hz=median_frequency(f, p),
        peak_hz=peak_frequency(f, p),
        power=p.sum(axis=-1) * df,
        band_power=None if bands is None else band_powers(f, p, bands),
    )
