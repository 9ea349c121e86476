"""Property tests over the public numeric API (issue 12, "What must exist": hypothesis).

For random VALID inputs every output is finite and every returned q lies inside the limits;
for random INVALID inputs (NaN, inf, wrong shapes, huge/tiny magnitudes, negative counts and
tolerances) every exception is an :mod:`anthroarm.errors` type or a documented
``ValueError``/``TypeError`` — never ``ZeroDivisionError``, numpy's ``LinAlgError`` (a
``ValueError`` subclass, excluded on purpose), ``OverflowError``, ``IndexError`` — and never a
silent NaN.  ``RuntimeWarning`` is an error inside these tests (fixture), so a NaN or overflow
that numpy only warns about fails the test.

Expected values come from mathematics (scale invariance of a linkage's angles, orthonormality,
round trips), not from the code under test.
"""

import math
import warnings
from dataclasses import fields, is_dataclass

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.errors import AnthroarmError

SETTINGS = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
FEW = settings(SETTINGS, max_examples=10)

FORBIDDEN = (
    np.linalg.LinAlgError,
    ZeroDivisionError,
    OverflowError,
    IndexError,
    FloatingPointError,
    RuntimeWarning,
    KeyError,
    AttributeError,
    AssertionError,
)
LIMIT_TOL = 1e-6  # ik.analytic's LIMIT_SLACK


@pytest.fixture(autouse=True)
def runtime_warnings_are_errors():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        yield


def finite(x, path="out") -> None:
    """Assert every number reachable from ``x`` (arrays, scalars, tuples, dicts, dataclasses,
    Dual numbers, result objects) is finite."""
    if x is None or isinstance(x, (str, bool, np.bool_)):
        return
    if isinstance(x, (int, float, complex, np.number)):
        assert np.isfinite(x), f"{path} = {x}"
        return
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fciu":
            assert np.all(np.isfinite(x)), f"{path} has non-finite entries: {x}"
        elif x.dtype == object:
            for i, v in enumerate(x.flat):
                finite(v, f"{path}[{i}]")
        return
    if isinstance(x, dict):
        for k, v in x.items():
            finite(v, f"{path}[{k!r}]")
        return
    if isinstance(x, (tuple, list)):
        for i, v in enumerate(x):
            finite(v, f"{path}[{i}]")
        return
    if is_dataclass(x):
        for f in fields(x):
            finite(getattr(x, f.name), f"{path}.{f.name}")
        return
    if hasattr(x, "real") and hasattr(x, "dual"):  # spatial.Dual
        finite(np.asarray(x.real), f"{path}.real")
        finite(np.asarray(x.dual), f"{path}.dual")
        return
    if hasattr(x, "__dict__"):
        for k, v in vars(x).items():
            if not k.startswith("_") and not callable(v):
                finite(v, f"{path}.{k}")


def typed_or_finite(fn, *args, **kw):
    """Call ``fn``: it raises an anthroarm error / ValueError / TypeError (not a forbidden
    type) or returns only finite numbers.  Returns the result (None after an error)."""
    try:
        res = fn(*args, **kw)
    except FORBIDDEN as exc:
        pytest.fail(f"{getattr(fn, '__name__', fn)}: untyped {type(exc).__name__}: {exc}")
    except (AnthroarmError, ValueError, TypeError) as exc:
        assert str(exc), f"{type(exc).__name__} without a message"
        return None
    finite(res, getattr(fn, "__name__", "out"))
    return res


def must_raise(fn, *args, **kw):
    """``fn`` must raise an anthroarm error / ValueError / TypeError (not a forbidden type)."""
    try:
        res = fn(*args, **kw)
    except FORBIDDEN as exc:
        pytest.fail(f"{getattr(fn, '__name__', fn)}: untyped {type(exc).__name__}: {exc}")
    except (AnthroarmError, ValueError, TypeError) as exc:
        assert str(exc)
        return
    pytest.fail(f"{getattr(fn, '__name__', fn)} accepted the input and returned {res!r}")


_ROBOTS = {}


def robot(name):
    if name not in _ROBOTS:
        _ROBOTS[name] = aa.load(name)
    return _ROBOTS[name]


