"""SUMT penalty methods (序列无约束极小化), book §4-4, Eq. (4-65)–(4-78).

Constraints follow §4-3 and SciPy: inequalities are feasible when ``g_u(X) ≥ 0``; equalities
``h_v(X) = 0``.  (For the book's ``g ≤ 0`` form (4-65)/(4-69) pass ``-g``.)  Bounds
``[(lo, hi), …]`` become the inequalities ``x − lo ≥ 0``, ``hi − x ≥ 0``.

* interior (内点法, barrier), (4-66): ``φ = f + r Σ 1/g_u``, r⁽⁰⁾ > r⁽¹⁾ > … → 0, from a
  strictly feasible point; infeasible trial points are rejected (φ = +∞).  Stop when
  ``|X*(r_k) − X*(r_{k−1})| < ε1`` (4-67) and ``|(φ_k − φ_{k−1})/φ_{k−1}| < ε2`` (4-68).
* exterior (外点法), (4-72)/(4-73): ``φ = f + M Σ min(0, g_u)² + M Σ h_v²``, M → ∞.  Stop when
  the largest violation ``Q ≤ ε1`` (4-74), or, once M > R, when ``|ΔX*| ≤ ε2`` (4-75) (the
  printed "M > R" in step 5 is read as in (4-75), see the notes).
* mixed (混合法), (4-78): ``φ = f + r Σ 1/g_u + r^{−1/2} Σ h_v²`` (Fiacco's M = r^{−1/2}, (4-77)).

The unconstrained minimiser is the book's simplex (:func:`simplex_book`) by default; any
``inner(phi, x0) -> OptimizeResult`` can be passed.  The book gives no values for r⁽⁰⁾, C, ε:
r⁽⁰⁾ = 1 ("many programs", l. 2013), C = 0.1 (interior/mixed) and 10 (exterior) are ours.

Arguments are checked (``ValueError``): r⁽⁰⁾, M⁽⁰⁾, R, ε1, ε2 and ``scale`` finite and > 0,
``max_stages`` an integer ≥ 1, ``x0`` finite within ±1e150, a bound NaN or beyond ±1e150 (±inf
means no bound).  An empty bound (lo ≥ hi) gives status ``"infeasible_bounds"`` with f(x0); an
objective (or penalty function) that is never finite raises
:class:`~anthroarm.errors.ObjectiveError`; one that is NaN somewhere gives status ``"nan"`` with
the best finite point.
"""

from __future__ import annotations

import numpy as np

from ...errors import ObjectiveError
from .result import MAX_COORD, OptimizeResult, as_vector, count, positive
from .simplex import simplex_book


def _vec(fn, x):
    if fn is None:
        return np.zeros(0)
    return np.atleast_1d(np.asarray(fn(x), dtype=float)).ravel()


def _check_bounds(bounds):
    """``[(lo, hi), …]`` as floats (None → ∓inf).  Raises ``ValueError`` naming a bound that is
    NaN or beyond ±1e150 (±inf means "no bound")."""
    out = []
    for i, b in enumerate(bounds):
        try:
            lo, hi = b
        except (TypeError, ValueError):
            raise ValueError(f"bound {i} must be a pair (lo, hi), got {b!r}") from None
        lo = -np.inf if lo is None else float(lo)
        hi = np.inf if hi is None else float(hi)
        for name, v in (("lower", lo), ("upper", hi)):
            if np.isnan(v) or (np.isfinite(v) and abs(v) > MAX_COORD):
                raise ValueError(
                    f"bound {i}: the {name} bound must be a number within +-{MAX_COORD:g} "
                    f"or +-inf (no bound), got {v!r}"
                )
        out.append((lo, hi))
    return out


def _empty_bound(bounds):
    """Message naming the first bound with lo >= hi, or None."""
    for i, (lo, hi) in enumerate(bounds):
        if lo >= hi:
            return f"bound {i} is empty: lower {lo:g} >= upper {hi:g}"
    return None


