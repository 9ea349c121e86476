"""Ch. 4 optimisers: golden section (4-9)-(4-14), quadratic interpolation (4-15)-(4-25),
Fletcher-Reeves (4-26)-(4-47), the book's simplex (4-48)-(4-64), SUMT (4-65)-(4-78), the §4-3
constrained example; cross-checked against scipy.optimize."""

import numpy as np
import pytest
import scipy.optimize as so
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.design import optimize as O
from anthroarm.errors import ObjectiveError

# ----------------------------------------------------------------------------- golden section


def test_golden_ratio_4_12():
    assert O.GOLDEN == pytest.approx(0.618034, abs=1e-6)
    assert O.GOLDEN**2 + O.GOLDEN - 1 == pytest.approx(0, abs=1e-15)
    assert 1 - O.GOLDEN == pytest.approx(0.382, abs=1e-3)


@pytest.mark.parametrize("eps,n", [(0.1, 6), (0.01, 11), (0.001, 16)])
def test_golden_points_4_13(eps, n):
    assert O.golden_points_needed(0, 1, eps) == n
    assert O.GOLDEN ** (n - 1) <= eps < O.GOLDEN ** (n - 2)


def test_golden_interval_shrinks_by_lambda_per_point():
    r = O.golden_section(lambda x: (x - 0.3) ** 2, 0.0, 1.0, n=8, scan=0)
    lo, hi = r.info["interval"]
    assert r.status == "n_points" and r.nit == 8
    assert hi - lo == pytest.approx(O.GOLDEN**7, rel=1e-9)
    assert lo <= 0.3 <= hi


@pytest.mark.parametrize(
    "f,a,b",
    [
        (lambda x: (x - 0.3) ** 2, 0, 1),
        (lambda x: np.cosh(x - 1.3) + 0.1 * x, -2, 4),
        (lambda x: abs(x - 2.2), 0, 3),
        (lambda x: -np.sin(x), 0, 3),
    ],
)
def test_golden_matches_scipy(f, a, b):
    r = O.golden_section(f, a, b, eps=1e-9)
    assert r.success
    ref = so.minimize_scalar(f, bounds=(a, b), method="bounded", options={"xatol": 1e-10}).x
    assert r.x == pytest.approx(ref, abs=1e-6)
    if a + 1e-6 < ref < b - 1e-6:  # scipy's own golden section, given a 3-point bracket
        assert r.x == pytest.approx(so.golden(f, brack=(a, ref, b), tol=1e-10), abs=1e-6)


def test_golden_not_unimodal_says_so():
    r = O.golden_section(lambda x: np.sin(10 * x), 0, 3, eps=1e-6)
    assert r.status == "not_unimodal" and not r.success
    assert "not unimodal" in r.message
    # a function that the golden points alone would not expose, caught by the scan
    r2 = O.golden_section(lambda x: min((x - 0.1) ** 2, (x - 0.9) ** 2 + 0.001), 0, 1, eps=1e-6)
    assert r2.status == "not_unimodal"


def test_golden_bad_input():
    with pytest.raises(ValueError, match="a < b"):
        O.golden_section(lambda x: x, 1, 0)
    with pytest.raises(ValueError, match="finite"):
        O.golden_section(lambda x: x, 0, np.inf)
    with pytest.raises(ValueError, match="eps"):
        O.golden_points_needed(0, 1, -1)
    with pytest.raises(ObjectiveError, match="never returned a finite value"):
        O.golden_section(lambda x: np.nan, 0, 1)
    for kw in ({"eps": 0.0}, {"eps": -1e-6}, {"eps": np.nan}, {"n": 0}, {"n": -1}, {"scan": -1}):
        with pytest.raises(ValueError, match=next(iter(kw))):
            O.golden_section(lambda x: x * x, 0, 1, **kw)
    with pytest.raises(ValueError, match="within"):
        O.golden_section(lambda x: x * x, -1e308, 1)
    # a partly-NaN objective: status "nan", the best finite sample
    r = O.golden_section(lambda x: np.nan if x > 0.5 else (x - 0.3) ** 2, 0, 1)
    assert r.status == "nan" and not r.success
    assert np.isfinite(r.fun) and 0 <= r.x <= 0.5 and r.fun == pytest.approx((r.x - 0.3) ** 2)