def q_in_limits(r, frac):
    """A configuration inside the limits from fractions in [0, 1] of each independent joint's
    range (continuous or unbounded joints: of [-pi, pi])."""
    ch = r.chain
    lo, hi = np.asarray(ch.lower, float), np.asarray(ch.upper, float)
    th = []
    for f, i in zip(frac, ch.independent):
        j = ch.joints[i]
        a, b = (lo[j.idx_q], hi[j.idx_q]) if j.kind != "continuous" else (-np.pi, np.pi)
        a, b = (a if np.isfinite(a) else -np.pi), (b if np.isfinite(b) else np.pi)
        th.append(a + f * (b - a))
    return ch.configuration(np.asarray(th))


def inside_limits(r, q, tol=LIMIT_TOL):
    ch = r.chain
    lo, hi = np.asarray(ch.lower, float), np.asarray(ch.upper, float)
    for j in ch.joints:
        if j.is_mimic or j.kind == "continuous":
            continue
        i = j.idx_q
        if np.isfinite(lo[i]):
            assert q[..., i].min() >= lo[i] - tol, (j.name, q[..., i], lo[i])
        if np.isfinite(hi[i]):
            assert q[..., i].max() <= hi[i] + tol, (j.name, q[..., i], hi[i])


fracs = st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9)
bad_float = st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-320])
nonfinite = st.sampled_from([math.nan, math.inf, -math.inf])


# ============================================================== VALID inputs: finite, in limits
@pytest.mark.parametrize("name", ["prosthetic_arm", "sixr_arm", "planar2r", "human_arm7"])
@SETTINGS
@given(frac=fracs)
def test_analytic_ik_solutions_finite_and_inside_limits(name, frac):
    r = robot(name)
    q = q_in_limits(r, frac)
    T = np.asarray(r.fk(q))
    res = aa.ik.analytic(r, T)
    sols = np.asarray(res.solutions, float).reshape(-1, r.nq)
    assert np.all(np.isfinite(sols))
    if sols.size:
        inside_limits(r, sols)
        for s in sols:  # every solution reaches the pose (IK o FK)
            Ts = np.asarray(r.fk(s))
            if name == "planar2r":
                assert np.allclose(Ts[:3, 3], T[:3, 3], atol=1e-6)
            elif name != "human_arm7":
                assert np.allclose(Ts, T, atol=1e-6)


@pytest.mark.parametrize("name", ["prosthetic_arm", "kinova"])
@FEW
@given(f0=fracs, f1=fracs, dt=st.floats(1e-3, 0.1))
def test_qp_step_integrate_stays_finite_and_inside_limits(name, f0, f1, dt):
    from anthroarm.ik import qp

    r = robot(name)
    conf = qp.IKConfiguration(r, q_in_limits(r, f0))
    ee = qp.FrameTask(r, position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)
    ee.set_target(r.fk(q_in_limits(r, f1)))
    tasks = [ee, qp.PostureTask(r, cost=1e-3)]
    for _ in range(5):
        v = qp.step(conf, None, tasks, dt)
        v = np.asarray(getattr(v, "v", v))
        assert np.all(np.isfinite(v))
        conf.integrate_inplace(v, dt)
        assert np.all(np.isfinite(conf.q))
        inside_limits(r, conf.q, tol=1e-9)


@pytest.mark.parametrize("name", ["planar2r", "prosthetic_arm", "kinova", "panda"])
@FEW
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 20))
def test_fk_and_jacobian_batches_are_finite(name, seed, n):
    r = robot(name)
    Q = r.random_q(n, rng=seed)
    T = np.asarray(r.fk(Q))
    J = np.asarray(r.jacobian(Q))
    assert T.shape == (n, 4, 4) and np.all(np.isfinite(T))
    assert np.all(np.isfinite(J))
    assert np.allclose(T[:, 3], [0, 0, 0, 1])
    R = T[:, :3, :3]
    assert np.allclose(R @ np.swapaxes(R, 1, 2), np.eye(3), atol=1e-9)


@pytest.mark.parametrize("name", ["planar2r", "prosthetic_arm"])
@FEW
@given(seed=st.integers(0, 2**31 - 1), scale=st.floats(1e-3, 1e3))
def test_lagrange_tau_M_forward_finite_and_consistent(name, seed, scale):
    from anthroarm.dynamics import lagrange

    r = robot(name)
    dyn = lagrange.load(r)
    rng = np.random.default_rng(seed)
    q = r.random_q(rng=seed)
    qd, qdd = scale * rng.normal(size=r.nv), scale * rng.normal(size=r.nv)
    M = dyn.mass_matrix(q)
    tau = dyn.tau(q, qd, qdd)
    assert np.all(np.isfinite(M)) and np.all(np.isfinite(tau))
    assert np.allclose(M, M.T)
    acc = dyn.forward(q, qd, tau)  # mathematics: forward(tau(q, qd, qdd)) = qdd
    assert np.allclose(acc, qdd, rtol=1e-6, atol=1e-6 * scale)


