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


#: bytes of working memory one call on a whole recording may take (the input's float copy, the
#: filters' outputs and temporaries: each function states its factor, bytes per input value,
#: measured with ``ru_maxrss``).  A longer recording is refused with the remedy: stream it
#: through :meth:`~anthroarm.emg.processor.EMGProcessor.process` in blocks with
#: ``reset=False`` (the same result as one piece), or cut it.
MEMORY_BUDGET = 2 * 2**30
#: dtype kinds accepted as EMG samples: signed/unsigned integers (ADC counts) and floats; not
#: complex (the imaginary part would be dropped), bool, strings, dates or records
_REAL_KINDS = "iuf"


def budget(values: int, bytes_per_value: float, what: str) -> None:
    """Refuse a call whose working memory ``values * bytes_per_value`` exceeds
    :data:`MEMORY_BUDGET` (:class:`~anthroarm.errors.EMGError` with the remedy)."""
    need = float(values) * float(bytes_per_value)
    if need > MEMORY_BUDGET:
        raise EMGError(
            f"{what}: {values:.4g} values would take about {need / 2**30:.3g} GiB of working "
            f"memory, beyond the budget of {MEMORY_BUDGET / 2**30:g} GiB "
            "(anthroarm.emg._checks.MEMORY_BUDGET). Remedy: process the recording in blocks "
            "(EMGProcessor.process(block, reset=False) gives the result of one piece) or cut it"
        )


def signal(
    x,
    name: str = "emg",
    n_channels: int | None = None,
    min_samples: int = 1,
    bytes_per_value: float = 24.0,
) -> np.ndarray:
    """``x`` as a float array of shape (n_channels, n_samples) (a 1-D array is one channel when
    ``n_channels`` is None or 1).  Raises :class:`~anthroarm.errors.EMGError` for: complex,
    boolean, string or date samples (never converted silently: a complex array would lose its
    imaginary part); masked samples or NaN/inf (gaps: fill or cut them first); magnitudes
    beyond :data:`MAX_VOLTS`; other ranks, no channel, a wrong channel count; more values than
    the memory budget allows at ``bytes_per_value`` bytes of working memory each
    (:func:`budget`)."""
    if isinstance(x, np.ma.MaskedArray):
        m = np.ma.getmaskarray(x)
        if m.any():
            bad = np.argwhere(m)[0]
            raise EMGError(
                f"{name} has masked samples (a gap; first at index {tuple(int(i) for i in bad)}): "
                "fill or cut the gap before processing"
            )
        x = np.ma.getdata(x)
    raw = x if isinstance(x, np.ndarray) else None
    if raw is None:
        try:
            raw = np.asarray(x)
        except (TypeError, ValueError):
            raise EMGError(
                f"{name} must be a numeric array (channels, samples), got {type(x).__name__} "
                "(ragged rows?)"
            ) from None
    if raw.dtype.kind == "c" or (
        raw.dtype.kind == "O" and any(isinstance(v, complex) for v in raw.flat)
    ):
        raise EMGError(
            f"{name} has complex samples (dtype {raw.dtype}): EMG is a real voltage; pass the "
            "real part (x.real) or the magnitude (abs(x)) explicitly if that is what you mean"
        )
    if raw.dtype.kind not in _REAL_KINDS + "O":
        raise EMGError(
            f"{name} must hold real numbers (volts), got dtype {raw.dtype} "
            "(booleans, strings and dates are not samples)"
        )
    budget(raw.size, bytes_per_value, f"{name} of shape {raw.shape}")
    try:
        a = np.asarray(raw, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise EMGError(
            f"{name} must be a numeric array (channels, samples), got {type(x).__name__}"
        ) from None
    if a.ndim == 1 and (n_channels is None or n_channels == 1):
        a = a[None, :]
    if a.ndim != 2:
        want = f"({n_channels}, n_samples)" if n_channels else "(channels, samples)"
        raise EMGError(f"{name} must have shape {want}, got shape {a.shape}")
    if a.shape[0] == 0:
        raise EMGError(f"{name} has no channel (shape {a.shape})")
    if n_channels is not None and a.shape[0] != n_channels:
        hint = " (samples along the last axis: pass emg.T?)" if a.shape[1] == n_channels else ""
        raise EMGError(f"{name} must have {n_channels} channels (rows), got shape {a.shape}{hint}")
    if a.shape[1] < min_samples:
        raise EMGError(f"{name} needs at least {min_samples} samples per channel, got {a.shape[1]}")
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise EMGError(
            f"{name} contains NaN/inf (a gap or a dropout; first at channel {bad[0]}, sample "
            f"{bad[1]}): fill or cut the gap before processing"
        )
    if a.size and np.max(np.abs(a)) > MAX_VOLTS:
        raise EMGError(
            f"{name} has values up to {np.max(np.abs(a)):.3g}, beyond {MAX_VOLTS:.0e} V: "
            "not a voltage (wrong units?)"
        )
    return a