# ----------------------------------------------------------------------------- quadratic
# interpolation


def printed_4_18(a1, a2, a3, f1, f2, f3):
    """(4-18) as printed (l. 1530): numerator cyclically shifted."""
    num = (a3**2 - a1**2) * f1 + (a1**2 - a2**2) * f2 + (a2**2 - a3**2) * f3
    den = (a2 - a3) * f1 + (a3 - a1) * f2 + (a1 - a2) * f3
    return 0.5 * num / den


def test_quadratic_4_20_exact_and_printed_4_18_wrong():
    q = lambda a: 2 * (a - 0.9) ** 2 + 1  # noqa: E731
    pts = (0.3, 1.1, 2.0)
    fs = tuple(q(a) for a in pts)
    assert O.quadratic_step(*pts, *fs) == pytest.approx(0.9, abs=1e-14)
    assert printed_4_18(*pts, *fs) == pytest.approx(0.8223, abs=1e-4)
    assert abs(printed_4_18(*pts, *fs) - 0.9) > 0.05
    A, B, C = O.quadratic_coefficients(*pts, *fs)
    assert -B / (2 * C) == pytest.approx(0.9)  # (4-17)
    for a, fa in zip(pts, fs):
        assert A + B * a + C * a * a == pytest.approx(fa)


@settings(max_examples=50, deadline=None)
@given(
    st.floats(-5, 5),
    st.floats(0.1, 10),
    st.floats(-3, 3),
    st.floats(0.05, 2),
    st.floats(0.05, 2),
    st.floats(-5, 5),
)
def test_quadratic_step_exact_on_parabolas(xm, c, a1, d1, d2, f0):
    q = lambda a: c * (a - xm) ** 2 + f0  # noqa: E731
    a2, a3 = a1 + d1, a1 + d1 + d2
    assert O.quadratic_step(a1, a2, a3, q(a1), q(a2), q(a3)) == pytest.approx(
        xm, abs=1e-7 * (1 + abs(xm)) / min(1, c)
    )
    h = d1
    if q(0) + q(2 * h) > 2 * q(h):
        # (4-23) equal spacing = (4-20) = (4-25)
        assert O.quadratic_step_equal(h, q(0), q(h), q(2 * h)) == pytest.approx(
            O.quadratic_step(0, h, 2 * h, q(0), q(h), q(2 * h)), rel=1e-9, abs=1e-9
        )


def test_quadratic_bad_input():
    with pytest.raises(ValueError, match="no minimum"):
        O.quadratic_step(0, 1, 2, 0, 1, 0)
    with pytest.raises(ValueError, match="distinct"):
        O.quadratic_step(0, 0, 2, 1, 1, 1)
    with pytest.raises(ValueError, match="4-24"):
        O.quadratic_step_equal(1, 0, 1, 0)
    r = O.quadratic_interpolation(lambda x: -x, (0, 1))
    assert r.status == "no_minimum"


@pytest.mark.parametrize(
    "f,br",
    [
        (lambda x: np.cosh(x - 1.3), (0, 3)),
        (lambda x: x**4 - 3 * x + 1, (0, 2)),
        (lambda x: np.exp(x) - 2 * x, (-1, 3)),
    ],
)
def test_quadratic_interpolation_matches_brent(f, br):
    r = O.quadratic_interpolation(f, br, eps=1e-12)
    assert r.success
    ref = so.minimize_scalar(f, bracket=br, method="brent", tol=1e-12).x
    assert r.x == pytest.approx(ref, abs=1e-6)