def same(a, b, tol):
    """Angles equal modulo 2 pi, rates equal (relative tolerance)."""
    for k in ("theta3", "theta4"):
        d = getattr(a, k) - getattr(b, k)
        assert abs(math.remainder(d, 2 * math.pi)) <= tol, (k, getattr(a, k), getattr(b, k))
    for k in ("omega3", "omega4", "alpha3", "alpha4"):
        assert math.isclose(getattr(a, k), getattr(b, k), rel_tol=tol, abs_tol=tol), (
            k,
            getattr(a, k),
            getattr(b, k),
        )


fourbar_lengths = st.tuples(*[st.floats(0.2, 5.0)] * 4)


@SETTINGS
@given(
    L=fourbar_lengths,
    th2=st.floats(-np.pi, np.pi),
    w2=st.floats(-10, 10),
    a2=st.floats(-10, 10),
    e=st.integers(-155, 155),
    branch=st.sampled_from([1, -1]),
)
def test_fourbar_is_scale_invariant(L, th2, w2, a2, e, branch):
    """Mathematics: scaling every length by s leaves the angles and angular rates unchanged."""
    from anthroarm.mechanisms.fourbar import fourbar, fourbar_cartesian

    s = 10.0**e
    ref = fourbar(*L, th2, w2, a2, branch=branch)
    got = typed_or_finite(fourbar, *(s * x for x in L), th2, w2, a2, branch=branch)
    assert got is not None
    assert got.status == ref.status
    if ref.status == "ok" and abs(math.sin(ref.theta3 - ref.theta4)) > 1e-3:
        same(got, ref, 1e-9)
        assert got.residual <= 1e-9 * s * sum(L)
    cart = typed_or_finite(
        fourbar_cartesian, (s * L[0], 0.0), *(s * x for x in L[1:]), th2, w2, a2, branch=branch
    )
    assert cart is not None and cart.status == ref.status
    if ref.status == "ok" and abs(math.sin(ref.theta3 - ref.theta4)) > 1e-3:
        same(cart, ref, 1e-8)


@SETTINGS
@given(L=fourbar_lengths, e=st.integers(-155, 155))
def test_fourbar_range_and_grashof_scale_invariant(L, e):
    from anthroarm.mechanisms.fourbar import fourbar_grashof, fourbar_input_range

    r1, r2, r3, r4 = L
    # away from the boundaries of the range (cos th2 = +-1 there: rounding decides)
    assume(
        min(abs(abs(r1 + sg * r2) - abs(r3 + sh * r4)) for sg in (1, -1) for sh in (1, -1)) > 1e-6
    )
    s = 10.0**e
    assert fourbar_grashof(*(s * x for x in L)) == fourbar_grashof(*L)
    a, b = fourbar_input_range(*L), typed_or_finite(fourbar_input_range, *(s * x for x in L))
    assert b is not None and a.full_turn == b.full_turn
    assert np.allclose(
        np.asarray(a.intervals, float).ravel(), np.asarray(b.intervals, float).ravel(), atol=1e-9
    )


@SETTINGS
@given(w2=st.sampled_from([1e300, -1e300, 1e200, 1e155]), L=fourbar_lengths, th2=st.floats(-3, 3))
def test_fourbar_huge_rates_are_finite_or_value_error(w2, L, th2):
    from anthroarm.mechanisms.fourbar import fourbar, fourbar_cartesian

    typed_or_finite(fourbar, *L, th2, w2, 0.0)
    typed_or_finite(fourbar, *L, th2, 1.0, w2)
    typed_or_finite(fourbar_cartesian, (L[0], 0.0), *L[1:], th2, w2, 0.0)


unit_vec = (
    st.tuples(*[st.floats(-1, 1)] * 3)
    .filter(lambda v: np.linalg.norm(v) > 0.3)
    .map(lambda v: np.asarray(v) / np.linalg.norm(v))
)
pt3 = st.tuples(*[st.floats(-2, 2)] * 3).map(np.asarray)


