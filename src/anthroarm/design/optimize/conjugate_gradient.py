"""Fletcher–Reeves conjugate gradient (F-R 共轭梯度法) and steepest descent, book §4-4,
Eq. (4-26)–(4-47).

    P⁽⁰⁾ = −G⁽⁰⁾ (4-41),  X⁽ⁱ⁺¹⁾ = X⁽ⁱ⁾ + h⁽ⁱ⁾P⁽ⁱ⁾ with h⁽ⁱ⁾ = argmin_h f(X⁽ⁱ⁾ + hP⁽ⁱ⁾)
    (4-35)/(4-36), P⁽ⁱ⁺¹⁾ = −G⁽ⁱ⁺¹⁾ + β⁽ⁱ⁾P⁽ⁱ⁾ (4-46),  β⁽ⁱ⁾ = |G⁽ⁱ⁺¹⁾|² / |G⁽ⁱ⁾|² (4-45)/(4-47).

On a positive-definite quadratic with exact line searches it ends in at most n steps.  The
book does not mention restarts; we restart with −G every ``restart`` steps (default n) and
whenever P is not a descent direction — the usual practice for non-quadratic f.
``scipy.optimize.minimize(method="CG")`` is Polak–Ribière, not this method.
The line search is the book's own: advance-retreat bracket then quadratic interpolation.
"""

from __future__ import annotations

import numpy as np

from .quadratic import line_minimize
from .result import MAX_COORD, Counted, as_vector, count, positive


def numerical_gradient(f, x, h: float = 1e-6):
    """Central-difference gradient (used when no gradient is given): step ``h·max(1, |x_i|)``
    along axis i.  ``h`` must be finite and > 0 and ``x`` a finite vector whose steps stay
    finite (``ValueError``); a NaN/inf value of ``f`` gives a NaN/inf component."""
    h = positive("h", h)
    x = as_vector("x", x)
    g = np.empty_like(x)
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h * max(1.0, abs(x[i]))
        if not (np.isfinite(e[i]) and np.isfinite(x[i] + e[i]) and np.isfinite(x[i] - e[i])):
            raise ValueError(
                f"the difference step h*max(1, |x[{i}]|) = {h!r}*{abs(x[i])!r} leaves the float "
                "range"
            )
        with np.errstate(over="ignore", invalid="ignore"):
            g[i] = (f(x + e) - f(x - e)) / (2 * e[i])
    return g


def _run(f, grad, x0, gtol, maxiter, restart, fr: bool):
    x = as_vector("x0", x0, limit=MAX_COORD)
    gtol = positive("gtol", gtol)
    maxiter = count("maxiter", maxiter)
    if restart is not None:
        restart = count("restart", restart)
    fc = Counted(f)
    gr = (
        (lambda z: numerical_gradient(fc, z))
        if grad is None
        else (lambda z: as_vector("gradient", grad(z)))
    )
    n = x.size
    restart = n if restart is None else int(restart)
    fx = fc(x)
    g = gr(x)
    if fc.saw_nan or not np.all(np.isfinite(g)):
        return fc.result(
            x, fx, "nan", "the objective or its gradient is NaN/inf at x0", 0, fc.n, [x.copy()]
        )
    p = -g
    hist = [x.copy()]
    scale = max(1.0, float(np.linalg.norm(g)))
    since = 0
    for it in range(1, maxiter + 1):
        if np.linalg.norm(g) <= gtol * scale:
            return fc.result(x, fx, "converged", f"|grad| <= {gtol:g}", it - 1, fc.n, hist)
        if p @ g >= 0:  # not a descent direction: restart
            p = -g
        pn = np.linalg.norm(p)
        h, fnew = line_minimize(lambda t: fc(x + t * p), h0=1e-2 * max(1.0, np.linalg.norm(x)) / pn)
        if not np.isfinite(h):
            return fc.result(
                x, fx, "no_minimum", "f is unbounded below along a search direction", it, fc.n, hist
            )
        if fc.saw_nan:
            return fc.result(
                x,
                fx,
                "nan",
                "the objective returned NaN (x, fun: the best finite point)",
                it,
                fc.n,
                hist,
            )
        x_new = x + h * p
        g_new = gr(x_new)
        step = np.linalg.norm(x_new - x)
        x, fold, fx = x_new, fx, fnew
        hist.append(x.copy())
        since += 1
        if fr and since < restart:
            beta = (g_new @ g_new) / (g @ g)  # (4-47)
            p = -g_new + beta * p  # (4-46)
        else:
            p = -g_new
            since = 0
        g = g_new
        if step <= 1e-15 * (1 + np.linalg.norm(x)) and abs(fold - fx) <= 1e-15 * (1 + abs(fx)):
            return fc.result(
                x,
                fx,
                "converged",
                "no further progress along the search directions",
                it,
                fc.n,
                hist,
            )
    status = "converged" if np.linalg.norm(g) <= gtol * scale else "maxiter"
    return fc.result(x, fx, status, f"stopped after {maxiter} iterations", maxiter, fc.n, hist)


def fletcher_reeves(
    f, x0, grad=None, gtol: float = 1e-8, maxiter: int = 1000, restart: int | None = None
):
    """Minimise ``f`` from ``x0`` by Fletcher–Reeves conjugate gradients, Eq. (4-41)–(4-47).

    ``grad`` (optional) returns ∇f; otherwise central differences.  Stops when
    ``|G| ≤ gtol·max(1, |G⁽⁰⁾|)``.  ``history`` lists the iterates X⁽ⁱ⁾.  ``gtol`` must be finite
    and > 0, ``maxiter`` and ``restart`` integers >= 1, ``x0`` finite within ±1e150
    (``ValueError``); an ``f`` that is never finite
    raises :class:`~anthroarm.errors.ObjectiveError`."""
    return _run(f, grad, x0, gtol, maxiter, restart, fr=True)


def steepest_descent(f, x0, grad=None, gtol: float = 1e-8, maxiter: int = 10000):
    """Steepest descent with the same line search (book §4-4 prose, l. 1568–1570): fast far from
    the optimum, slow near it — the book's reason to switch to conjugate gradients."""
    return _run(f, grad, x0, gtol, maxiter, restart=1, fr=False)
