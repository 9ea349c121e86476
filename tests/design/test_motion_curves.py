"""Ch. 3 motion curves: printed coefficients, difference table, least squares (3-1)-(3-6), Fig.
3-9."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.design import motion_curves as M


def test_printed_curves_values():
    # coefficients as printed (l. 1077, 1081, 1089); values derived from them (ch3-4 notes E1-E3)
    f, g, f2, f3 = M.FINGERTIP_POWER_GRASP, M.FINGERTIP_PINCH, M.THUMB_F2, M.THUMB_F3
    assert f.coeffs == (55.61, 1.133, -1.707e-2, 0.22e-4)
    assert g.coeffs == (18.7688, 1.35, -0.0584)
    for x, v in [(0, 55.61), (10, 65.255), (20, 71.618), (30, 74.831), (40, 75.026)]:
        assert f(x) == pytest.approx(v, abs=1e-3)
    assert f.stationary_points() == pytest.approx([35.643, 481.6], abs=0.05)
    assert g(10) == pytest.approx(26.429, abs=1e-3) and g(20) == pytest.approx(22.409, abs=1e-3)
    assert g.stationary_points() == pytest.approx([11.558], abs=1e-3)
    assert f2(30) == pytest.approx(6.9247, abs=1e-4) and f2(60) == pytest.approx(19.8264, abs=1e-4)
    assert len(f2.stationary_points()) == 0  # monotone increasing
    assert f3(20) == pytest.approx(40.3547, abs=1e-4) and f3(30) == pytest.approx(55.6754, abs=1e-4)
    assert f3.stationary_points()[-1] == pytest.approx(32.864, abs=1e-3)
    assert (f2.mean_error, f3.mean_error) == (0.271, 0.744)


def test_difference_table_cubic_constant_third():
    x = np.arange(0, 41, 2.0)
    y = M.FINGERTIP_POWER_GRASP(x)
    d3 = M.difference_table(y, 3)[3]
    np.testing.assert_allclose(d3, 6 * 0.22e-4 * 2.0**3, rtol=1e-9)  # Δ³y = 6 d Δx³
    assert M.detect_degree(x, y) == 3
    assert M.detect_degree(x, M.FINGERTIP_PINCH(x)) == 2
    assert M.detect_degree(x, 3 + 0 * x) == 0


def test_detect_degree_bad_input():
    with pytest.raises(ValueError, match="constant step"):
        M.detect_degree([0, 1, 3, 4], [0, 1, 2, 3])
    with pytest.raises(ValueError, match="NaN"):
        M.detect_degree([0, 1, 2], [0, np.nan, 1])
    x = np.linspace(0, 1, 12)
    with pytest.raises(ValueError, match="no difference order"):
        M.detect_degree(x, np.exp(5 * x), max_degree=4)


def test_fit_recovers_printed_curves():
    for c in (M.FINGERTIP_POWER_GRASP, M.FINGERTIP_PINCH, M.THUMB_F2, M.THUMB_F3):
        x, y = M.sample_curve(c, 0, 40, 21)
        fit = M.fit_curve(x, y)
        np.testing.assert_allclose(fit.coeffs, c.coeffs, rtol=1e-7, atol=1e-10)
        assert fit.S < 1e-16 * len(x) * np.max(y**2) + 1e-18


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 4), st.integers(0, 2**31 - 1))
def test_fit_matches_numpy_lstsq_and_normal_equations(deg, seed):
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-5, 40, 30))
    y = rng.normal(size=30) * 3 + M.FINGERTIP_POWER_GRASP(x)
    fit = M.fit_polynomial(x, y, deg)
    ref = np.polynomial.polynomial.polyfit(x, y, deg)
    pred_ref = np.polynomial.polynomial.polyval(x, ref)
    # same minimiser: equal S, equal predictions; gradient of S (the normal equations) vanishes
    assert fit.S == pytest.approx(float(np.sum((pred_ref - y) ** 2)), rel=1e-8)
    np.testing.assert_allclose(fit(x), pred_ref, atol=1e-7)
    V = np.asarray(fit(x)) - y
    grad = np.array([np.sum(V * ((x - x.mean()) / 20) ** j) for j in range(deg + 1)])
    assert np.max(np.abs(grad)) < 1e-7 * np.sum(np.abs(y))
    assert fit.mean_error == pytest.approx(np.mean(np.abs(V)))


def test_normal_equations_structure():
    N, r = M.normal_equations([1.0, 2.0, 3.0], [1.0, 0.0, 2.0], 1)
    np.testing.assert_allclose(N, [[3, 6], [6, 14]])
    np.testing.assert_allclose(r, [3, 7])


def test_fit_bad_input():
    with pytest.raises(ValueError, match="samples"):
        M.fit_polynomial([1, 2], [1, 2], 3)
    with pytest.raises(ValueError, match="shapes"):
        M.fit_polynomial([1, 2, 3], [1, 2], 1)
    with pytest.raises(ValueError, match="singular"):
        M.fit_polynomial([1, 1, 1, 1], [1, 2, 3, 4], 2)


def test_piecewise_three_segments_recovered():
    knots = np.array([0.0, 40.0, 90.0, 130.0])  # A, B, C, D (deg of elbow flexion)
    vals = {
        "shoulder": np.array([0.0, 30.0, 35.0, 10.0]),
        "wrist": np.array([-10.0, 5.0, 5.0, 25.0]),
    }
    th = np.linspace(0, 130, 131)
    rng = np.random.default_rng(3)
    joints = {k: np.interp(th, knots, v) + rng.normal(0, 0.2, th.size) for k, v in vals.items()}
    coord = M.coordinate_joints(th, joints, 3)
    for k, v in vals.items():
        pw = coord.segments[k]
        np.testing.assert_allclose(pw.knots[1:-1], knots[1:-1], atol=1.5)
        np.testing.assert_allclose(pw.values, v, atol=1.0)
        assert pw.mean_error < 0.3
    out = coord(np.array([0.0, 130.0]))
    assert set(out) == {"shoulder", "wrist"}
    # imposed common breakpoints
    pw = M.fit_piecewise_linear(th, joints["wrist"], breakpoints=[40, 90])
    np.testing.assert_allclose(pw.values, vals["wrist"], atol=0.3)
    with pytest.raises(ValueError, match="strictly inside"):
        M.fit_piecewise_linear(th, joints["wrist"], breakpoints=[200])