@SETTINGS
@given(
    a0=pt3,
    ua=unit_vec,
    a1=pt3,
    b0=pt3,
    ub=unit_vec,
    b1=pt3,
    alpha=st.floats(-np.pi, np.pi),
    w=st.floats(-5, 5),
    branch=st.sampled_from([1, -1]),
)
def test_rssr_and_rrss_valid_inputs_are_finite(a0, ua, a1, b0, ub, b1, alpha, w, branch):
    from anthroarm.mechanisms.rrss import RRSSGeometry, rrss
    from anthroarm.mechanisms.rssr import RSSRGeometry, rssr

    g = typed_or_finite(RSSRGeometry, a0=a0, ua=ua, a1=a1, b0=b0, ub=ub, b1=b1)
    if g is not None:
        typed_or_finite(rssr, g, alpha, w, 0.5 * w, branch=branch)
    h = typed_or_finite(RRSSGeometry, a0=a0, u0=ua, a1=a1, u1=ub, b0=b0, b1=b1)
    if h is not None:
        typed_or_finite(rrss, h, alpha, w, 0.5 * w, branch=branch)


@SETTINGS
@given(
    P1=st.tuples(st.floats(-2, 2), st.floats(-2, 2)),
    P2=st.tuples(st.floats(-2, 2), st.floats(-2, 2)),
    r1=st.floats(0.1, 3),
    r2=st.floats(0.1, 3),
    e=st.integers(-150, 150),
    branch=st.sampled_from([1, -1]),
)
def test_dyad_valid_inputs_are_finite(P1, P2, r1, r2, e, branch):
    from anthroarm.mechanisms.dyads import dyad

    s = 10.0**e
    z = (0.0, 0.0)
    typed_or_finite(
        dyad, np.multiply(P1, s), z, z, np.multiply(P2, s), z, z, r1 * s, r2 * s, branch=branch
    )


@SETTINGS
@given(
    u=unit_vec,
    th=st.floats(-10, 10),
    s=st.floats(-5, 5),
    p=pt3,
    a=st.floats(-np.pi, np.pi),
    b=st.floats(-np.pi, np.pi),
    c=st.floats(-np.pi, np.pi),
)
def test_spatial_valid_inputs_are_finite_and_orthonormal(u, th, s, p, a, b, c):
    from anthroarm import spatial as sp
    from anthroarm.spatial import dual as du

    R = sp.rot_axis(u, th)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12) and np.isclose(np.linalg.det(R), 1.0)
    Rt = sp.rotation_matrix(th, u)
    assert np.allclose(Rt, R, atol=1e-12)
    finite(sp.screw_matrix(th, s, u, p))
    finite(sp.screw_twist(th, s, u, p))
    finite(sp.euler_zxz(a, b, c))
    finite(sp.euler_xyx(a, b, c))
    ax, ang = sp.axis_angle(R)
    finite((ax, ang))
    finite(sp.rotation_between(u, p + 3.0))
    d = du.Dual(th, s)
    for f in (du.sin, du.cos, du.exp, du.atan2):
        finite(f(d) if f is not du.atan2 else f(d, du.Dual(1.0, 0.0)))
    finite(du.sqrt(du.Dual(abs(th) + 1.0, s)))


# ========================================================= INVALID inputs: typed errors only
@SETTINGS
@given(bad=bad_float, which=st.integers(0, 6), L=fourbar_lengths)
def test_fourbar_bad_numbers(bad, which, L):
    from anthroarm.mechanisms.fourbar import (
        fourbar,
        fourbar_cartesian,
        fourbar_grashof,
        fourbar_input_range,
    )

    args = [*L, 0.7, 1.0, 0.0]
    args[which] = bad
    typed_or_finite(fourbar, *args)
    typed_or_finite(fourbar_cartesian, (args[0], 0.0), *args[1:])
    typed_or_finite(fourbar_input_range, *args[:4])
    typed_or_finite(fourbar_grashof, *args[:4])
    for neg in (-1.0, 0.0):
        a = list(args)
        a[which % 4] = neg
        must_raise(fourbar, *a)


