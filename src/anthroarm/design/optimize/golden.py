"""Golden-section search (黄金分割法, 0.618 法), book §4-4, Eq. (4-9)–(4-14).

Interval elimination on a unimodal (单峰) interval [a, b]: the two interior points
``α1 = b − λ(b − a)`` and ``α2 = a + λ(b − a)`` (4-10)/(4-11) with ``λ = (√5 − 1)/2`` (4-12);
each new point shrinks the interval by λ, so n points leave ``λ^{n−1}(b − a)`` and
``n ≥ ln(ε/(b − a))/ln λ + 1`` points reach a tolerance ε (4-13).  Update rule (4-14):
if f(α2) > f(α1) keep [a, α2], else keep [α1, b].
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import ObjectiveError
from .result import Counted, OptimizeResult, count, finite_interval, positive

#: Eq. (4-12): the positive root of λ² + λ − 1 = 0
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def golden_points_needed(a: float, b: float, eps: float) -> int:
    """Eq. (4-13): the smallest n with ``λ^{n−1}(b − a) ≤ ε``."""
    a, b = finite_interval(a, b)
    eps = positive("eps", eps)
    if eps >= b - a:
        return 1
    n = math.log(eps / (b - a)) / math.log(GOLDEN) + 1
    return int(math.ceil(n - 1e-12))


def unimodality_violation(xs, fs, rtol: float = 1e-10):
    """First sampled point that proves the samples are not unimodal (a rise followed by a fall),
    or None.  ``xs`` need not be sorted."""
    xs = np.asarray(xs, dtype=float)
    fs = np.asarray(fs, dtype=float)
    o = np.argsort(xs)
    xs, fs = xs[o], fs[o]
    finite = np.isfinite(fs)
    xs, fs = xs[finite], fs[finite]
    if len(fs) < 3:
        return None
    tol = rtol * (1.0 + np.max(np.abs(fs)))
    d = np.diff(fs)
    rising = False
    for i, di in enumerate(d):
        if di > tol:
            rising = True
        elif di < -tol and rising:
            return float(xs[i + 1])
    return None


def golden_section(
    f, a: float, b: float, eps: float = 1e-6, n: int | None = None, scan: int = 11
) -> OptimizeResult:
    """Minimise ``f`` on [a, b] by the book's golden section (4-14).

    ``n`` points (default from (4-13) for ``eps``); stops after n points or when the interval is
    ≤ ε.  Unimodality is required by the method: ``scan`` extra evenly spaced samples (0 to skip)
    plus every evaluated point are checked, and a rise followed by a fall gives
    ``status="not_unimodal"`` (``x`` is still the point the search ended at; ``info`` holds the
    best sampled point).  Returns ``x`` = interval midpoint; ``info["interval"]`` = final [a, b].
    If ``f`` was NaN somewhere the status is ``"nan"`` and ``x``, ``fun`` the best finite sample;
    an ``f`` that is never finite raises :class:`~anthroarm.errors.ObjectiveError`.  ``eps`` must
    be finite and > 0, ``n`` an integer >= 1, ``scan`` an integer >= 0 (``ValueError``)."""
    a, b = finite_interval(a, b)
    eps = positive("eps", eps)
    scan = count("scan", scan, minimum=0)
    if n is not None:
        n = count("n", n)
    f = Counted(f)
    n_pts = golden_points_needed(a, b, eps) if n is None else n
    if n_pts < 2:
        n_pts = 2
    xs, fs = [], []

    def ev(x):
        v = f(x)
        xs.append(x)
        fs.append(v)
        return v

    lo, hi = a, b
    x1, x2 = hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo)
    f1, f2 = ev(x1), ev(x2)
    k = 2
    hist = []
    while True:
        if f2 > f1:  # drop the right part (4-14)
            hi = x2
            x2, f2 = x1, f1
            new = "x1"
        else:  # drop the left part
            lo = x1
            x1, f1 = x2, f2
            new = "x2"
        hist.append((lo, hi))
        if k >= n_pts or hi - lo <= eps:
            break
        if new == "x1":
            x1 = hi - GOLDEN * (hi - lo)  # = a1 + 0.382 (b1 - a1)
            f1 = ev(x1)
        else:
            x2 = lo + GOLDEN * (hi - lo)
            f2 = ev(x2)
        k += 1
    xm = 0.5 * (lo + hi)
    fm = ev(xm)
    if scan > 0:
        for xx in np.linspace(a, b, scan):
            ev(float(xx))
    info = {"interval": (lo, hi), "n_points": k, "n_needed": n_pts}
    ib = int(np.argmin(fs))
    info["best_sampled"] = (xs[ib], fs[ib])
    if f.best is None:
        raise f.never_finite()
    if f.saw_nan:
        return f.result(
            xm,
            np.inf,
            "nan",
            "the objective returned NaN (x, fun: the best finite sample)",
            k,
            f.n,
            hist,
            info,
        )
    bad = unimodality_violation(xs, fs)
    if bad is not None:
        return f.result(
            xm,
            fm,
            "not_unimodal",
            f"f is not unimodal on [{a:g}, {b:g}]: a second valley near x = {bad:.6g}; "
            "narrow the interval (best sampled point in info['best_sampled'])",
            k,
            f.n,
            hist,
            info,
        )
    status = "converged" if hi - lo <= eps else "n_points"
    return f.result(
        xm, fm, status, f"interval [{lo:.6g}, {hi:.6g}] after {k} points", k, f.n, hist, info
    )


def bracket_minimum(f, x0: float = 0.0, h: float = 1e-2, grow: float = 2.0, maxiter: int = 60):
    """Advance-retreat bracketing (进退法, used before a line search): returns
    ``(a1, a2, a3, f1, f2, f3)`` with a1 < a2 < a3 and f2 ≤ f1, f2 ≤ f3, or None if the function
    keeps decreasing for ``maxiter`` steps (unbounded direction).  NaN values count as ``inf``;
    an ``f`` that is not finite at the bracketed point raises
    :class:`~anthroarm.errors.ObjectiveError`.  ``h`` must be finite and > 0, ``grow`` > 1,
    ``maxiter`` an integer >= 1, the points visited finite (``ValueError``)."""
    h = positive("initial step h", h)
    grow = positive("grow", grow)
    if not grow > 1:
        raise ValueError(f"grow must be > 1, got {grow!r}")
    maxiter = count("maxiter", maxiter)
    x0 = float(x0)
    if not math.isfinite(x0):
        raise ValueError(f"x0 must be finite, got {x0!r}")
    f_user = f

    def f(x):
        if not math.isfinite(x):
            raise ValueError(
                f"bracket_minimum stepped beyond the float range from x0 = {x0!r} (h = {h!r})"
            )
        v = float(f_user(x))
        return math.inf if math.isnan(v) else v

    def checked(a1, a2, a3, f1, f2, f3):
        if not math.isfinite(f2):
            raise ObjectiveError(
                f"the objective is not finite at the bracketed point: f({a2!r}) = {f2}", a2, f2
            )
        return (a1, a2, a3, f1, f2, f3)

    xa, fa = x0, f(x0)
    xb, fb = x0 + h, f(x0 + h)
    if fb > fa:  # retreat: search the other way
        h = -h
        xb, fb = x0 + h, f(x0 + h)
        if fb > fa:  # x0 is already bracketed
            return checked(x0 + h, x0, x0 - h, fb, fa, f(x0 - h))  # h < 0 here
    for _ in range(maxiter):
        h *= grow
        xc, fc = xb + h, f(xb + h)
        if fc >= fb:
            pts = sorted([(xa, fa), (xb, fb), (xc, fc)])
            return checked(pts[0][0], pts[1][0], pts[2][0], pts[0][1], pts[1][1], pts[2][1])
        xa, fa, xb, fb = xb, fb, xc, fc
    return None
