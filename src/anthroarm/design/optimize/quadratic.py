"""Quadratic (parabolic) interpolation (二次插值法), book §4-4, Eq. (4-15)–(4-25).

Fit ``p(α) = A + Bα + Cα²`` (4-15) through three points a1 < a2 < a3 and step to its vertex
``α* = −B/2C`` (4-17), a minimum when C > 0 (4-19).  The book's closed form (4-18) has its
numerator shifted cyclically (docs/errata.md); the convenient form (4-20) is right:

    α* = ½ (a1 + a3 − k1/k2),  k1 = (f3 − f1)/(a3 − a1),  k2 = ((f2 − f1)/(a2 − a1) − k1)/(a2 − a3)

(k2 is C).  Equal spacing a1 = 0, a2 = h, a3 = 2h gives (4-23)
``α* = (4f2 − 3f1 − f3)/(4f2 − 2f3 − 2f1)·h``, valid when f1 + f3 > 2f2 (4-24).
"""

from __future__ import annotations

import math

import numpy as np

from .golden import bracket_minimum
from .result import Counted, OptimizeResult, count, positive


def quadratic_coefficients(a1, a2, a3, f1, f2, f3):
    """``(A, B, C)`` of the interpolating parabola (4-15)/(4-16), D = (a1−a2)(a2−a3)(a3−a1)."""
    D = (a1 - a2) * (a2 - a3) * (a3 - a1)
    if D == 0:
        raise ValueError(f"interpolation points must be distinct, got {a1}, {a2}, {a3}")
    B = ((a2**2 - a3**2) * f1 + (a3**2 - a1**2) * f2 + (a1**2 - a2**2) * f3) / D
    C = -((a2 - a3) * f1 + (a3 - a1) * f2 + (a1 - a2) * f3) / D
    A = f1 - B * a1 - C * a1**2
    return A, B, C


def quadratic_step(a1, a2, a3, f1, f2, f3) -> float:
    """Vertex of the parabola through the three points, Eq. (4-20) (= corrected (4-18)).
    Raises ``ValueError`` if the points coincide or the parabola opens downward (k2 ≤ 0, no
    minimum, (4-19))."""
    if len({a1, a2, a3}) < 3:
        raise ValueError(f"interpolation points must be distinct, got {a1}, {a2}, {a3}")
    k1 = (f3 - f1) / (a3 - a1)
    k2 = ((f2 - f1) / (a2 - a1) - k1) / (a2 - a3)
    if not k2 > 0:
        raise ValueError(
            f"the parabola through the points has no minimum (C = k2 = {k2:g} <= 0), (4-19)"
        )
    return 0.5 * (a1 + a3 - k1 / k2)


def quadratic_step_equal(h, f1, f2, f3) -> float:
    """Equal spacing 0, h, 2h: Eq. (4-23) ``α* = (4f2 − 3f1 − f3)/(4f2 − 2f3 − 2f1)·h``;
    requires (4-24) ``f1 + f3 > 2 f2``."""
    h = positive("trial step h", h)
    if not all(math.isfinite(v) for v in (f1, f2, f3)):
        raise ValueError(f"the three values must be finite, got {f1!r}, {f2!r}, {f3!r}")
    if not f1 + f3 > 2 * f2:
        raise ValueError("(4-24) f1 + f3 > 2 f2 fails: the three values have no parabolic minimum")
    a = (4 * f2 - 3 * f1 - f3) / (4 * f2 - 2 * f3 - 2 * f1) * h
    if not math.isfinite(a):
        raise ValueError(
            f"alpha* = ... * h is beyond the float range (h = {h!r}, values {f1!r}, {f2!r}, {f3!r})"
        )
    return a