@SETTINGS
@given(bad=bad_float, which=st.integers(0, 5))
def test_rssr_rrss_bad_numbers(bad, which):
    from anthroarm.mechanisms.rrss import RRSSGeometry, rrss
    from anthroarm.mechanisms.rssr import RSSRGeometry, rssr, rssr_crank_test

    good = dict(a0=[0, 0, 0], ua=[0, 0, 1], a1=[1, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 3])
    g = RSSRGeometry(**good)
    kw = dict(good)
    key = list(kw)[which]
    kw[key] = [bad, 0, 0] if key[0] != "u" else [bad, 0, 1]
    typed_or_finite(RSSRGeometry, **kw)
    typed_or_finite(rssr, g, bad)
    typed_or_finite(rssr, g, 0.3, bad)
    typed_or_finite(rssr, g, 0.3, 1.0, bad)
    must_raise(rssr, g, 0.3, branch=0)
    typed_or_finite(rssr_crank_test, g, samples=-5)
    h = RRSSGeometry(
        a0=[0, 0, 0], u0=[0, 0, 1], a1=[1, 0, 0], u1=[1, 0, 0], b0=[3, 0, 1], b1=[3, 0, 3]
    )
    typed_or_finite(rrss, h, bad)
    typed_or_finite(rrss, h, 0.3, bad)
    typed_or_finite(
        RRSSGeometry,
        a0=[0, 0, 0],
        u0=[0, 0, 1],
        a1=[1, 0, 0],
        u1=[bad, 0, 0],
        b0=[3, 0, 1],
        b1=[3, 0, 3],
    )


@SETTINGS
@given(
    e=st.integers(-300, 308), alpha=st.floats(-np.pi, np.pi), w=st.sampled_from([0.0, 1.0, 1e200])
)
def test_rssr_rrss_extreme_scales_are_finite_or_value_error(e, alpha, w):
    """Geometry scaled by 10^e: the geometry is accepted or refused with a ValueError; the
    closed forms return finite states (the same angles, by scale invariance, where the length
    scale is moderate) or a ValueError naming the unrepresentable quantity (E^2 + F^2 - G^2
    grows as the fourth power of the lengths)."""
    from anthroarm.mechanisms.rrss import RRSSGeometry, rrss
    from anthroarm.mechanisms.rssr import RSSRGeometry, rssr

    s = 10.0**e
    P = dict(a0=[0, 0, 0], a1=[1, 0, 0], b0=[3, 0, 1], b1=[3, 0, 3])
    sc = {k: [s * x for x in v] for k, v in P.items()}
    g = typed_or_finite(RSSRGeometry, ua=[0, 0, 1], ub=[0, 1, 0], **sc)
    if g is not None:
        got = typed_or_finite(rssr, g, alpha, w)
        if got is not None and abs(e) <= 60 and w == 0.0:
            ref = rssr(RSSRGeometry(ua=[0, 0, 1], ub=[0, 1, 0], **P), alpha)
            assert got.status == ref.status
            assert abs(math.remainder(got.beta - ref.beta, 2 * math.pi)) <= 1e-9
    h = typed_or_finite(RRSSGeometry, u0=[0, 0, 1], u1=[1, 0, 0], **sc)
    if h is not None:
        typed_or_finite(rrss, h, alpha, w)


