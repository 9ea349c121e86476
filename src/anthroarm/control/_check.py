"""Input checks shared by the modules of :mod:`anthroarm.control` (one place for the messages)."""

from __future__ import annotations

import numpy as np

from ..errors import ControlError
from ..spatial.rotations import as_scalar


def scalar(x, name: str) -> float:
    """``x`` as one finite float (:func:`anthroarm.spatial.rotations.as_scalar`), with a
    :class:`~anthroarm.errors.ControlError` naming ``name`` otherwise."""
    try:
        return as_scalar(x, name)
    except ValueError as exc:
        raise ControlError(str(exc)) from None


def positive(x, name: str) -> float:
    """A finite float > 0."""
    v = scalar(x, name)
    if v <= 0.0:
        raise ControlError(f"{name} must be > 0, got {v}")
    return v


def nonnegative(x, name: str) -> float:
    """A finite float >= 0."""
    v = scalar(x, name)
    if v < 0.0:
        raise ControlError(f"{name} must be >= 0, got {v}")
    return v


def array(x, name: str) -> np.ndarray:
    """A finite float array (any shape)."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ControlError(f"{name} must be numbers, got {x!r}") from None
    if not np.all(np.isfinite(a)):
        raise ControlError(f"{name} has a NaN or infinite element")
    return a


def time_grid(t, name: str = "t") -> np.ndarray:
    """A 1-D, finite, strictly increasing time grid of at least two samples (s)."""
    t = array(t, name)
    if t.ndim != 1 or t.size < 2:
        raise ControlError(f"{name} must be a 1-D array of at least two times, got shape {t.shape}")
    if np.any(np.diff(t) <= 0.0):
        raise ControlError(f"{name} must be strictly increasing")
    return t


def on_grid(x, t: np.ndarray, name: str) -> np.ndarray:
    """A scalar or an array of one value per time sample, as a (len(t),) array."""
    a = array(x, name)
    if a.ndim == 0:
        return np.full(t.shape, float(a))
    if a.shape != t.shape:
        raise ControlError(
            f"{name} must be a scalar or have one value per time sample {t.shape}, got {a.shape}"
        )
    return a


def count(x, name: str, minimum: int = 0) -> int:
    """An integer (not a bool) >= ``minimum``."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < minimum:
        raise ControlError(f"{name} must be an integer >= {minimum}, got {x!r}")
    return int(x)


def finite_result(func):
    """Decorate a method whose array result must be finite: a result beyond the float range
    (inputs near 1e308) is a :class:`~anthroarm.errors.ControlError` naming the method, not an
    inf or NaN handed back."""
    import functools

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with np.errstate(over="ignore", invalid="ignore"):
            out = func(*args, **kwargs)
        if not np.all(np.isfinite(out)):
            raise ControlError(
                f"{func.__name__}: the result is beyond the floating-point range for these inputs"
            )
        return out

    return wrapper
