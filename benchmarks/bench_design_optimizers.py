"""Ch. 4 optimisers as the book writes them vs scipy.optimize: evaluations, time, error."""

from __future__ import annotations

import numpy as np
import scipy.optimize as so

from anthroarm.design import optimize as O

from .common import time_call

F43 = lambda x: x[0] ** 2 + x[1] ** 2 - 4 * x[0] + 4  # noqa: E731
G43 = lambda x: np.array([x[0] - x[1] + 2, -(x[0] ** 2) + x[1] - 1, x[0], x[1]])  # noqa: E731
X43 = np.array([0.5535737822, 1.3064439324])  # true optimum: KKT tangency solved by fsolve


def _cases():
    f1 = lambda x: np.cosh(x - 1.3) + 0.1 * x  # noqa: E731
    x1 = so.minimize_scalar(f1, bounds=(-2, 4), method="bounded", options={"xatol": 1e-12}).x
    x0 = np.array([-1.2, 1.0])
    return [
        (
            "1-D cosh",
            "golden_section (book, n from (4-13))",
            lambda: O.golden_section(f1, -2, 4, 1e-8, scan=0),
            x1,
        ),
        (
            "1-D cosh",
            "scipy golden",
            lambda: so.golden(f1, brack=(-2, x1, 4), tol=1e-8, full_output=True),
            x1,
        ),
        (
            "1-D cosh",
            "quadratic_interpolation (4-20)",
            lambda: O.quadratic_interpolation(f1, (-2, 4), 1e-10),
            x1,
        ),
        (
            "1-D cosh",
            "scipy brent",
            lambda: so.minimize_scalar(f1, bracket=(-2, 4), method="brent"),
            x1,
        ),
        (
            "Rosenbrock",
            "fletcher_reeves (book)",
            lambda: O.fletcher_reeves(so.rosen, x0, grad=so.rosen_der, gtol=1e-10),
            np.ones(2),
        ),
        (
            "Rosenbrock",
            "scipy CG (Polak-Ribiere)",
            lambda: so.minimize(so.rosen, x0, jac=so.rosen_der, method="CG", tol=1e-12),
            np.ones(2),
        ),
        (
            "Rosenbrock",
            "simplex_book",
            lambda: O.simplex_book(so.rosen, x0, step=0.5, eps1=0, xtol=1e-10),
            np.ones(2),
        ),
        (
            "Rosenbrock",
            "scipy Nelder-Mead",
            lambda: so.minimize(
                so.rosen, x0, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-14}
            ),
            np.ones(2),
        ),
        (
            "§4-3 example",
            "sumt_interior (book)",
            lambda: O.sumt_interior(F43, [0.5, 2.0], G43),
            X43,
        ),
        (
            "§4-3 example",
            "sumt_exterior (book)",
            lambda: O.sumt_exterior(F43, [0.5, 2.0], G43),
            X43,
        ),
        ("§4-3 example", "sumt_mixed (book)", lambda: O.sumt_mixed(F43, [0.5, 2.0], G43), X43),
        (
            "§4-3 example",
            "scipy SLSQP",
            lambda: so.minimize(
                F43, [0.5, 2.0], method="SLSQP", constraints=[{"type": "ineq", "fun": G43}]
            ),
            X43,
        ),
        (
            "§4-3 example",
            "scipy trust-constr",
            lambda: so.minimize(
                F43,
                [0.5, 2.0],
                method="trust-constr",
                constraints=[so.NonlinearConstraint(G43, 0, np.inf)],
            ),
            X43,
        ),
    ]


def _x_nfev(r):
    if isinstance(r, tuple):  # scipy golden full_output
        return np.atleast_1d(r[0]), r[2]
    return np.atleast_1d(np.asarray(r.x, dtype=float)), int(getattr(r, "nfev", 0))


def run(quick: bool = False) -> dict:
    rows = []
    for problem, method, fn, xref in _cases():
        x, nfev = _x_nfev(fn())
        t = time_call(fn, repeat=3 if quick else 7)
        rows.append(
            [problem, method, nfev, float(np.max(np.abs(x - np.atleast_1d(xref)))), t * 1e3]
        )
    return dict(
        title="Ch. 4 optimisers vs scipy.optimize",
        columns=["problem", "method", "nfev", "max |x - x*|", "time (ms)"],
        rows=rows,
        notes=(
            "Same starting points and tolerances as the tests. The book's methods are plain Python "
            "(no compiled inner loops); the SUMT methods use the book's simplex inside, one "
            "unconstrained minimisation per penalty stage."
        ),
    )
