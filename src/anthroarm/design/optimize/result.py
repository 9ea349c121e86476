"""Result record shared by the Ch. 4 optimisers."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

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
    ``"nan"`` (the objective returned NaN).  ``success`` is True only for the first two.
    ``x`` is the best point found (even on failure), ``fun`` its value, ``nit`` iterations
    (stages for SUMT), ``nfev`` objective evaluations, ``history`` the iterates, ``info`` extras
    (e.g. final bracket, penalty parameter, constraint violation)."""

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
        return (f"OptimizeResult(status={self.status!r}, x={x}, fun={self.fun:.6g}, nit={self.nit}, "
                f"nfev={self.nfev}, message={self.message!r})")


class Counted:
    """Wrap an objective: count calls, turn NaN into a flag the caller can report."""

    def __init__(self, f):
        if not callable(f):
            raise TypeError(f"objective must be callable, got {type(f).__name__}")
        self.f = f
        self.n = 0
        self.saw_nan = False

    def __call__(self, x):
        self.n += 1
        v = float(self.f(x))
        if np.isnan(v):
            self.saw_nan = True
            return np.inf
        return v


def as_vector(name: str, x) -> np.ndarray:
    x = np.atleast_1d(np.asarray(x, dtype=float))
    if x.ndim != 1:
        raise ValueError(f"{name} must be a 1-D vector, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN/inf: {x}")
    return x.copy()


def finite_interval(a, b):
    a, b = float(a), float(b)
    if not (np.isfinite(a) and np.isfinite(b)):
        raise ValueError(f"interval ends must be finite, got [{a}, {b}]")
    if not a < b:
        raise ValueError(f"need a < b for the search interval, got [{a}, {b}]")
    return a, b