def bounds_to_ineq(bounds):
    """``[(lo, hi), …]`` -> function ``x -> [x_i − lo_i, hi_i − x_i, …]`` (≥ 0 when feasible).
    ``None`` or ±inf ends are skipped.  Raises ``ValueError`` on a bound with lo ≥ hi, or one
    that is NaN or beyond ±1e150, naming it."""
    bounds = _check_bounds(bounds)
    empty = _empty_bound(bounds)
    if empty:
        raise ValueError(empty)

    def g(x):
        out = []
        for xi, (lo, hi) in zip(np.asarray(x, dtype=float), bounds):
            if np.isfinite(lo):
                out.append(xi - lo)
            if np.isfinite(hi):
                out.append(hi - xi)
        return np.array(out)

    return g


def _combine(ineq, bounds):
    gb = bounds_to_ineq(bounds) if bounds is not None else None
    if gb is None:
        return ineq
    if ineq is None:
        return gb
    return lambda x: np.concatenate([_vec(ineq, x), gb(x)])


def _finite_f(f, x, what: str) -> float:
    """``f(x)`` for a result; an objective that is not finite there raises ObjectiveError."""
    v = float(f(x))
    if not np.isfinite(v):
        raise ObjectiveError(f"the objective is {v} at {what} x = {np.asarray(x)}", x, v, 1)
    return v


def _check_params(max_stages, eps1, eps2, scale, **factors):
    for name, v in factors.items():
        positive(name, v)
    return (
        count("max_stages", max_stages),
        positive("eps1", eps1),
        positive("eps2", eps2),
        positive("scale", scale),
    )


def _prepare(f, x0, ineq, eq, bounds):
    x0 = as_vector("x0", x0, limit=MAX_COORD)
    if bounds is not None:
        if len(bounds) != x0.size:
            raise ValueError(f"bounds has {len(bounds)} entries for {x0.size} variables")
        empty = _empty_bound(_check_bounds(bounds))
        if empty:
            return None, OptimizeResult(
                x0, _finite_f(f, x0, "the starting point"), "infeasible_bounds", empty, nfev=1
            )
    return (x0, _combine(ineq, bounds)), None


def _default_inner(phi, x, scale):
    step = 0.1 * np.maximum(np.abs(x), scale)
    return simplex_book(
        phi, x, step=step, eps1=1e-20, xtol=1e-10 * (1 + np.linalg.norm(x)), maxiter=4000
    )


def _barrier_inner(phi, x, scale, g):
    """Book simplex for a barrier function: the initial simplex is kept inside the feasible region
    (edge = half the smallest constraint value) and the search restarts from its result until it
    stops improving — a collapsed simplex cannot follow the narrow curved valley along an active
    constraint otherwise."""

    def step_at(z):
        return min(
            0.1 * float(np.max(np.maximum(np.abs(z), scale))),
            max(0.5 * float(np.min(_vec(g, z))), 1e-12),
        )

    best, nfev = None, 0
    for _ in range(4):
        r = simplex_book(
            phi, x, step=step_at(x), eps1=1e-20, xtol=1e-12 * (1 + np.linalg.norm(x)), maxiter=4000
        )
        nfev += r.nfev
        if best is not None and r.fun >= best.fun - 1e-15 * abs(best.fun):
            if r.fun < best.fun:
                best = r
            break
        best, x = r, r.x
    best.nfev = nfev
    return best


def _nan_result(f, x, stage, nfev, hist) -> OptimizeResult:
    return OptimizeResult(
        x,
        _finite_f(f, x, f"the best finite point of stage {stage}"),
        "nan",
        f"the objective or a constraint returned NaN in stage {stage} "
        "(x, fun: the best finite point)",
        stage,
        nfev,
        hist,
    )


def violation(x, ineq=None, eq=None) -> float:
    """Largest constraint violation Q: ``max(−g_u, |h_v|, 0)`` (4-74)."""
    g, h = _vec(ineq, x), _vec(eq, x)
    return float(max(np.max(-g, initial=0.0), np.max(np.abs(h), initial=0.0), 0.0))