# ----------------------------------------------------------------------------- Fletcher-Reeves


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**31 - 1))
def test_fr_quadratic_termination_and_conjugacy(n, seed):
    rng = np.random.default_rng(seed)
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    A = Q @ np.diag(rng.uniform(0.5, 5, n)) @ Q.T
    b = rng.normal(size=n)
    r = O.fletcher_reeves(
        lambda x: 0.5 * x @ A @ x - b @ x, np.zeros(n), grad=lambda x: A @ x - b, gtol=1e-7
    )
    assert r.success and r.nit <= n  # at most n steps on an SPD quadratic
    np.testing.assert_allclose(r.x, np.linalg.solve(A, b), atol=1e-7)
    G = [A @ x - b for x in r.history]
    P = np.diff(np.array(r.history), axis=0)  # steps h P^(i)
    for i in range(len(P)):
        for j in range(i):
            assert abs(G[i] @ G[j]) < 1e-6 * (1 + np.linalg.norm(G[i]) * np.linalg.norm(G[j]))
            assert abs(P[i] @ A @ P[j]) < 1e-6 * (
                1 + np.linalg.norm(P[i]) * np.linalg.norm(P[j])
            )  # (4-26)


def test_fr_rosenbrock_vs_scipy():
    ros, jac = so.rosen, so.rosen_der
    x0 = np.array([-1.2, 1.0])
    r = O.fletcher_reeves(ros, x0, grad=jac, gtol=1e-10)
    assert r.success
    np.testing.assert_allclose(
        r.x, so.minimize(ros, x0, jac=jac, method="CG", tol=1e-12).x, atol=1e-5
    )
    r_fd = O.fletcher_reeves(ros, x0)  # numerical gradient
    np.testing.assert_allclose(r_fd.x, [1, 1], atol=1e-4)
    sd = O.steepest_descent(ros, x0, grad=jac, maxiter=200)
    assert sd.status == "maxiter" and r.nit < 200  # the book's point: SD crawls near the optimum
    assert O.fletcher_reeves(lambda x: -x @ x, [1.0, 0.0]).status == "no_minimum"


# ----------------------------------------------------------------------------- simplex


@pytest.mark.parametrize(
    "f,x0",
    [
        (so.rosen, [-1.2, 1.0]),
        (lambda x: (x[0] - 1) ** 2 + 10 * (x[1] + 2) ** 2 + x[2] ** 2, [3.0, 3.0, 3.0]),
        (lambda x: (x[0] ** 2 + x[1] - 11) ** 2 + (x[0] + x[1] ** 2 - 7) ** 2, [2.5, 2.5]),
    ],
)
def test_simplex_book_vs_scipy_nelder_mead(f, x0):
    r = O.simplex_book(f, x0, step=0.5, eps1=0.0, xtol=1e-11, maxiter=20000)
    ref = so.minimize(
        f, x0, method="Nelder-Mead", options={"xatol": 1e-11, "fatol": 1e-14, "maxiter": 20000}
    )
    assert r.success
    np.testing.assert_allclose(r.x, ref.x, atol=1e-6)


def test_simplex_variants_and_bad_input():
    for lam, mu, e in [(0.75, 1.5, "G"), (0.25, 2.0, "L"), (0.3, 1.2, "G")]:
        r = O.simplex_book(
            so.rosen,
            [-1.2, 1.0],
            step=0.5,
            lam=lam,
            mu=mu,
            expand_if=e,
            eps1=0,
            xtol=1e-10,
            maxiter=20000,
        )
        np.testing.assert_allclose(r.x, [1, 1], atol=1e-5)
    r = O.simplex_book(
        lambda x: (x @ x - 4) ** 2 + 1, [3.0, 0.0], eps1=0.0, eps2=1e-8
    )  # (4-64) stop
    assert r.success and "4-64" in r.message
    assert np.linalg.norm(r.x) == pytest.approx(2.0, abs=1e-3)
    with pytest.raises(ValueError, match="0.5"):
        O.simplex_book(so.rosen, [0, 0], lam=0.5)
    with pytest.raises(ValueError, match="> 1"):
        O.simplex_book(so.rosen, [0, 0], mu=0.9)
    with pytest.raises(ValueError, match="linearly dependent"):
        O.simplex_book(so.rosen, None, initial_simplex=[[0, 0], [1, 1], [2, 2]])
    with pytest.raises(ValueError, match="NaN"):
        O.simplex_book(so.rosen, [np.nan, 0])
    assert O.simplex_book(lambda x: 1.0, [0, 0], maxiter=5, eps1=0).status == "maxiter"


