"""Input checks shared by the modules of :mod:`anthroarm.control` and :mod:`anthroarm.trajectory`
(one place for the messages), and the budgets that bound what a call may allocate or loop over.
A foundation module (it needs only :mod:`anthroarm.errors` and :mod:`anthroarm.spatial`), so
that both packages import it by its public name.

**Budgets.**  A time step that is tiny against a duration (``dt = 1e-12`` over 2 s) or a count
that is huge (``n = 10**12``) would ask for more memory than any machine has, or for a loop that
never ends in practice.  Every sampled result is checked *before* it is computed:

* :data:`MAX_VALUES` — the largest number of floats (samples × values per sample) a sampled
  result may hold: 2**25 ≈ 3.4e7 floats, 268 MB as float64;
* :data:`MAX_STEPS` — the largest number of integration or search steps one call may take:
  5e6 (a few seconds to a minute of Python).

A request beyond a budget is a :class:`~anthroarm.errors.ControlError` that says what it needs,
what the budget is and what to change.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .errors import ControlError
from .spatial.rotations import as_scalar

#: the largest number of float values (samples × values per sample) of one sampled result
MAX_VALUES = 2**25
#: the largest number of integration or search steps of one call
MAX_STEPS = 5_000_000


def scalar(x, name: str) -> float:
    """``x`` as one finite float (:func:`anthroarm.spatial.rotations.as_scalar`), with a
    :class:`~anthroarm.errors.ControlError` naming ``name`` otherwise (also for an integer
    beyond the float range and for a complex number)."""
    if isinstance(x, (complex, np.complexfloating)):
        raise ControlError(f"{name} must be a real number, got {x!r}")
    try:
        return as_scalar(x, name)
    except OverflowError:
        raise ControlError(
            f"{name} must be finite, got an integer beyond the float range"
        ) from None
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
    if np.iscomplexobj(x):
        raise ControlError(f"{name} must be real numbers, got complex values")
    try:
        a = np.asarray(x, dtype=float)
    except OverflowError:
        raise ControlError(f"{name} has an integer beyond the float range") from None
    except (TypeError, ValueError):
        raise ControlError(f"{name} must be numbers, got {short(x)}") from None
    if not np.all(np.isfinite(a)):
        raise ControlError(f"{name} has a NaN or infinite element")
    return a


def time_grid(t, name: str = "t") -> np.ndarray:
    """A 1-D, finite, strictly increasing time grid of at least two samples (s)."""
    t = array(t, name)
    if t.ndim != 1 or t.size < 2:
        raise ControlError(f"{name} must be a 1-D array of at least two times, got shape {t.shape}")
    if np.any(t[1:] <= t[:-1]):  # (np.diff would overflow between ends near ±1e308)
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


def count(x, name: str, minimum: int = 0, maximum: int | None = None) -> int:
    """An integer (not a bool) >= ``minimum`` (and <= ``maximum`` when given)."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < minimum:
        raise ControlError(f"{name} must be an integer >= {minimum}, got {short(x)}")
    if maximum is not None and x > maximum:
        raise ControlError(f"{name} = {int(x)} is beyond the budget of {maximum}")
    return int(x)


def short(x) -> str:
    r = repr(x)
    return r if len(r) <= 80 else r[:77] + "..."


def _fmt(n: float) -> str:
    return f"{n:.3g}" if n >= 1e6 else f"{n:g}"


def samples(n: float, width: int, what: str, remedy: str) -> int:
    """``n`` samples of ``width`` values each, as an int, within :data:`MAX_VALUES`; otherwise
    a :class:`~anthroarm.errors.ControlError` that says ``what`` needs them and the ``remedy``.
    ``n`` may be a float (``duration / dt``, possibly inf)."""
    width = max(1, int(width))
    if not (n * width <= MAX_VALUES):  # also inf and NaN
        raise ControlError(
            f"{what} needs {_fmt(n)} samples"
            + (f" of {width} values" if width > 1 else "")
            + f"; the budget is {MAX_VALUES} values (anthroarm.input_checks.MAX_VALUES): "
            + remedy
        )
    return int(n)


def steps(n: float, what: str, remedy: str) -> int:
    """``n`` integration or search steps, as an int, within :data:`MAX_STEPS`; otherwise a
    :class:`~anthroarm.errors.ControlError` naming ``what`` and the ``remedy``."""
    if not (n <= MAX_STEPS):
        raise ControlError(
            f"{what} needs {_fmt(n)} steps; the budget is {MAX_STEPS} steps "
            f"(anthroarm.input_checks.MAX_STEPS): {remedy}"
        )
    return int(n)


def n_per(duration: float, dt: float) -> float:
    """``ceil(duration / dt)`` as a float (inf when the quotient overflows), at least 1."""
    with np.errstate(over="ignore"):
        q = duration / dt
    return max(1.0, float(math.ceil(q))) if math.isfinite(q) else math.inf


def broadcast(*pairs) -> tuple[np.ndarray, ...]:
    """Broadcast ``(array, name)`` pairs against each other; a
    :class:`~anthroarm.errors.ControlError` naming them and their shapes otherwise."""
    try:
        return tuple(np.broadcast_arrays(*(a for a, _ in pairs)))
    except ValueError:
        shapes = ", ".join(f"{nm} {np.shape(a)}" for a, nm in pairs)
        raise ControlError(f"shapes that do not broadcast together: {shapes}") from None


def finite(value, what: str, remedy: str = "the inputs are too large or too small"):
    """``value`` when every element is finite, else a :class:`~anthroarm.errors.ControlError`."""
    if not np.all(np.isfinite(value)):
        raise ControlError(f"{what} is beyond the floating-point range: {remedy}")
    return value


def finite_result(func):
    """Decorate a method whose array result must be finite: a result beyond the float range
    (inputs near 1e308) is a :class:`~anthroarm.errors.ControlError` naming the method, not an
    inf or NaN handed back."""

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
