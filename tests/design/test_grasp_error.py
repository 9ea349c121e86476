"""§2-4 grasp error, Eq. (2-5)-(2-20): book case split vs brute force; (2-17) bracket erratum."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.design import grasp_error as G

D = np.deg2rad
L, TH, RMIN, RMAX = 100.0, D(60), 10.0, 30.0


def test_translational_zero():
    assert G.grasp_error_translational() == 0.0


@pytest.mark.parametrize(
    "a,beta_deg,case,delta",
    [
        # ch1-2 notes part 3, self-derived reference table (mathematics, re-checked by brute force
        # below)
        (0, 90, "same_side", 5.165593),
        (0, 80, "split", 1.503874),
        (20, 90, "same_side", 5.265391),
        (20, 80, "split", 1.535384),
    ],
)
def test_reference_table(a, beta_deg, case, delta):
    r = (
        G.grasp_error_single(L, TH, D(beta_deg), RMIN, RMAX)
        if a == 0
        else G.grasp_error_double(L, TH, D(beta_deg), a, RMIN, RMAX)
    )
    assert r.case == case
    assert r.delta == pytest.approx(delta, abs=2e-6)
    assert r.delta == pytest.approx(
        G.grasp_error_brute(L, TH, D(beta_deg), RMIN, RMAX, a=a or None), abs=1e-6
    )


def test_optimal_beta_2_12_centres_hyperbola():
    bc = G.optimal_beta_single(L, TH, RMIN, RMAX)
    assert np.rad2deg(bc) == pytest.approx(76.647574, abs=1e-6)
    r = G.grasp_error_single(L, TH, bc, RMIN, RMAX)
    assert r.r0 == pytest.approx(20.0)
    assert r.delta1 == pytest.approx(r.delta2)  # X(R_max) = X(R_min)
    assert r.delta == pytest.approx(0.682793, abs=1e-6)
    assert float(G.x_single(L, RMAX, TH, bc)) == pytest.approx(97.979590, abs=1e-6)
    assert r.x_min == pytest.approx(97.296797, abs=1e-6)
    # beta_c is where a single-pivot finger's error is smallest (brute-force scan)
    betas = np.linspace(D(40), D(90), 2001)
    errs = [G.grasp_error_single(L, TH, b, RMIN, RMAX).delta for b in betas]
    assert betas[int(np.argmin(errs))] == pytest.approx(bc, abs=D(0.05))


def test_too_short_finger_for_2_12():
    with pytest.raises(ValueError, match="lengthen"):
        G.optimal_beta_single(10.0, TH, 10, 30)


def test_two_sizes_2_20_zero_error():
    for a in (None, 15.0):
        b0 = G.beta_two_sizes(L, TH, 12.0, 27.0)
        xs = [
            G.x_single(L, r, TH, b0) if a is None else G.x_double(L, r, TH, b0, a)
            for r in (12.0, 27.0)
        ]
        assert xs[0] == pytest.approx(xs[1], abs=1e-12)


def test_hyperbolas_2_7_and_2_15():
    R = np.linspace(1, 60, 50)
    for beta in (D(50), D(80), D(95)):
        X = G.x_single(L, R, TH, beta)
        np.testing.assert_allclose(G.hyperbola_single_residual(L, R, X, TH, beta), 0, atol=1e-10)
        Xd = G.x_double(L, R, TH, beta, 30.0)
        np.testing.assert_allclose(
            G.hyperbola_double_residual(L, R, Xd, TH, beta, 30.0), 0, atol=1e-10
        )


@settings(max_examples=50, deadline=None)
@given(
    st.floats(30, 200),
    st.floats(10, 85),
    st.floats(20, 120),
    st.floats(1, 20),
    st.floats(1.2, 4),
    st.floats(0, 0.9),
)
def test_case_split_equals_max_minus_min(l, th_deg, beta_deg, rmin, ratio, afrac):
    th, beta, rmax = D(th_deg), D(beta_deg), rmin * ratio
    assert G.grasp_error_single(l, th, beta, rmin, rmax).delta == pytest.approx(
        G.grasp_error_brute(l, th, beta, rmin, rmax), rel=1e-6, abs=1e-6
    )
    a = afrac * l * abs(math.sin(beta))
    assert G.grasp_error_double(l, th, beta, a, rmin, rmax).delta == pytest.approx(
        G.grasp_error_brute(l, th, beta, rmin, rmax, a=a), rel=1e-6, abs=1e-6
    )


def printed_2_17(l, th, beta, a, rmin, rmax):
    """(2-17) as the OCR prints it (l. 781-783): the first sqrt closes after (R_max/sin th)^2 and
    the absolute value closes after the first line, so the remaining terms are added outside."""
    s = math.sin(th)
    first = math.sqrt(l**2 + (rmax / s) ** 2)
    inner = abs(first - 2 * l * (rmax / s) * math.cos(beta) - a**2)
    return inner - math.sqrt(l**2 + (rmin / s) ** 2 - 2 * l * (rmin / s) * math.cos(beta) - a**2)


def test_printed_2_17_bracket_is_wrong():
    beta, a = D(90), 20.0
    true = G.grasp_error_double(L, TH, beta, a, RMIN, RMAX)
    assert true.case == "same_side"
    assert true.delta == pytest.approx(G.grasp_error_brute(L, TH, beta, RMIN, RMAX, a=a), abs=1e-9)
    assert abs(printed_2_17(L, TH, beta, a, RMIN, RMAX) - true.delta) > 100


def test_bad_input():
    with pytest.raises(ValueError, match="R_min < R_max"):
        G.grasp_error_single(L, TH, D(80), 30, 10)
    with pytest.raises(ValueError, match="theta"):
        G.grasp_error_single(L, 0.0, D(80), 10, 30)
    with pytest.raises(ValueError, match="finite"):
        G.grasp_error_single(L, TH, float("nan"), 10, 30)
    with pytest.raises(ValueError, match="2-16"):
        G.grasp_error_double(L, TH, D(10), 50.0, 10, 30)
    with pytest.raises(ValueError, match="R must be finite"):
        G.x_single(L, [10.0, np.nan], TH, D(80))
    with pytest.raises(ValueError, match="l must be finite"):
        G.double_x_min(np.nan, TH, D(80), 5.0)


def test_plot_runs():
    import matplotlib

    matplotlib.use("Agg")
    ax = G.plot_grasp_error(L, TH, RMIN, RMAX)
    G.plot_grasp_error(L, TH, RMIN, RMAX, a=20.0, ax=ax)
    assert len(ax.lines) >= 2
