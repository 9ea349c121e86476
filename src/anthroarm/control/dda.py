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

from dataclasses import dataclass

import numpy as np

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


def _counts(counts) -> np.ndarray:
    a = np.asarray(counts)
    if a.ndim != 1 or a.size == 0:
        raise ControlError(
            f"counts must be a 1-D list of pulse counts (one per axis), got shape {a.shape}"
        )
    if a.dtype.kind not in "iu":
        try:
            f = np.asarray(a, dtype=float)
        except (TypeError, ValueError):
            raise ControlError(f"counts must be integers, got {counts!r}") from None
        if not np.all(np.isfinite(f)) or np.any(f != np.round(f)):
            raise ControlError(
                f"counts must be whole numbers of pulses, got {f.tolist()}; "
                "round positions to pulses with pulse_counts()"
            )
        if np.any(np.abs(f) > 2**62):
            raise ControlError("a pulse count is beyond 2**62")
        a = f.astype(np.int64)
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
    if N > 50_000_000 // max(1, c.size):
        raise ControlError(f"{N} ticks x {c.size} axes is too many pulses to tabulate")
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
    a = np.asarray(q_from, dtype=float)
    b = np.asarray(q_to, dtype=float)
    r = np.asarray(resolution, dtype=float)
    if a.shape != b.shape or a.ndim != 1:
        raise ControlError(
            f"q_from and q_to must be 1-D of the same length, got {a.shape} and {b.shape}"
        )
    if not (
        np.all(np.isfinite(a))
        and np.all(np.isfinite(b))
        and np.all(np.isfinite(r))
        and np.all(r > 0)
    ):
        raise ControlError("positions must be finite and the resolution finite and > 0")
    steps = (b - a) / r
    if np.any(np.abs(steps) > 2**62):
        raise ControlError("the move is beyond 2**62 pulses")
    return np.round(steps).astype(np.int64)