def quadratic_interpolation(f, bracket, eps: float = 1e-8, maxiter: int = 100) -> OptimizeResult:
    """Minimise a 1-D ``f`` by repeated quadratic interpolation.

    ``bracket`` is ``(a1, a2, a3)`` with f(a2) below f(a1) and f(a3), or ``(a, b)``: then the
    midpoint is tried and, failing a bracket, the advance-retreat method (:func:`bracket_minimum`)
    searches from a.  Each step keeps the three points that bracket the lowest value (the book's
    flowchart Fig. 4-5 is missing; this is the standard rule) and stops when successive vertices
    differ by less than ``eps`` (relative to |α| + 1).  Status ``"no_minimum"`` when no bracket
    exists (monotone or concave data).  If ``f`` was NaN somewhere the status is ``"nan"`` with the
    best finite point; an ``f`` that is never finite
    raises :class:`~anthroarm.errors.ObjectiveError`. ``eps`` must be finite and > 0, ``maxiter`` an
    integer >= 1, the bracket finite (``ValueError``)."""
    eps = positive("eps", eps)
    maxiter = count("maxiter", maxiter)
    if any(not math.isfinite(float(v)) for v in bracket):
        raise ValueError(f"bracket must be finite, got {bracket}")
    f = Counted(f)
    if len(bracket) == 3:
        a1, a2, a3 = (float(v) for v in bracket)
        if not a1 < a2 < a3:
            raise ValueError(f"need a1 < a2 < a3, got {bracket}")
        f1, f2, f3 = f(a1), f(a2), f(a3)
    elif len(bracket) == 2:
        a, b = (float(v) for v in bracket)
        if not a < b:
            raise ValueError(f"need a < b, got {bracket}")
        a1, a2, a3 = a, 0.5 * (a + b), b
        f1, f2, f3 = f(a1), f(a2), f(a3)
        if not (f2 <= f1 and f2 <= f3):
            br = bracket_minimum(f, a, (b - a) / 10)
            if br is None:
                return f.result(
                    a1 if f1 < f3 else a3,
                    min(f1, f3),
                    "no_minimum",
                    "f keeps decreasing: no bracket of a minimum",
                    0,
                    f.n,
                )
            a1, a2, a3, f1, f2, f3 = br
    else:
        raise ValueError("bracket must be (a, b) or (a1, a2, a3)")
    if f.saw_nan:
        return f.result(
            a2, np.inf, "nan", "the objective returned NaN (x, fun: the best finite point)", 0, f.n
        )
    if not (f2 <= f1 and f2 <= f3):
        return f.result(a2, f2, "no_minimum", "the three points do not bracket a minimum", 0, f.n)
    prev = a2
    hist = [a2]
    for it in range(1, maxiter + 1):
        try:
            x = quadratic_step(a1, a2, a3, f1, f2, f3)
        except ValueError:  # flat / collinear values: the middle point is the answer
            return f.result(
                a2, f2, "converged", "the three values are equal: flat bracket", it, f.n, hist
            )
        if not a1 <= x <= a3:
            x = a2
        if x == a2:  # vertex on the middle point: nudge to keep three distinct points
            x = a2 + 1e-3 * ((a3 - a2) if a3 - a2 > a2 - a1 else (a1 - a2))
        fx = f(x)
        if x > a2:
            if fx <= f2:
                a1, f1, a2, f2 = a2, f2, x, fx
            else:
                a3, f3 = x, fx
        else:
            if fx <= f2:
                a3, f3, a2, f2 = a2, f2, x, fx
            else:
                a1, f1 = x, fx
        hist.append(a2)
        if f.saw_nan:
            return f.result(
                a2,
                np.inf,
                "nan",
                "the objective returned NaN (x, fun: the best finite point)",
                it,
                f.n,
                hist,
            )
        if abs(x - prev) < eps * (abs(x) + 1.0) or (a3 - a1) < eps * (abs(a2) + 1.0):
            return f.result(
                a2,
                f2,
                "converged",
                f"|alpha* - previous| < {eps:g}",
                it,
                f.n,
                hist,
                {"bracket": (a1, a2, a3)},
            )
        prev = x
    return f.result(
        a2,
        f2,
        "maxiter",
        f"no convergence in {maxiter} steps",
        maxiter,
        f.n,
        hist,
        {"bracket": (a1, a2, a3)},
    )


def line_minimize(phi, h0: float = 1e-2, eps: float = 1e-10):
    """1-D minimisation used by the multi-dimensional methods: advance-retreat bracket from 0,
    then quadratic interpolation (exact in one step on a quadratic).  Returns ``(h, phi(h))``,
    or ``(0, phi(0))`` when no decrease exists.  ``h0`` and ``eps`` must be finite and > 0."""
    h0 = positive("h0", h0)
    eps = positive("eps", eps)
    br = bracket_minimum(phi, 0.0, h0)
    if br is None:
        return math.nan, -math.inf
    r = quadratic_interpolation(phi, br[:3], eps=eps)
    if not math.isfinite(r.fun):
        return 0.0, phi(0.0)
    return float(r.x), float(r.fun)
