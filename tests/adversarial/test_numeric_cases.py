"""Numeric abuse of the public numeric API (issue 12, items 7, 8 and 12): each case a typed
error (anthroarm.errors or a documented ValueError/TypeError) or a correct answer."""

import math

import numpy as np
import pytest

import anthroarm as aa


@pytest.fixture(scope="module")
def arm():
    return aa.load("prosthetic_arm")


@pytest.mark.parametrize("tol", [-1.0, 0.0, math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("kw", ["tol", "tol_orthonormal"])
def test_analytic_rejects_bad_tolerances(arm, tol, kw):
    T = np.asarray(arm.fk(np.full(6, 0.3)))
    with pytest.raises(ValueError, match=kw):
        aa.ik.analytic(arm, T, **{kw: tol})
    with pytest.raises(ValueError, match=kw):
        aa.ik.analytic_batch(arm, T[None], **{kw: tol})


def test_analytic_rejects_non_numeric_tolerance(arm):
    T = np.asarray(arm.fk(np.full(6, 0.3)))
    with pytest.raises(TypeError, match="tol"):
        aa.ik.analytic(arm, T, tol="1e-9")


@pytest.mark.parametrize(
    "name", ["prosthetic_arm", "sixr_arm", "planar2r", "human_arm7", "ur5", "panda"]
)
def test_analytic_batch_of_zero_poses_is_empty(name):
    robot = aa.load(name)
    b = aa.ik.analytic_batch(robot, np.zeros((0, 4, 4)))
    assert len(b) == 0
    assert b.solutions.shape[0] == 0 and b.valid.shape[0] == 0
    assert b.n_solutions.shape == (0,)


@pytest.mark.parametrize("name", ["ur5", "kinova", "human_arm7", "planar2r", "panda"])
def test_analytic_takes_a_strided_pose(name):
    """A pose that is a strided view (a slice of a larger array, neither C nor Fortran order)
    is answered as its contiguous copy — it had raised a TypingError from inside Numba."""
    robot = aa.load(name)
    kw = {"param": 0.4} if name == "panda" else {}
    for q in robot.random_q(3, rng=5):
        T = robot.fk(q)
        big = np.zeros((8, 8))
        big[::2, ::2] = T
        view = big[::2, ::2]
        assert not view.flags.c_contiguous and not view.flags.f_contiguous
        a, b = (
            aa.ik.analytic(robot, view, **kw),
            aa.ik.analytic(robot, np.ascontiguousarray(T), **kw),
        )
        assert a.branches == b.branches and a.reason == b.reason, name
        np.testing.assert_array_equal(a.solutions, b.solutions)
        r = aa.ik.solve(robot, view if name != "planar2r" else np.ascontiguousarray(view[:3, 3]))
        assert r.success, name


@pytest.mark.parametrize("damping", [-10.0, -1e-12, math.nan, math.inf])
@pytest.mark.parametrize("solver", ["osqp", "proxqp"])
def test_qp_step_rejects_negative_or_non_finite_damping(arm, damping, solver):
    from anthroarm.ik import qp

    q0 = arm.random_q(rng=5, margin=0.2)
    conf = qp.IKConfiguration(arm, q0)
    ee = qp.FrameTask(arm, position_cost=1.0, orientation_cost=0.5)
    ee.set_target(arm.fk(arm.random_q(rng=6, margin=0.2)))
    with pytest.raises(ValueError, match="damping"):
        qp.step(conf, None, [ee], 0.01, solver=solver, damping=damping)


@pytest.mark.parametrize("samples", [0, -3, 2, 2.5, True])
def test_rssr_crank_test_rejects_bad_sample_counts(samples):
    from anthroarm.mechanisms.rssr import RSSRGeometry, rssr_crank_test

    g = RSSRGeometry(
        a0=[0, 0, 0], ua=[0, 0, 1], a1=[1, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 3]
    )
    with pytest.raises(ValueError, match="samples"):
        rssr_crank_test(g, samples=samples)


# ----------------------------------------------------------------- fourbar at extreme scales
FOURBAR = (4.0, 1.5, 3.5, 3.0)  # the module docstring's crank-rocker


@pytest.mark.parametrize("scale", [1e-155, 1e-100, 1e100, 1e155, 1e300])
@pytest.mark.parametrize("kind", ["complex", "cartesian"])
def test_fourbar_angles_do_not_depend_on_the_length_unit(scale, kind):
    """Mathematics: angles and angular rates of a linkage are invariant under scaling its
    lengths."""
    import warnings

    from anthroarm.mechanisms.fourbar import fourbar, fourbar_cartesian

    def run(s):
        r1, r2, r3, r4 = (s * x for x in FOURBAR)
        if kind == "complex":
            return fourbar(r1, r2, r3, r4, 0.7, omega2=2.0, alpha2=-1.0)
        return fourbar_cartesian((r1, 0.0), r2, r3, r4, 0.7, omega2=2.0, alpha2=-1.0)

    ref = run(1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        got = run(scale)
    assert got.status == "ok"
    for k in ("theta3", "theta4", "omega3", "omega4", "alpha3", "alpha4"):
        assert math.isclose(getattr(got, k), getattr(ref, k), rel_tol=1e-12, abs_tol=1e-12), k
    assert math.isclose(got.d, scale * ref.d, rel_tol=1e-12)
    assert got.residual <= 1e-12 * scale


@pytest.mark.parametrize("scale", [1e-155, 1.0, 1e155])
def test_fourbar_range_and_grashof_at_extreme_scales(scale):
    from anthroarm.mechanisms.fourbar import fourbar_grashof, fourbar_input_range

    L = [scale * x for x in FOURBAR]
    assert fourbar_grashof(*L) == "crank-rocker"
    assert fourbar_input_range(*L).full_turn


@pytest.mark.parametrize("omega2, alpha2", [(1e300, 0.0), (-1e300, 0.0), (1e160, 0.0)])
def test_fourbar_unrepresentable_rates_are_a_value_error(omega2, alpha2):
    import warnings

    from anthroarm.mechanisms.fourbar import fourbar, fourbar_cartesian

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ValueError, match="beyond the float range"):
            fourbar(*FOURBAR, 0.7, omega2=omega2, alpha2=alpha2)
        with pytest.raises(ValueError, match="beyond the float range"):
            fourbar_cartesian((FOURBAR[0], 0.0), *FOURBAR[1:], 0.7, omega2=omega2, alpha2=alpha2)


def test_fourbar_large_but_representable_rates():
    """th2' = 1e150 rad/s: accelerations ~1e300 are representable; they scale as th2'^2."""
    from anthroarm.mechanisms.fourbar import fourbar

    ref = fourbar(*FOURBAR, 0.7, omega2=1.0)
    got = fourbar(*FOURBAR, 0.7, omega2=1e150)
    assert math.isclose(got.omega4, 1e150 * ref.omega4, rel_tol=1e-12)
    assert math.isclose(got.alpha4, 1e300 * ref.alpha4, rel_tol=1e-12)


@pytest.mark.parametrize(
    "lengths", [(1e-160, 1.0, 1.0, 1.0), (1.0, 1.0, 1e160, 1.0), (1e-320, 1.0, 1.0, 1.0)]
)
def test_fourbar_length_ratio_beyond_the_float_range(lengths):
    from anthroarm.mechanisms.fourbar import fourbar, fourbar_input_range

    with pytest.raises(ValueError, match="differ by a factor"):
        fourbar(*lengths, 0.3)
    with pytest.raises(ValueError, match="differ by a factor"):
        fourbar_input_range(*lengths)


# ------------------------------------------------------------- ik.qp limits and integration
@pytest.mark.parametrize("v_max", [-1.0, -1e-12, [1, 1, 1, 1, 1, -2.0]])
def test_qp_velocity_limit_rejects_negative_bounds(arm, v_max):
    """A negative speed bound used to be silently replaced by "no limit"."""
    from anthroarm.ik import qp

    with pytest.raises(ValueError, match="v_max"):
        qp.VelocityLimit(arm, v_max=v_max)


def test_qp_configuration_limit_rejects_nan_bounds(arm):
    from anthroarm.ik import qp

    with pytest.raises(ValueError, match="NaN"):
        qp.ConfigurationLimit(arm, lower=np.full(6, math.nan))
    with pytest.raises(ValueError, match="NaN"):
        qp.ConfigurationLimit(arm, upper=np.r_[np.ones(5), math.nan])


@pytest.mark.parametrize("dt", [math.nan, math.inf, np.array(math.nan)])
def test_qp_integrate_rejects_non_finite_dt(arm, dt):
    from anthroarm.ik import qp

    conf = qp.IKConfiguration(arm, arm.random_q(rng=3, margin=0.1))
    q0 = conf.q.copy()
    with pytest.raises(ValueError, match="dt"):
        conf.integrate_inplace(np.zeros(6), dt)
    assert np.array_equal(conf.q, q0)


# ------------------------------------------------------------------------ Lagrange magnitudes
@pytest.mark.parametrize("what", ["q", "qd", "tau"])
def test_lagrange_rejects_states_beyond_the_bound(what):
    """|x| > 1e100: squares times inertias leave the float range (was NaN/inf with a warning)."""
    import warnings

    from anthroarm.dynamics import lagrange

    d = lagrange.load(aa.load("planar2r"))
    args = {"q": np.zeros(2), "qd": np.zeros(2), "tau": np.zeros(2)}
    args[what] = np.array([0.0, 1e200])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ValueError, match=what):
            d.forward(args["q"], args["qd"], args["tau"])
