"""The argument checks of the viewer's public methods: colours, point arrays, lengths.

Each raises :class:`~anthroarm.errors.ParameterError` (a TypeError and ValueError) with the
shape or value it got and the one it expects.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError


def rgb255(value, what: str) -> list[int]:
    """One colour (r, g, b), components in 0..255 -> a list of three ints."""
    try:
        c = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        c = np.array([np.nan])
    if c.shape != (3,) or not np.all(np.isfinite(c)) or np.any((c < 0) | (c > 255)):
        raise ParameterError(f"{what} must be three numbers (r, g, b) in 0..255, got {value!r}")
    return [int(round(x)) for x in c]


def check_background(background):
    """``None`` or ((r, g, b), (r, g, b)) with 0..255 components -> two lists of ints."""
    if background is None:
        return None
    if (
        isinstance(background, (str, bytes))
        or not hasattr(background, "__len__")
        or len(background) != 2
    ):
        raise ParameterError(
            f"background must be ((r, g, b), (r, g, b)) in 0..255 (top, bottom), got {background!r}"
        )
    return rgb255(background[0], "background top colour"), rgb255(
        background[1], "background bottom colour"
    )


def rgb01(value, n: int, what: str) -> np.ndarray:
    """One colour (3,) or one per item (n, 3), components in [0, 1] -> (n, 3) float."""
    try:
        c = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        c = np.array([np.nan])
    if c.shape == (3,):
        c = np.tile(c, (n, 1))
    if c.shape != (n, 3) or not np.all(np.isfinite(c)) or np.any((c < 0) | (c > 1)):
        raise ParameterError(
            f"{what} must be one colour (r, g, b) or ({n}, 3) colours, components in 0..1, "
            f"got shape {np.shape(value)}"
        )
    return c


def points3(points, what: str, min_rows: int = 1) -> np.ndarray:
    """An (N >= ``min_rows``, 3) array of finite numbers (one 3-vector: N = 1), as floats."""
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{what} must be an (N, 3) array of numbers (m, base frame), got {type(points).__name__}"
        ) from None
    if P.shape == (3,):
        P = P[None]
    if P.ndim != 2 or P.shape[1] != 3 or len(P) < min_rows:
        raise ParameterError(
            f"{what} must be an (N>={min_rows}, 3) array (m, base frame), got shape {P.shape}"
        )
    if not np.all(np.isfinite(P)):
        bad = int(np.argmax(~np.isfinite(P).all(axis=1)))
        raise ParameterError(f"{what} contain NaN or inf (row {bad})")
    return P


def positive_length(value, default: float, what: str) -> float:
    """``default`` for None, else ``value`` as a positive finite float (m)."""
    if value is None:
        return float(default)
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{what} must be a positive number, got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(f"{what} must be positive and finite, got {value!r}")
    return v