# ----------------------------------------------------------------------------- SUMT and the §4-3
# example

F43 = lambda x: x[0] ** 2 + x[1] ** 2 - 4 * x[0] + 4  # noqa: E731
G43 = lambda x: np.array([x[0] - x[1] + 2, -(x[0] ** 2) + x[1] - 1, x[0], x[1]])  # noqa: E731  (g >= 0)
BOOK_X, BOOK_F = np.array([0.58, 1.34]), 3.80
TRUE_X, TRUE_F = np.array([0.5536, 1.3064]), 3.7989
TRUE_X_PRECISE = np.array(
    [0.5535737822, 1.3064439324]
)  # KKT tangency, see test_section_4_3_true_optimum_is_tangency


def _slsqp(f, g, x0, eq=None):
    cons = [{"type": "ineq", "fun": g}] + ([{"type": "eq", "fun": eq}] if eq else [])
    return so.minimize(
        f, x0, method="SLSQP", constraints=cons, options={"ftol": 1e-14, "maxiter": 500}
    )


@pytest.mark.parametrize("method", ["interior", "exterior", "mixed"])
def test_section_4_3_constrained_example(method):
    fn = {"interior": O.sumt_interior, "exterior": O.sumt_exterior, "mixed": O.sumt_mixed}[method]
    r = fn(F43, [0.5, 2.0], G43)
    assert r.success, r.message
    # the book's printed optimum (l. 1350).  It is read off the contour plot: the true optimum is
    # 0.034 away in x2 (1.3064 vs 1.34), so the tolerance on x is 0.04 (0.03 would reject the truth)
    assert np.max(np.abs(r.x - BOOK_X)) <= 0.04 and abs(r.fun - BOOK_F) <= 0.015
    assert np.max(np.abs(TRUE_X - BOOK_X)) > 0.03
    # the true optimum (SLSQP, and the analytic tangency of the circle and the parabola)
    ref = _slsqp(F43, G43, [0.5, 2.0])
    np.testing.assert_allclose(ref.x, TRUE_X, atol=1e-4)
    assert ref.fun == pytest.approx(TRUE_F, abs=1e-4)
    np.testing.assert_allclose(r.x, TRUE_X_PRECISE, atol=1e-4)
    np.testing.assert_allclose(r.x, ref.x, atol=2e-4)
    assert r.fun == pytest.approx(ref.fun, abs=1e-4)
    assert np.all(G43(r.x) >= -1e-5)


def test_section_4_3_true_optimum_is_tangency():
    # at the optimum grad F is parallel to grad g2 and g2 = 0: solve by scipy root (mathematics)
    def eqs(z):
        x, y, mu = z
        return [2 * x - 4 + 2 * mu * x, 2 * y - mu, -(x**2) + y - 1]  # grad F = mu grad g2, g2 = 0

    x, y, mu = so.fsolve(eqs, [0.5, 1.3, 2.0])
    assert (x, y) == pytest.approx(tuple(TRUE_X), abs=1e-4) and mu > 0
    assert F43([0.58, 1.34]) == pytest.approx(3.812, abs=1e-3)  # the printed point is not optimal
    assert -(0.58**2) + 1.34 - 1 == pytest.approx(0.0036, abs=1e-4)  # but lies on the parabola


