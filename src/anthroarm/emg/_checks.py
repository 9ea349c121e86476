"""Input checks shared by the EMG modules (one place for the messages)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import EMGError

#: the largest magnitude accepted as a voltage (V); squares and sums of it stay far from overflow
MAX_VOLTS = 1e6


def number(value, name: str, unit: str = "") -> float:
    """``value`` as a finite float, else :class:`~anthroarm.errors.EMGError` naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise EMGError(
            f"{name} must be a number{' in ' + unit if unit else ''}, got {value!r}"
        ) from None
    if not math.isfinite(v):
        raise EMGError(f"{name} must be finite{' (' + unit + ')' if unit else ''}, got {value!r}")
    return v


def positive(value, name: str, unit: str = "") -> float:
    """``value`` as a finite float > 0, else :class:`~anthroarm.errors.EMGError` naming it."""
    v = number(value, name, unit)
    if not v > 0:
        raise EMGError(
            f"{name} must be finite and > 0{' (' + unit + ')' if unit else ''}, got {value!r}"
        )
    return v


def nonnegative(value, name: str, unit: str = "") -> float:
    """``value`` as a finite float >= 0, else :class:`~anthroarm.errors.EMGError` naming it."""
    v = number(value, name, unit)
    if not v >= 0:
        raise EMGError(
            f"{name} must be finite and >= 0{' (' + unit + ')' if unit else ''}, got {value!r}"
        )
    return v


def count(value, name: str, lo: int, hi: int) -> int:
    """``value`` as an int in ``lo..hi`` (an integer type, not a float or a string), else
    :class:`~anthroarm.errors.EMGError` naming it."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise EMGError(f"{name} must be an integer in {lo}..{hi:g}, got {value!r}")
    return int(value)


def signal(x, name: str = "emg", n_channels: int | None = None, min_samples: int = 1) -> np.ndarray:
    """``x`` as a float array of shape (n_channels, n_samples) (a 1-D array is one channel when
    ``n_channels`` is None or 1); NaN/inf, magnitudes beyond :data:`MAX_VOLTS`, other ranks or a
    wrong channel count raise :class:`~anthroarm.errors.EMGError`."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise EMGError(
            f"{name} must be a numeric array (channels, samples), got {type(x).__name__}"
        ) from None
    if a.ndim == 1 and (n_channels is None or n_channels == 1):
        a = a[None, :]
    if a.ndim != 2:
        want = f"({n_channels}, n_samples)" if n_channels else "(channels, samples)"
        raise EMGError(f"{name} must have shape {want}, got shape {a.shape}")
    if n_channels is not None and a.shape[0] != n_channels:
        hint = " (samples along the last axis: pass emg.T?)" if a.shape[1] == n_channels else ""
        raise EMGError(f"{name} must have {n_channels} channels (rows), got shape {a.shape}{hint}")
    if a.shape[1] < min_samples:
        raise EMGError(f"{name} needs at least {min_samples} samples per channel, got {a.shape[1]}")
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise EMGError(
            f"{name} contains NaN/inf (first at channel {bad[0]}, sample {bad[1]}): "
            "fill or cut the gap before processing"
        )
    if a.size and np.max(np.abs(a)) > MAX_VOLTS:
        raise EMGError(
            f"{name} has values up to {np.max(np.abs(a)):.3g}, beyond {MAX_VOLTS:.0e} V: "
            "not a voltage (wrong units?)"
        )
    return a
