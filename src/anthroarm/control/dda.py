"""DDA pulse distribution: every axis of a coordinated move ends on the same tick (§9-3 四,
line 7591 of the book: "coordinated motion by DDA pulse distribution, so that all channels
arrive simultaneously").

The book names the method (and glosses DDA wrongly as 动态数据分析; it is the *digital
differential analyser*, 数字微分分析器) but does not describe it.  The algorithm here is the
classical integrating DDA of NC pulse interpolation (e.g. Koren, *Computer Control of
Manufacturing Systems*, McGraw-Hill 1983, §4.3): for a move of ``Δ_k`` pulses on axis k over
``N`` ticks, each axis adds ``|Δ_k|`` to an accumulator every tick and emits one pulse (in the
direction of ``Δ_k``) whenever the accumulator reaches ``N``, subtracting ``N``.  With the
accumulators starting at zero, after tick j axis k has emitted exactly ``floor(j |Δ_k| / N)``
pulses, so

* each axis emits exactly ``|Δ_k|`` pulses in ``N`` ticks (integer arithmetic, no rounding),
* every moving axis emits its last pulse on tick ``N`` (``floor(N|Δ|/N) − floor((N−1)|Δ|/N) = 1``
  for ``|Δ| ≥ 1``): all axes arrive together,
* the pulses of each axis are spread as evenly as integers allow (gaps differ by at most one
  tick), so the joint path is a straight line in pulse space to within one pulse.

``N`` defaults to ``max |Δ_k|`` (the fastest axis pulses on every tick); an NC register of
``n`` bits uses ``N = 2**n``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError

__all__ = ["DDAResult", "dda", "pulse_counts"]


@dataclass(frozen=True)
class DDAResult:
    """Pulse trains of :func:`dda`.

    Attributes
    ----------
    counts : numpy.ndarray of int, shape (k,)
        The signed pulse count asked of each axis.
    pulses : numpy.ndarray of int8, shape (N, k)
        ``pulses[j, a]`` is +1, −1 or 0: the pulse axis ``a`` emits on tick ``j + 1``.
    n_ticks : int
        N, the number of ticks.
    status : str
        ``"ok"``, or ``"no motion"`` when every count is zero (``pulses`` then has N rows of
        zeros, N = 0 unless ``n_ticks`` was given).
    """

    counts: np.ndarray
    pulses: np.ndarray
    n_ticks: int
    status: str

    def positions(self) -> np.ndarray:
        """Cumulative pulse position of every axis after each tick, shape (N + 1, k), starting
        at zero."""
        return np.vstack(
            [
                np.zeros((1, self.counts.size), dtype=np.int64),
                np.cumsum(self.pulses, axis=0, dtype=np.int64),
            ]
        )

    def last_pulse_tick(self) -> np.ndarray:
        """The tick (1-based) of each axis's last pulse; 0 for an axis that does not move."""
        nz = self.pulses != 0
        any_ = nz.any(axis=0)
        last = self.n_ticks - np.argmax(nz[::-1], axis=0)
        return np.where(any_, last, 0)


#: the largest |count| accepted: beyond it ``j |Δ|`` of the accumulator could leave int64
MAX_COUNT = 2**62


def _counts(counts) -> np.ndarray:
    """Signed pulse counts as int64, every one within ±:data:`MAX_COUNT`, checked on the exact
    values (Python ints, or the array's own integer type) before any conversion can wrap."""
    try:
        a = np.asarray(counts)
    except (TypeError, ValueError, OverflowError):
        raise ControlError(f"counts must be integers, got {_check.short(counts)}") from None
    if a.ndim != 1 or a.size == 0:
        raise ControlError(
            f"counts must be a 1-D list of pulse counts (one per axis), got shape {a.shape}"
        )
    if a.dtype.kind in "iu":
        lo, hi = int(a.min()), int(a.max())  # exact Python ints: no wrap-around
    elif a.dtype.kind == "f" or (
        a.dtype.kind == "O"
        and all(isinstance(x, (int, float, np.integer, np.floating)) for x in a.tolist())
        and not any(isinstance(x, bool) for x in a.tolist())
    ):
        vals = a.tolist()
        fl = [float(v) for v in vals if not isinstance(v, (int, np.integer))]
        if not all(math.isfinite(x) and x == math.floor(x) for x in fl):
            raise ControlError(
                f"counts must be whole numbers of pulses, got {_check.short(vals)}; "
                "round positions to pulses with pulse_counts()"
            )
        ints = [int(v) for v in vals]
        lo, hi = min(ints), max(ints)
        a = np.array(ints, dtype=object)
    else:
        raise ControlError(
            f"counts must be integers, got {a.dtype.name} values {_check.short(counts)}"
        )
    if hi > MAX_COUNT or lo < -MAX_COUNT:
        big = hi if hi > MAX_COUNT else lo
        raise ControlError(
            f"counts: a pulse count of {big} is beyond ±2**62 (the DDA works in 64-bit "
            "integers); split the move into shorter ones"
        )
    return a.astype(np.int64)