def test_section_4_3_printed_linear_g2_does_not_give_book_answer():
    # OCR/print has g2 = -x1 + x2 - 1 >= 0 (l. 1330); with it the optimum is (0.5, 1.5), F = 4.5
    g_lin = lambda x: np.array([x[0] - x[1] + 2, -x[0] + x[1] - 1, x[0], x[1]])  # noqa: E731
    r = O.sumt_exterior(F43, [0.5, 2.0], g_lin)
    np.testing.assert_allclose(r.x, [0.5, 1.5], atol=1e-3)
    assert r.fun == pytest.approx(4.5, abs=1e-3)
    assert abs(r.fun - BOOK_F) > 0.5


def test_unconstrained_optimum_of_4_3():
    for r in (
        O.simplex_book(F43, [0.5, 2.0], eps1=0, xtol=1e-10),
        O.fletcher_reeves(F43, [0.5, 2.0]),
    ):
        np.testing.assert_allclose(r.x, [2, 0], atol=1e-6)
        assert r.fun == pytest.approx(0, abs=1e-10)


def test_equality_constraints_exterior_and_mixed_vs_slsqp():
    f = lambda x: (x[0] - 2) ** 2 + (x[1] - 1) ** 2  # noqa: E731
    h = lambda x: np.array([x[0] + x[1] - 1])  # noqa: E731
    g = lambda x: np.array([x[1] + 0.5])  # noqa: E731
    ref = _slsqp(f, g, [0.0, 0.0], eq=h)
    np.testing.assert_allclose(ref.x, [1, 0], atol=1e-8)
    re = O.sumt_exterior(f, [0.0, 0.0], ineq=g, eq=h)
    rm = O.sumt_mixed(f, [0.0, 0.0], ineq=g, eq=h, max_stages=30)
    for r in (re, rm):
        np.testing.assert_allclose(r.x, ref.x, atol=2e-3)


def test_nan_objective_is_a_status():
    nan = lambda x: np.nan  # noqa: E731
    inf = lambda x: np.inf  # noqa: E731
    g = lambda x: np.array([x[0]])  # noqa: E731
    # an objective that is never finite has no best point: a typed error carrying x and the value
    for bad in (nan, inf):
        for call in (
            lambda: O.quadratic_interpolation(bad, (0, 1)),
            lambda: O.quadratic_interpolation(bad, (0, 0.5, 1)),
            lambda: O.fletcher_reeves(bad, [1.0, 0.0]),
            lambda: O.steepest_descent(bad, [1.0]),
            lambda: O.simplex_book(bad, [1.0, 0.0]),
            lambda: O.sumt_exterior(bad, [1.0], g),
            lambda: O.sumt_interior(bad, [1.0], g),
            lambda: O.sumt_mixed(bad, [1.0], g),
            lambda: O.bracket_minimum(bad, 0.0),
            lambda: O.line_minimize(bad),
        ):
            with pytest.raises(ObjectiveError) as e:
                call()
            assert isinstance(e.value, ValueError) and not np.isfinite(e.value.value)
    # a constraint that is NaN everywhere makes the penalty function NaN everywhere
    with pytest.raises(ObjectiveError):
        O.sumt_exterior(lambda x: x @ x, [1.0], lambda x: np.array([np.nan]))
    # partly NaN: status "nan" with the best point where f was finite
    part = lambda x: (
        np.nan if np.atleast_1d(x)[0] > 1.5 else float(np.sum((np.atleast_1d(x) - 1.0) ** 2))
    )  # noqa: E731
    r = O.quadratic_interpolation(part, (0.0, 1.0, 3.0))
    assert r.status == "nan" and not r.success, r
    assert np.isfinite(r.x) and r.fun == part(r.x) and r.x <= 1.5
    # the simplex treats NaN like inf (a point to move away from) and still converges
    r = O.simplex_book(part, [1.2, 0.0], step=1.0)
    assert (
        r.success
        and r.fun == pytest.approx(part(r.x))
        and np.all(np.isfinite(r.x))
        and r.x[0] <= 1.5
    )