def find_feasible(x0, ineq, margin: float = 1e-6, inner=None):
    """Phase 1 for the interior method: minimise ``Σ min(0, g_u − margin)²`` from x0.
    Returns a strictly feasible point or None."""

    def pen(x):
        return float(np.sum(np.minimum(0.0, _vec(ineq, x) - margin) ** 2))

    x = np.asarray(x0, dtype=float)
    for _ in range(5):
        if np.all(_vec(ineq, x) > 0):
            return x
        r = (inner or (lambda p, z: _default_inner(p, z, 1.0)))(pen, x)
        if np.allclose(r.x, x):
            break
        x = r.x
    return x if np.all(_vec(ineq, x) > 0) else None


def _barrier_method(
    name, f, x0, ineq, eq, bounds, r0, c, eps1, eps2, max_stages, inner, scale
) -> OptimizeResult:
    """The stage loop shared by the interior (4-66) and mixed (4-78) methods: barrier
    ``r Σ 1/g_u`` on the inequalities, plus ``r^{−1/2} Σ h_v²`` when there are equalities;
    r shrinks by ``c`` per stage until (4-67) and (4-68) hold."""
    max_stages, eps1, eps2, scale = _check_params(max_stages, eps1, eps2, scale, r0=r0, c=c)
    if not c < 1:
        raise ValueError(f"need r0 > 0 and 0 < c < 1, got r0={r0!r}, c={c!r}")
    prep, bad = _prepare(f, x0, ineq, eq, bounds)
    if bad:
        return bad
    x, g = prep
    if g is None:
        raise ValueError(f"{name} needs inequality constraints (ineq or bounds); use sumt_exterior")
    if not np.all(_vec(g, x) > 0):
        xf = find_feasible(x, g)
        if xf is None:
            return OptimizeResult(
                x,
                _finite_f(f, x, "the starting point"),
                "infeasible",
                "no strictly feasible starting point found: the constraints may be inconsistent",
                info={"violation": violation(x, g, eq)},
            )
        x = xf
    inner = inner or (lambda p, z: _barrier_inner(p, z, scale, g))
    r = float(r0)
    hist, nfev = [x.copy()], 0
    phi_prev, x_prev = None, x.copy()
    status, msg = "maxiter", f"no convergence in {max_stages} stages"
    k = 0
    for k in range(1, max_stages + 1):

        def phi(z, r=r):
            gz = _vec(g, z)
            if np.any(gz <= 0):
                return np.inf
            val = float(f(z)) + r * float(np.sum(1.0 / gz))  # (4-66)
            if eq is not None:
                val += r**-0.5 * float(np.sum(_vec(eq, z) ** 2))  # (4-78)
            return val

        res = inner(phi, x)
        nfev += res.nfev
        x = np.asarray(res.x, dtype=float)
        hist.append(x.copy())
        if res.status == "nan":
            return _nan_result(f, x, k, nfev, hist)
        ph = res.fun
        if phi_prev is not None:
            dx = np.linalg.norm(x - x_prev)
            dphi = abs((ph - phi_prev) / phi_prev) if phi_prev != 0 else abs(ph - phi_prev)
            if dx < eps1 and dphi < eps2:  # (4-67), (4-68)
                status, msg = "converged", "(4-67) and (4-68) hold"
                break
        phi_prev, x_prev = ph, x.copy()
        r *= c
    Q = violation(x, g, eq)
    if eq is not None and status == "converged" and Q > 1e-4 * (1 + np.linalg.norm(x)):
        status, msg = "infeasible", f"equality constraints violated by {Q:.3g} at the end"
    return OptimizeResult(
        x,
        _finite_f(f, x, "the result"),
        status,
        msg,
        k,
        nfev,
        hist,
        {"r": r, "violation": Q, "g": _vec(g, x), "h": _vec(eq, x)},
    )