def dda(counts, n_ticks: int | None = None) -> DDAResult:
    """Distribute signed pulse counts over ``N`` ticks with an integrating DDA (module docstring).

    Parameters
    ----------
    counts : array_like of int, shape (k,)
        Pulses to emit per axis (sign = direction).
    n_ticks : int, optional
        N; default ``max |counts|``.  Must be ≥ every ``|count|`` (one pulse per tick at most).

    Returns
    -------
    DDAResult
        Pulse trains with exact counts, all ending on tick N.

    Raises
    ------
    anthroarm.errors.ControlError
        Counts that are not whole numbers, ``n_ticks`` < 1 or below a ``|count|`` (a DDA with
        zero steps cannot move an axis).
    """
    c = _counts(counts)
    mag = np.abs(c)
    need = int(mag.max())
    if n_ticks is None:
        N = need
    else:
        if isinstance(n_ticks, bool) or not isinstance(n_ticks, (int, np.integer)):
            raise ControlError(f"n_ticks must be an integer, got {n_ticks!r}")
        N = int(n_ticks)
        if N < 1:
            raise ControlError(
                f"n_ticks must be >= 1 (a DDA with zero steps moves nothing), got {N}"
            )
        if N < need:
            raise ControlError(
                f"n_ticks = {N} is below the largest count {need}: a DDA emits at most one pulse "
                "per tick and axis"
            )
    if need == 0:
        return DDAResult(c, np.zeros((N, c.size), dtype=np.int8), N, "no motion")
    _check.samples(
        N,
        c.size,
        f"a DDA of {N} ticks over {c.size} axes",
        "tabulate fewer ticks (n_ticks, or split the move into shorter ones)",
    )
    j = np.arange(N + 1, dtype=np.int64)[:, None]
    emitted = (j * mag[None, :]) // N  # floor(j |Δ| / N): the accumulator's overflows
    pulses = (np.diff(emitted, axis=0) * np.sign(c)[None, :]).astype(np.int8)
    return DDAResult(c, pulses, N, "ok")


def pulse_counts(q_from, q_to, resolution) -> np.ndarray:
    """Signed whole pulse counts of a joint move, ``round((q_to − q_from) / resolution)``.

    Parameters
    ----------
    q_from, q_to : array_like, shape (k,)
        Joint positions (rad or m).
    resolution : float or array_like, shape (k,)
        Joint motion per pulse (rad or m per pulse; > 0).

    Returns
    -------
    numpy.ndarray of int64
    """
    a = _check.array(q_from, "q_from")
    b = _check.array(q_to, "q_to")
    r = _check.array(resolution, "resolution")
    if a.shape != b.shape or a.ndim != 1 or a.size == 0:
        raise ControlError(
            f"q_from and q_to must be 1-D of the same length (at least one axis), got "
            f"{a.shape} and {b.shape}"
        )
    if r.shape not in ((), a.shape):
        raise ControlError(
            f"resolution must be a scalar or one value per axis {a.shape}, got shape {r.shape}"
        )
    if not np.all(r > 0):
        raise ControlError(f"resolution must be > 0, got {r.tolist()}")
    with np.errstate(over="ignore", invalid="ignore"):
        steps = (b - a) / r
    if not np.all(np.abs(steps) <= MAX_COUNT):  # also inf: the move overflowed
        raise ControlError(
            "the move is beyond 2**62 pulses on an axis (resolution too fine for the distance)"
        )
    return np.round(steps).astype(np.int64)