def test_optimiser_arguments_are_checked():
    q = lambda x: float(np.sum((np.atleast_1d(x) - 1.0) ** 2))  # noqa: E731
    for bad in (0.0, -1e-6, np.nan, np.inf):
        for call in (
            lambda: O.quadratic_interpolation(q, (0, 1, 2), eps=bad),
            lambda: O.fletcher_reeves(q, [0.5], gtol=bad),
            lambda: O.sumt_exterior(q, [0.5], eps1=bad),
            lambda: O.sumt_exterior(q, [0.5], c=bad),
            lambda: O.sumt_interior(q, [0.5], lambda x: 2 - x, r0=bad),
            lambda: O.numerical_gradient(q, [0.5], h=bad),
            lambda: O.bracket_minimum(q, 0.0, h=bad),
            lambda: O.line_minimize(q, h0=bad),
        ):
            with pytest.raises(ValueError):
                call()
    for bad in (-1e-6, np.nan, np.inf):  # eps1 = 0 switches (4-63) off
        with pytest.raises(ValueError, match="eps1"):
            O.simplex_book(q, [0.5], eps1=bad)
    for n in (0, -1):
        for call in (
            lambda: O.quadratic_interpolation(q, (0, 1, 2), maxiter=n),
            lambda: O.fletcher_reeves(q, [0.5], maxiter=n),
            lambda: O.steepest_descent(q, [0.5], maxiter=n),
            lambda: O.simplex_book(q, [0.5], maxiter=n),
            lambda: O.bracket_minimum(q, 0.0, maxiter=n),
            lambda: O.sumt_exterior(q, [0.5], max_stages=n),
        ):
            with pytest.raises(ValueError, match="maxiter|max_stages"):
                call()
    with pytest.raises(TypeError, match="integer"):
        O.simplex_book(q, [0.5], maxiter=2.5)
    for call in (
        lambda: O.fletcher_reeves(q, [1e308, 0.5]),
        lambda: O.simplex_book(q, [1e308]),
        lambda: O.simplex_book(q, [0.5], step=1e308),
    ):
        with pytest.raises(ValueError, match="x0|step"):
            call()


def test_infeasible_problems_say_so():
    f = lambda x: x[0] ** 2  # noqa: E731
    g = lambda x: np.array([x[0] - 1, -x[0]])  # x >= 1 and x <= 0  # noqa: E731
    assert O.sumt_exterior(f, [0.5], g).status == "infeasible"
    ri = O.sumt_interior(f, [0.5], g)
    assert ri.status == "infeasible" and not ri.success
    assert O.sumt_mixed(f, [0.5], g).status == "infeasible"
    rb = O.sumt_interior(f, [0.5], None, bounds=[(2.0, 1.0)])
    assert rb.status == "infeasible_bounds" and "bound 0" in rb.message
    assert rb.fun == f([0.5])  # the value at x0, finite
    for bad in (np.nan, -1e308, 1e308):
        with pytest.raises(ValueError, match="bound 0"):
            O.sumt_exterior(f, [0.5], bounds=[(0.0, bad)])
    assert O.sumt_exterior(f, [0.5], bounds=[(0.0, -np.inf)]).status == "infeasible_bounds"
    with pytest.raises(ValueError, match="entries"):
        O.sumt_exterior(f, [0.5], bounds=[(0, 1), (0, 1)])


def test_interior_starts_from_infeasible_point_via_phase1():
    r = O.sumt_interior(F43, [3.0, -1.0], G43)
    assert r.success
    np.testing.assert_allclose(r.x, TRUE_X, atol=1.5e-3)


def test_bounds_vs_scipy_bounded():
    f = lambda x: (x[0] - 3) ** 2 + (x[1] + 1) ** 2 + x[0] * x[1]  # noqa: E731
    bnds = [(0, 2), (-0.5, 1)]
    ref = so.minimize(f, [1, 0], method="L-BFGS-B", bounds=bnds)
    for fn in (O.sumt_interior, O.sumt_exterior):
        r = fn(f, [1.0, 0.0], None, bounds=bnds)
        np.testing.assert_allclose(r.x, ref.x, atol=2e-3)