def sumt_interior(
    f,
    x0,
    ineq,
    bounds=None,
    r0: float = 1.0,
    c: float = 0.1,
    eps1: float = 1e-7,
    eps2: float = 1e-7,
    max_stages: int = 40,
    inner=None,
    scale: float = 1.0,
) -> OptimizeResult:
    """Interior penalty (barrier) method, Eq. (4-66)–(4-68).

    ``ineq(x)`` returns the g_u (feasible ≥ 0).  If ``x0`` is not strictly feasible a phase-1
    search (:func:`find_feasible`) looks for one; if none is found the status is ``"infeasible"``.
    ``info``: the final r, the constraint values and the largest violation."""
    return _barrier_method(
        "sumt_interior", f, x0, ineq, None, bounds, r0, c, eps1, eps2, max_stages, inner, scale
    )


def sumt_exterior(
    f,
    x0,
    ineq=None,
    eq=None,
    bounds=None,
    M0: float = 1.0,
    c: float = 10.0,
    eps1: float = 1e-6,
    eps2: float = 1e-7,
    R: float = 1e8,
    max_stages: int = 40,
    inner=None,
    scale: float = 1.0,
) -> OptimizeResult:
    """Exterior penalty method, Eq. (4-69)–(4-75), any starting point.

    Converged when the largest violation Q ≤ ``eps1`` (4-74).  When M exceeds the control value
    ``R`` and X* stops moving (4-75) while Q is still above ``eps1``, the constraints cannot be
    met: status ``"infeasible"`` with the remaining violation in ``info``."""
    max_stages, eps1, eps2, scale = _check_params(max_stages, eps1, eps2, scale, M0=M0, c=c, R=R)
    if not c > 1:
        raise ValueError(f"need M0 > 0 and c > 1, got M0={M0!r}, c={c!r}")
    prep, bad = _prepare(f, x0, ineq, eq, bounds)
    if bad:
        return bad
    x, g = prep
    inner = inner or (lambda p, z: _default_inner(p, z, scale))
    M = float(M0)
    hist, nfev = [x.copy()], 0
    x_prev = None
    status, msg = "maxiter", f"no convergence in {max_stages} stages"
    k = 0
    Q = violation(x, g, eq)
    for k in range(1, max_stages + 1):

        def phi(z, M=M):
            pen = np.sum(np.minimum(0.0, _vec(g, z)) ** 2) + np.sum(
                _vec(eq, z) ** 2
            )  # (4-72)/(4-73)
            return float(f(z)) + M * float(pen)

        res = inner(phi, x)
        nfev += res.nfev
        x = np.asarray(res.x, dtype=float)
        hist.append(x.copy())
        if res.status == "nan":
            return _nan_result(f, x, k, nfev, hist)
        Q = violation(x, g, eq)
        if Q <= eps1:  # (4-74)
            status, msg = "converged", f"largest violation Q = {Q:.3g} <= {eps1:g} (4-74)"
            break
        if (
            M > R
            and x_prev is not None
            and np.linalg.norm(x - x_prev) <= eps2 * (1 + np.linalg.norm(x))
        ):
            status = "infeasible"  # (4-75) holds but Q does not
            msg = (
                f"X* stopped moving at M = {M:.3g} with violation Q = {Q:.3g} > {eps1:g}: "
                "the constraints cannot all be satisfied"
            )
            break
        x_prev = x.copy()
        M *= c
    return OptimizeResult(
        x,
        _finite_f(f, x, "the result"),
        status,
        msg,
        k,
        nfev,
        hist,
        {"M": M, "violation": Q, "g": _vec(g, x), "h": _vec(eq, x)},
    )


def sumt_mixed(
    f,
    x0,
    ineq,
    eq=None,
    bounds=None,
    r0: float = 1.0,
    c: float = 0.1,
    eps1: float = 1e-7,
    eps2: float = 1e-7,
    max_stages: int = 40,
    inner=None,
    scale: float = 1.0,
) -> OptimizeResult:
    """Mixed method, Eq. (4-78): barrier on the inequalities, ``r^{−1/2}`` penalty on the
    equalities.  X⁽⁰⁾ must satisfy the inequalities strictly (phase 1 is tried otherwise).
    Status ``"infeasible"`` when the stages converge with the equalities still violated."""
    return _barrier_method(
        "sumt_mixed", f, x0, ineq, eq, bounds, r0, c, eps1, eps2, max_stages, inner, scale
    )