@SETTINGS
@given(bad=bad_float, which=st.integers(0, 8))
def test_dyad_bad_numbers(bad, which):
    from anthroarm.mechanisms.dyads import dyad, rigid_body_point

    args = [(0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (2.0, 0.0), (0.0, 0.0), (0.0, 0.0), 1.5, 1.5]
    if which < 6:
        args[which] = (bad, 0.0)
    elif which < 8:
        args[which] = bad
    typed_or_finite(dyad, *args)
    typed_or_finite(rigid_body_point, (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), bad, 0.3)
    typed_or_finite(rigid_body_point, (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), 1.0, bad, bad)


@SETTINGS
@given(bad=bad_float, shape=st.sampled_from([(2,), (4,), (3, 3), ()]))
def test_spatial_bad_inputs(bad, shape):
    from anthroarm import spatial as sp
    from anthroarm.spatial import dual as du
    from anthroarm.spatial import euler as eu

    u = np.array([bad, 0.0, 1.0])
    typed_or_finite(sp.rot_axis, u, 0.3)
    typed_or_finite(sp.rot_axis, [0.0, 0.0, 1.0], bad)
    typed_or_finite(sp.rot_axis, [0.0, 0.0, 2.0], 0.3)  # non-unit axis
    typed_or_finite(sp.rot_axis, np.zeros(shape), 0.3)
    typed_or_finite(sp.rotation_matrix, 0.3, u)
    typed_or_finite(sp.rotation_matrix, bad, [0.0, 0.0, 1.0])
    typed_or_finite(sp.screw_matrix, 0.3, bad, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    typed_or_finite(sp.screw_matrix, 0.3, 0.1, [0.0, 0.0, 1.0], [bad, 0.0, 0.0])
    typed_or_finite(sp.screw_twist, 0.3, 0.1, [0.0, 3.0, 0.0], [0.0, 0.0, 0.0])
    typed_or_finite(sp.velocity_matrix, bad, [0.0, 0.0, 1.0])
    typed_or_finite(sp.acceleration_matrix, 1.0, bad, [0.0, 0.0, 1.0])
    typed_or_finite(sp.euler_zxz, bad, 0.1, 0.2)
    typed_or_finite(sp.euler_xyx, 0.1, bad, 0.2)
    typed_or_finite(sp.euler_zxz_inverse, np.full((3, 3), bad))
    typed_or_finite(sp.euler_xyx_inverse, np.full((3, 3), bad))
    typed_or_finite(sp.euler_zxz_inverse, np.eye(3), tol=bad)
    typed_or_finite(eu.euler_xyx_rate_matrix, bad, 0.2)
    typed_or_finite(sp.axis_angle, np.full((3, 3), bad))
    typed_or_finite(sp.axis_angle, np.zeros(shape))
    typed_or_finite(sp.rotation_between, [bad, 0.0, 0.0], [0.0, 1.0, 0.0])
    typed_or_finite(sp.rotation_between, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    typed_or_finite(sp.homogeneous, np.full((3, 3), bad), [0, 0, 0])
    typed_or_finite(sp.skew, [bad, 0, 0])
    typed_or_finite(sp.unskew, np.full((3, 3), bad))
    typed_or_finite(sp.check_rotation, np.full((3, 3), bad))
    typed_or_finite(sp.unit_axis, [bad, 0, 0])
    typed_or_finite(sp.unit_axis, np.zeros(3))
    typed_or_finite(sp.rotate, [0.0, 0.0, 1.0], bad, [1.0, 0.0, 0.0])
    typed_or_finite(sp.rotated_vector_motion, [0.0, 0.0, 1.0], 0.1, bad, 0.0, [1.0, 0.0, 0.0])
    typed_or_finite(du.Dual, bad, 0.0)
    typed_or_finite(lambda: du.Dual(1.0, 0.0) / du.Dual(0.0, 1.0))
    typed_or_finite(lambda: du.sqrt(du.Dual(0.0, 1.0)))
    typed_or_finite(lambda: du.log(du.Dual(0.0, 1.0)))
    typed_or_finite(lambda: du.acos(du.Dual(1.0, 1.0)))
    typed_or_finite(lambda: du.asin(du.Dual(-1.0, 1.0)))
    typed_or_finite(lambda: du.tan(du.Dual(np.pi / 2, 1.0)))
    typed_or_finite(lambda: du.exp(du.Dual(1000.0, 1.0)))
    typed_or_finite(lambda: du.atan2(du.Dual(0.0, 1.0), du.Dual(0.0, 1.0)))
    typed_or_finite(lambda: du.norm(du.Dual(np.zeros(3), np.ones(3))))
    typed_or_finite(du.dual_angle, bad, 0.0)
    typed_or_finite(du.screw_x, bad)
    typed_or_finite(du.translation_dual, bad, 0.0, 0.0)
    typed_or_finite(du.Line, [bad, 0, 0], [0, 0, 0]) if hasattr(du, "Line") else None


def _quad(x):
    x = np.atleast_1d(np.asarray(x, float))
    return float(np.sum((x - 1.0) ** 2))


@SETTINGS
@given(
    bad=bad_float,
    count=st.sampled_from([0, -1, -100]),
    tol=st.sampled_from([0.0, -1e-6, math.nan, math.inf]),
)
def test_design_optimisers_bad_inputs(bad, count, tol):
    from anthroarm.design import optimize as o

    nanf = lambda x: math.nan  # noqa: E731
    inff = lambda x: math.inf  # noqa: E731
    for f in (nanf, inff):
        typed_or_finite(o.golden_section, f, 0.0, 2.0)
        typed_or_finite(o.quadratic_interpolation, f, (0.0, 1.0, 2.0))
        typed_or_finite(o.fletcher_reeves, f, [0.5, 0.5])
        typed_or_finite(o.steepest_descent, f, [0.5, 0.5])
        typed_or_finite(o.simplex_book, f, [0.5, 0.5])
        typed_or_finite(o.sumt_exterior, f, [0.5, 0.5])
        typed_or_finite(o.sumt_interior, f, [0.5, 0.5], [lambda x: 2.0 - x[0]])
        typed_or_finite(o.bracket_minimum, f, 0.0)
        typed_or_finite(o.line_minimize, f)
    typed_or_finite(o.golden_section, _quad, bad, 2.0)
    typed_or_finite(o.golden_section, _quad, 0.0, 2.0, eps=tol)
    typed_or_finite(o.golden_section, _quad, 0.0, 2.0, n=count)
    typed_or_finite(o.golden_section, _quad, 0.0, 2.0, scan=count)
    typed_or_finite(o.golden_points_needed, 0.0, 2.0, tol)
    typed_or_finite(o.golden_points_needed, 0.0, bad, 1e-3)
    typed_or_finite(o.quadratic_interpolation, _quad, (0.0, bad, 2.0))
    typed_or_finite(o.quadratic_interpolation, _quad, (0.0, 1.0, 2.0), eps=tol)
    typed_or_finite(o.quadratic_interpolation, _quad, (0.0, 1.0, 2.0), maxiter=count)
    typed_or_finite(o.quadratic_step, 0.0, 1.0, 1.0, 1.0, 2.0, 3.0)
    typed_or_finite(o.quadratic_step, 0.0, 1.0, 2.0, 1.0, 1.0, 1.0)
    typed_or_finite(o.quadratic_step_equal, 0.0, 1.0, 1.0, 1.0)
    typed_or_finite(o.quadratic_step_equal, bad, 1.0, 0.0, 1.0)
    typed_or_finite(o.quadratic_coefficients, 0.0, 0.0, 2.0, 1.0, 1.0, 1.0)
    typed_or_finite(o.fletcher_reeves, _quad, [bad, 0.5])
    typed_or_finite(o.fletcher_reeves, _quad, [0.5, 0.5], gtol=tol)
    typed_or_finite(o.fletcher_reeves, _quad, [0.5, 0.5], maxiter=count)
    typed_or_finite(o.steepest_descent, _quad, [0.5, 0.5], maxiter=count)
    typed_or_finite(o.numerical_gradient, _quad, [0.5, 0.5], h=tol)
    typed_or_finite(o.simplex_book, _quad, [bad, 0.5])
    typed_or_finite(o.simplex_book, _quad, [0.5, 0.5], step=bad)
    typed_or_finite(o.simplex_book, _quad, [0.5, 0.5], step=0.0)
    typed_or_finite(o.simplex_book, _quad, [0.5, 0.5], eps1=tol)
    typed_or_finite(o.simplex_book, _quad, [0.5, 0.5], maxiter=count)
    typed_or_finite(o.sumt_exterior, _quad, [0.5, 0.5], bounds=[(0.0, bad), (0.0, 1.0)])
    typed_or_finite(o.sumt_exterior, _quad, [0.5, 0.5], eps1=tol)
    typed_or_finite(o.sumt_exterior, _quad, [0.5, 0.5], max_stages=count)
    typed_or_finite(o.sumt_exterior, _quad, [0.5, 0.5], c=tol)
    typed_or_finite(o.sumt_interior, _quad, [0.5, 0.5], [lambda x: 2.0 - x[0]], r0=tol)
    typed_or_finite(o.sumt_interior, _quad, [0.5, 0.5], [lambda x: 2.0 - x[0]], max_stages=count)
    typed_or_finite(o.sumt_mixed, _quad, [0.5, 0.5], [lambda x: 2.0 - x[0]], eps1=tol)
    typed_or_finite(o.bounds_to_ineq, [(bad, 1.0)])
    typed_or_finite(o.bracket_minimum, _quad, 0.0, h=tol)
    typed_or_finite(o.bracket_minimum, _quad, 0.0, maxiter=count)
    typed_or_finite(o.line_minimize, _quad, h0=tol)


@pytest.mark.parametrize("name", ["planar2r", "prosthetic_arm"])
@SETTINGS
@given(
    bad=bad_float, where=st.integers(0, 20), shape=st.sampled_from([None, (1,), (3, 2, 2), (0, 2)])
)
def test_lagrange_bad_states(name, bad, where, shape):
    from anthroarm.dynamics import lagrange

    r = robot(name)
    dyn = lagrange.load(r)
    q, v = np.zeros(r.nq), np.zeros(r.nv)
    qb = q.copy()
    qb[where % r.nq] = bad
    for fn, args in (
        (dyn.mass_matrix, (qb,)),
        (dyn.tau, (qb, v, v)),
        (dyn.forward, (qb, v, v)),
        (dyn.forward, (q, v, np.full(r.nv, bad))),
        (dyn.gravity, (qb,)),
        (dyn.coriolis, (q, qb[: r.nv])),
    ):
        typed_or_finite(fn, *args)
    if shape is not None:
        typed_or_finite(dyn.forward, np.zeros(shape), v, v)
        typed_or_finite(dyn.tau, q, np.zeros(shape), v)


@pytest.mark.parametrize("name", ["planar2r", "prosthetic_arm", "kinova"])
@SETTINGS
@given(bad=bad_float, where=st.integers(0, 20), n=st.integers(-3, 3))
def test_fk_jacobian_bad_inputs(name, bad, where, n):
    r = robot(name)
    q = np.asarray(r.random_q(rng=0), float)
    q[where % r.nq] = bad
    typed_or_finite(r.fk, q)
    typed_or_finite(r.jacobian, q)
    typed_or_finite(r.fk, np.stack([q, q]))
    typed_or_finite(r.fk, np.zeros(r.nq + 1))
    typed_or_finite(r.jacobian, np.zeros((2, r.nq - 1)))
    typed_or_finite(r.random_q, n)
    typed_or_finite(r.random_q, rng=0, margin=bad)


@SETTINGS
@given(bad=bad_float, neg=st.sampled_from([-1.0, -1e-12, -1e300]))
def test_qp_tasks_and_limits_reject_negative_or_non_finite_weights(bad, neg):
    from anthroarm.ik import qp

    r = robot("prosthetic_arm")
    h = robot("human_arm7")
    for x in (neg,) + ((bad,) if not math.isfinite(bad) else ()):
        must_raise(qp.FrameTask, r, position_cost=x)
        must_raise(qp.FrameTask, r, orientation_cost=x)
        must_raise(qp.FrameTask, r, gain=x)
        must_raise(qp.FrameTask, r, lm_damping=x)
        must_raise(qp.PositionTask, r, cost=x)
        must_raise(qp.OrientationTask, r, cost=x)
        must_raise(qp.PostureTask, r, cost=x)
        must_raise(qp.PostureTask, r, cost=np.r_[np.ones(r.nv - 1), x])
        must_raise(qp.DampingTask, cost=x)
        must_raise(qp.SwivelTask, h, cost=x)
        must_raise(qp.RelativeFrameTask, r, r.tool, r.model.frames[1].name, position_cost=x)
        must_raise(
            qp.JointCouplingTask,
            r,
            [r.chain.joints[0].name, r.chain.joints[1].name],
            [1.0, -1.0],
            cost=x,
        )
        must_raise(qp.ConfigurationLimit, r, gain=x)
        if x != math.inf:  # an infinite speed / acceleration bound is documented as "no limit"
            must_raise(qp.VelocityLimit, r, v_max=x)
            must_raise(qp.VelocityLimit, r, v_max=np.r_[np.ones(r.nv - 1), x])
            must_raise(qp.AccelerationLimit, r, a_max=x)
    if math.isnan(bad):
        must_raise(qp.ConfigurationLimit, r, lower=np.full(r.nq, bad))
        must_raise(qp.SwivelTask, h, target=bad)
    conf = qp.IKConfiguration(r, r.random_q(rng=2, margin=0.1))
    if not math.isfinite(bad):
        must_raise(conf.integrate_inplace, np.zeros(r.nv), bad)
        must_raise(qp.step, conf, None, [qp.PostureTask(r)], bad)
        must_raise(qp.step, r, np.full(r.nq, bad), [qp.PostureTask(r)], 0.01)
        ft = qp.FrameTask(r)
        must_raise(ft.set_target, np.full((4, 4), bad))
    must_raise(qp.step, conf, None, [qp.PostureTask(r)], neg)


@SETTINGS
@given(bad=bad_float, n=st.integers(-2, 1))
def test_via_points_bad_inputs(bad, n):
    from anthroarm.trajectory.via_points import ViaPointTrajectory

    typed_or_finite(ViaPointTrajectory, [0.0, bad, 2.0], np.zeros((3, 2)))
    typed_or_finite(ViaPointTrajectory, [0.0, 1.0, 2.0], np.full((3, 2), bad))
    typed_or_finite(ViaPointTrajectory, np.arange(max(n, 0), dtype=float), np.zeros((max(n, 0), 2)))
    tr = ViaPointTrajectory([0.0, 1.0, 2.0], np.zeros((3, 2)))
    typed_or_finite(tr, bad)
    typed_or_finite(tr, 0.5, derivative=n - 2)
