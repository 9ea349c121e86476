"""Result record shared by the Ch. 4 optimisers."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import ObjectiveError

#: statuses that count as success
OK_STATUSES = frozenset({"converged", "n_points"})


@dataclass
class OptimizeResult:
    """Outcome of an optimiser.

    ``status`` says what happened: ``"converged"`` (a stopping test of the book held),
    ``"n_points"`` (golden section used its n points, (4-13)), ``"maxiter"``, ``"not_unimodal"``
    (golden section saw two valleys), ``"no_minimum"`` (quadratic model not convex / no bracket),
    ``"infeasible"`` (constraints cannot all hold), ``"infeasible_bounds"`` (a lower bound above
    its upper bound), ``"infeasible_start"`` (interior method without a strictly feasible point),
    ``"nan"`` (the objective returned NaN somewhere; ``x`` and ``fun`` are then the best point
    where it was finite).  ``success`` is True only for the first two.
    ``x`` is the best point found (even on failure), ``fun`` its value (always finite: an
    objective that is never finite raises :class:`~anthroarm.errors.ObjectiveError`), ``nit``
    iterations (stages for SUMT), ``nfev`` objective evaluations, ``history`` the iterates, ``info``
    extras (e.g. final bracket, penalty parameter, constraint violation)."""

    x: object
    fun: float
    status: str
    message: str = ""
    nit: int = 0
    nfev: int = 0
    history: list = field(default_factory=list)
    info: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status in OK_STATUSES

    def __repr__(self) -> str:
        x = np.array2string(np.asarray(self.x, dtype=float), precision=6)
        return (
            f"OptimizeResult(status={self.status!r}, x={x}, fun={self.fun:.6g}, nit={self.nit}, "
            f"nfev={self.nfev}, message={self.message!r})"
        )


class Counted:
    """Wrap an objective: count calls, turn NaN into ``inf`` (a flag the caller reports as
    status ``"nan"``) and remember the lowest finite value seen, so that a result never carries
    a NaN/inf value (:meth:`result`)."""

    def __init__(self, f):
        if not callable(f):
            raise TypeError(f"objective must be callable, got {type(f).__name__}")
        self.f = f
        self.n = 0
        self.saw_nan = False
        self.best = None  # (x, f(x)) with the lowest finite f(x) seen
        self.last = (None, np.nan)  # last point evaluated and its raw value

    def __call__(self, x):
        self.n += 1
        v = float(self.f(x))
        if not np.isfinite(v):
            self.last = (x, v)
            if np.isnan(v):
                self.saw_nan = True
                return np.inf
            return v
        if self.best is None or v < self.best[1]:
            self.best = (np.array(x, dtype=float), v)
        return v

    def never_finite(self) -> ObjectiveError:
        x, v = self.last
        xs = np.array2string(np.asarray(x, dtype=float), precision=6) if x is not None else "?"
        return ObjectiveError(
            f"the objective never returned a finite value ({self.n} evaluations; "
            f"f = {v} at x = {xs})",
            x,
            v,
            self.n,
        )

    def result(
        self, x, fun, status, message="", nit=0, nfev=None, history=None, info=None
    ) -> OptimizeResult:
        """The :class:`OptimizeResult` of a run.  A non-finite ``fun`` (the objective was NaN or
        inf there), or status ``"nan"``, reports the best finite point and value seen instead; if
        there is none the run has nothing to report and :class:`~anthroarm.errors.ObjectiveError` is
        raised."""
        fun = float(fun)
        if status == "nan" or not np.isfinite(fun):
            if self.best is None:
                raise self.never_finite()
            x = self.best[0].reshape(np.shape(x)) if np.ndim(x) else float(self.best[0])
            fun = self.best[1]
        return OptimizeResult(
            x,
            fun,
            status,
            message,
            nit,
            self.n if nfev is None else nfev,
            [] if history is None else history,
            {} if info is None else info,
        )


#: largest magnitude accepted for a starting point, a step or a bound: squares and sums of
#: squares of such numbers (norms, the simplex spread, a quadratic objective) stay finite
MAX_COORD = 1e150


def as_vector(name: str, x, limit: float | None = None) -> np.ndarray:
    """``x`` as a finite 1-D float vector (a copy); ``limit`` bounds the magnitude of its
    entries."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    if x.ndim != 1:
        raise ValueError(f"{name} must be a 1-D vector, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN/inf: {x}")
    if limit is not None and np.any(np.abs(x) > limit):
        raise ValueError(f"{name} has an entry beyond +-{limit:g}: {x} (rescale the problem)")
    return x.copy()


def finite_interval(a, b):
    a, b = float(a), float(b)
    if not (np.isfinite(a) and np.isfinite(b)):
        raise ValueError(f"interval ends must be finite, got [{a}, {b}]")
    if not a < b:
        raise ValueError(f"need a < b for the search interval, got [{a}, {b}]")
    if max(abs(a), abs(b)) > MAX_COORD:
        raise ValueError(
            f"interval ends must lie within +-{MAX_COORD:g}, got [{a}, {b}] (rescale the problem)"
        )
    return a, b


def positive(name: str, value, allow_zero: bool = False) -> float:
    """A tolerance, step or factor: a finite number > 0 (>= 0 with ``allow_zero``)."""
    if isinstance(value, (bool, str, bytes)):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}") from None
    if not ((v > 0 or (allow_zero and v == 0)) and np.isfinite(v)):
        raise ValueError(
            f"{name} must be finite and {'>=' if allow_zero else '>'} 0, got {value!r}"
        )
    return v


def count(name: str, value, minimum: int = 1) -> int:
    """An iteration or point count: an integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if not (isinstance(value, (float, np.floating)) and float(value).is_integer()):
            raise TypeError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if v < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return v
