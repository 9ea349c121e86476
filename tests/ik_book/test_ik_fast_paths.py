"""The fast paths of the closed-form IK against the general path (ik/closed_form.py).

Four implementations of the same formulas: the general vectorised path (the reference,
``_impl="general"``), the structure-of-arrays numpy kernels (batched, ``_impl="python"``), the
scalar ``math`` kernels (single pose, ``_impl="python"``) and the optional compiled kernel
(``_impl="c"``, skipped without a C compiler).  On thousands of poses per arm — reachable ones,
poses whose configurations break the joint limits, unreachable ones, singular ones — every fast
path must return the same branches, the same solutions (to rounding), the same reasons and the
same singularity notes as the general path, and its solutions must reproduce the pose under
Pinocchio's FK.  Expected values come from Pinocchio and the general path, never from the path
under test.  Also: the generated FK against Pinocchio, cos/sin from tan(q/2) against numpy, and
the fallback when no compiler is usable."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.ik import analytic_c
from anthroarm.ik.analytic_plan import plan_for
from anthroarm.ik import swivel_angle
from anthroarm.ik.closed_form import analytic, analytic_batch
from anthroarm.ik.fk_codegen import FKStages, cos_sin

HAS_CC = analytic_c.compiler() is not None and analytic_c.enabled()
needs_cc = pytest.mark.skipif(not HAS_CC, reason="compiled kernel unavailable (no C compiler, or ANTHROARM_IK_C=0); "
                                                  "it is optional")
IMPLS = ["python", pytest.param("c", marks=needs_cc)]

ARMS = {
    "sixr_arm": {},
    "prosthetic_arm": {},
    "human_arm7": {},
    "planar2r": {},
    "sixr_arm:custom": dict(s0=0.3, h2=0.55, s3=0.25, P=0.05),
    "prosthetic_arm:caption": dict(L2=0.240),
    "human_arm7:female": dict(height=1.60, mass=55.0, sex="female"),
}
N_REACH = 2000
SOL_ATOL = 1e-7   # the paths round differently (numpy's SIMD atan2/asin/acos vs libm: 1 ulp)
NEAR_ATOL = 1e-5  # 1e-4 rad from a singularity the rounding is amplified ~1e10 (θ3, θ5 of the prosthetic arm)
REGULAR, NEAR, SINGULAR = 0, 1, 2
SINGULAR_AGREE = 0.95  # fraction of exactly singular poses on which the paths agree about success


def _load(key):
    return aa.load(key.split(":")[0], **ARMS[key])


def _special_q(name, robot, rng, n):
    """(near-singular, exactly singular) configurations of each arm, n of each."""
    near, sing = robot.random_q(n, rng), robot.random_q(n, rng)
    h = n // 2
    if name == "sixr_arm":
        near[:h, 4] = 1e-5                               # close to the wrist singularity
        near[h:, 2] = np.pi / 2 - 1e-4                   # elbow nearly stretched
        sing[:h, 4] = 0.0                                # wrist: sin θ5 = 0
        sing[h:, 2] = np.pi / 2                          # stretched: the elbow branches coincide
    elif name == "prosthetic_arm":
        near[:, 3] = 1e-4                                # elbow nearly straight (ill-conditioned)
        sing[:h, 3] = 0.0                                # straight elbow
        sing[h:, 1] = 0.0                                # upper arm vertical (θ1 free)
    elif name == "human_arm7":
        near[:h, 3] = 1e-4
        near[h:, 1] = np.pi / 2 - 1e-5                   # close to the shoulder gimbal lock
        sing[:h, 3] = 0.0                                # straight elbow
        sing[h:, 1] = -np.pi / 2                         # gimbal lock of the shoulder Euler angles
    else:
        near[:, 1] = 1e-4
        sing[:, 1] = 0.0                                 # stretched: the two elbow branches coincide
    return near, sing


def _poses(key, robot, seed):
    """(T, swivel, kind) for a mixed set of poses: reachable, limit-breaking, near-singular,
    exactly singular, reachable positions with random orientations, unreachable; ``kind`` marks
    REGULAR / NEAR / SINGULAR poses."""
    name = robot.spec.name
    rng = np.random.default_rng(seed)
    near, sing = _special_q(name, robot, rng, 200)
    Q = np.concatenate([robot.random_q(N_REACH, rng),
                        rng.uniform(-np.pi, np.pi, (400, robot.nq)),     # often outside the limits
                        near, sing])
    kind = np.full(len(Q), REGULAR)
    kind[-len(sing) - len(near):-len(sing)] = NEAR
    kind[-len(sing):] = SINGULAR
    T = robot.fk(Q)
    sw = swivel_angle(robot, Q) if name == "human_arm7" else None
    # random orientations at reachable positions (prosthetic arm: the elbow plane may miss)
    m = 200
    R = np.linalg.qr(rng.normal(size=(m, 3, 3)))[0]
    R *= np.sign(np.linalg.det(R))[:, None, None]
    Tr = T[:m].copy()
    Tr[:, :3, :3] = R
    # unreachable: far away
    Tf = T[:50].copy()
    Tf[:, :3, 3] *= 10.0
    T = np.concatenate([T, Tr, Tf])
    kind = np.concatenate([kind, np.full(m + 50, REGULAR)])
    if name == "planar2r":
        T[-20:, 0, 3] = 0.3                                            # out of the mechanism plane
    if sw is not None:
        sw = np.concatenate([sw, sw[:m], sw[:50]])
    return T, sw, kind


def _assert_same_batch(a, g, robot, atol=SOL_ATOL):
    assert a.branches == g.branches
    np.testing.assert_array_equal(a.valid, g.valid)
    np.testing.assert_allclose(a.solutions, g.solutions, rtol=0, atol=atol)         # NaN where invalid
    assert a.reasons == g.reasons
    assert a.singular == g.singular
    if g.swivel is not None:
        np.testing.assert_allclose(a.swivel, g.swivel, rtol=0, atol=0)
    assert np.nanmax(a.residuals, initial=0.0) <= 1e-9


def _assert_pin_fk(robot, res, T, rows, tol):
    """Every solution returned for poses ``rows`` inside the limits and FK(q) = T (Pinocchio)
    to ``tol`` (1e-10 for regular poses, the round-trip goal of the issue; near singular poses
    only the analytic's own check ``tol`` = 1e-9 holds)."""
    i, b = np.nonzero(res.valid & rows[:, None])
    S = res.solutions[i, b]
    assert robot.within_limits(S).all()
    cols = slice(3, 4) if robot.spec.name == "planar2r" else slice(0, 4)
    assert np.abs(robot.fk(S)[:, :3, cols] - T[i, :3, cols]).max(initial=0.0) <= tol


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("key", list(ARMS))
def test_batch_fast_path_equals_general(key, impl):
    """Same branches, validity, solutions, reasons and notes as the general path; on exactly
    singular poses (measure zero: a stretched elbow puts sin θ3 or cos θ4 at ±1 up to the last
    bit, where the rounding of each implementation decides whether two nearly coincident roots
    or one double root come out, and a straight elbow leaves θ3 ± θ5 free) Pinocchio-exact
    solutions, not necessarily the same list — and nearly always the same
    success: where θ3 ± θ5 is free, the representative picked from rounding noise may lie inside
    the joint limits in one path and outside in the other)."""
    robot = _load(key)
    T, sw, kind = _poses(key, robot, 11)
    kw = {} if sw is None else {"swivel": sw}
    g = analytic_batch(robot, T, _impl="general", **kw)
    a = analytic_batch(robot, T, _impl=impl, **kw)
    for k, atol in ((REGULAR, SOL_ATOL), (NEAR, NEAR_ATOL)):
        sel = np.flatnonzero(kind == k)
        kws = {} if sw is None else {"swivel": sw[sel]}
        _assert_same_batch(analytic_batch(robot, T[sel], _impl=impl, **kws),
                           analytic_batch(robot, T[sel], _impl="general", **kws), robot, atol)
    # the test set exercises every outcome
    assert g.valid[kind == REGULAR].any(1).mean() > 0.5
    assert any(r is not None for r in g.reasons)
    singular = kind == SINGULAR
    # singular poses: (almost always) the same success, every solution exact
    assert (a.valid[singular].any(1) == g.valid[singular].any(1)).mean() >= SINGULAR_AGREE
    _assert_pin_fk(robot, a, T, kind == REGULAR, 1e-10)
    _assert_pin_fk(robot, a, T, kind != REGULAR, 1e-9)


@pytest.mark.parametrize("impl", IMPLS)
def test_human_swivel_grid_fast_path(impl):
    """A grid of swivel angles per pose (N, S) and the default grid: labels, swivels, solutions."""
    robot = aa.load("human_arm7")
    rng = np.random.default_rng(5)
    T = robot.fk(robot.random_q(100, rng))
    grid = np.linspace(-np.pi, np.pi, 12, endpoint=False)[None, :]
    for kw in ({"swivel": grid}, {}):
        g = analytic_batch(robot, T, _impl="general", **kw)
        a = analytic_batch(robot, T, _impl=impl, **kw)
        _assert_same_batch(a, g, robot)
    one = analytic(robot, T[0], _impl=impl)                  # single pose, default grid of 36
    ref = analytic(robot, T[0], _impl="general")
    assert one.branches == ref.branches and len(one.branches) > 8
    np.testing.assert_allclose(one.solutions, ref.solutions, atol=SOL_ATOL)
    np.testing.assert_array_equal(one.swivel, ref.swivel)


def _assert_same_single(a, g, atol=SOL_ATOL):
    assert a.branches == g.branches
    assert a.reason == g.reason
    assert a.singular == g.singular
    assert a.solutions.shape == g.solutions.shape
    np.testing.assert_allclose(a.solutions, g.solutions, rtol=0, atol=atol)
    assert (a.swivel is None) == (g.swivel is None)
    if a.swivel is not None:
        np.testing.assert_array_equal(a.swivel, g.swivel)
    assert len(a.residuals) == len(a.branches) and (a.residuals <= 1e-9).all()


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("key", list(ARMS))
def test_single_fast_path_equals_general(key, impl):
    """As the batch test, one pose at a time (exactly singular poses: same success, exact FK)."""
    robot = _load(key)
    T, sw, kind = _poses(key, robot, 12)
    rng = np.random.default_rng(3)
    idx = np.concatenate([rng.choice(N_REACH, 150, replace=False), np.arange(N_REACH, len(T))[::4]])
    cols = slice(3, 4) if robot.spec.name == "planar2r" else slice(0, 4)
    agree = []
    for k in idx:
        kw = {} if sw is None else {"swivel": float(sw[k])}
        a = analytic(robot, T[k], _impl=impl, **kw)
        g = analytic(robot, T[k], _impl="general", **kw)
        if kind[k] == SINGULAR:
            agree.append(a.success == g.success)
            if a.success:
                assert robot.within_limits(a.solutions).all()
                assert np.abs(robot.fk(a.solutions)[:, :3, cols] - T[k, :3, cols]).max() <= 1e-9
        else:
            _assert_same_single(a, g, SOL_ATOL if kind[k] == REGULAR else NEAR_ATOL)
    assert np.mean(agree) >= SINGULAR_AGREE


@pytest.mark.parametrize("impl", IMPLS)
def test_fast_paths_bad_input(impl):
    """Malformed poses reach the general path's ValueError (the fast paths defer to it)."""
    robot = aa.load("sixr_arm")
    T = robot.fk(robot.neutral())
    bad = T.copy()
    bad[1, 2] = np.nan
    skew = T.copy()
    skew[:3, :3] *= 1.01
    mirror = T.copy()
    mirror[:3, 0] *= -1
    lastrow = T.copy()
    lastrow[3, 0] = 0.1
    for P, msg in ((bad, "not finite"), (skew, "rotation"), (mirror, "rotation"), (lastrow, "last row")):
        with pytest.raises(ValueError, match=msg):
            analytic(robot, P, _impl=impl)
        with pytest.raises(ValueError, match=msg):
            analytic_batch(robot, np.stack([T, P, T]), _impl=impl)
    with pytest.raises(ValueError, match="swivel"):
        analytic(aa.load("human_arm7"), np.eye(4), swivel=np.nan, _impl=impl)


def test_generated_fk_matches_pinocchio():
    """The verification FK (scalar math and numpy forms) against Pinocchio's FK, including
    angles near ±π and the position-only form."""
    for name, splits in (("sixr_arm", (1, 3)), ("prosthetic_arm", (2,)), ("human_arm7", (4,)), ("planar2r", ())):
        robot = aa.load(name)
        rng = np.random.default_rng(1)
        Q = rng.uniform(-np.pi, np.pi, (300, robot.nq))
        Q[:30] = np.pi - rng.uniform(0, 1e-9, (30, robot.nq))
        Q[30:60] = -np.pi
        T = robot.fk(Q)
        Tq = robot.fk(Q + 1e-7)                                  # a wrong target must be detected
        bounds = [0, *splits, robot.nq]
        for po in (False, True):
            fk = FKStages(robot.chain, splits, position_only=po)
            rows = tuple(T[:, i, j] for i in range(3) for j in range(4))
            st = None
            for k, f in enumerate(fk.numpy):
                args = [Q[:, j] for j in range(bounds[k], bounds[k + 1])]
                args = ([st] if k else []) + args + ([rows] if k == fk.n_stages - 1 else [])
                st = f(*args)
            assert st.max() < 1e-14
            for q, Tk, Tw in zip(Q[:40], T[:40], Tq[:40]):
                for target, small in ((Tk, True), (Tw, False)):
                    st = None
                    rows = tuple(target[:3].ravel().tolist())
                    for k, f in enumerate(fk.scalar):
                        args = list(q[bounds[k]:bounds[k + 1]])
                        args = ([st] if k else []) + args + ([rows] if k == fk.n_stages - 1 else [])
                        st = f(*args)
                    assert (st < 1e-14) if small else (st > 1e-9)


@needs_cc
@pytest.mark.parametrize("name", ["sixr_arm", "prosthetic_arm", "human_arm7", "planar2r"])
def test_compiled_fk_check_matches_pinocchio(name):
    """The compiled FK check returns Pinocchio's max |FK(q) − T| for right and wrong targets."""
    robot = aa.load(name)
    kern = analytic_c.kernel_for(plan_for(robot))
    rng = np.random.default_rng(8)
    Q = rng.uniform(-np.pi, np.pi, (200, robot.nq))
    T = robot.fk(Q)
    Tw = robot.fk(Q + rng.normal(scale=1e-3, size=Q.shape))
    for q, Tk, Tx in zip(Q, T, Tw):
        assert kern.fk_residual(q, Tk) < 1e-14
        assert kern.fk_residual(q, Tk, position_only=True) < 1e-14
        np.testing.assert_allclose(kern.fk_residual(q, Tx), np.abs(Tk[:3] - Tx[:3]).max(), rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(kern.fk_residual(q, Tx, position_only=True), np.abs(Tk[:3, 3] - Tx[:3, 3]).max(),
                                   rtol=1e-9, atol=1e-15)


def test_cos_sin_half_angle_tangent():
    rng = np.random.default_rng(0)
    q = np.concatenate([rng.uniform(-10, 10, 200000), np.pi + rng.uniform(-1e-6, 1e-6, 1000),
                        -np.pi + rng.uniform(-1e-12, 1e-12, 1000), rng.uniform(-1e-9, 1e-9, 1000),
                        [0.0, np.pi, -np.pi, np.pi / 2, 3 * np.pi, -0.0]])
    c, s = cos_sin(q)
    assert np.abs(c - np.cos(q)).max() < 5e-16
    assert np.abs(s - np.sin(q)).max() < 5e-16


@needs_cc
def test_compiled_kernel_is_used_and_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path))
    robot = aa.load("sixr_arm", s0=0.45)                     # a fresh parameterisation
    plan = plan_for(robot)
    assert plan.c_kernel is None
    T = robot.fk(robot.random_q(3, np.random.default_rng(0)))
    res = analytic(robot, T[0])
    assert isinstance(plan.c_kernel, analytic_c.CKernel)
    assert list((tmp_path / "ik").glob("analytic_sixr_arm_*.so"))
    np.testing.assert_allclose(robot.fk(res.solutions)[:, :3], np.broadcast_to(T[0, :3], (len(res), 3, 4)), atol=1e-12)


def test_fallback_without_compiler(monkeypatch):
    """No usable compiler: the pure-Python kernels answer, with the same results; _impl="c"
    then raises."""
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("ANTHROARM_IK_C", "1")
    robot = aa.load("prosthetic_arm", L3=0.12)               # a fresh parameterisation
    T = robot.fk(robot.random_q(50, np.random.default_rng(2)))
    g = analytic_batch(robot, T, _impl="general")
    _assert_same_batch(analytic_batch(robot, T), g, robot)
    _assert_same_single(analytic(robot, T[0]), g[0])
    assert plan_for(robot).c_kernel is False or analytic_c.compiler() is None
    assert "pure-Python" in analytic_c.status()
    with pytest.raises(RuntimeError, match="unavailable"):
        analytic(robot, T[0], _impl="c")


def test_fallback_when_disabled(monkeypatch):
    monkeypatch.setenv("ANTHROARM_IK_C", "0")
    robot = aa.load("human_arm7")
    q = robot.random_q(None, np.random.default_rng(4))
    T = robot.fk(q)
    res = analytic(robot, T, swivel=swivel_angle(robot, q))
    assert np.abs(res.solutions - q).max(1).min() < 1e-9
    assert analytic_c.kernel_for(plan_for(robot)) is None
    assert "disabled" in analytic_c.status()


@needs_cc
def test_compile_failure_falls_back(monkeypatch, tmp_path):
    """A compiler that fails: status says so, the Python kernels answer."""
    monkeypatch.setenv("CC", "false")
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path))
    robot = aa.load("planar2r", l1=0.9)
    res = analytic(robot, robot.fk(np.array([0.3, 0.4])))
    assert res.success
    assert plan_for(robot).c_kernel is False
    assert "unavailable" in analytic_c.status()


@pytest.mark.parametrize("impl", IMPLS)
@pytest.mark.parametrize("name", ["sixr_arm", "prosthetic_arm", "human_arm7", "planar2r"])
def test_fast_paths_options(name, impl):
    """position_only (both values) and a tolerance that rejects some candidates: same answers."""
    robot = aa.load(name)
    T, sw, kind = _poses(name, robot, 13)
    sel = np.flatnonzero(kind == REGULAR)[::10]
    T = T[sel]
    kw = {} if sw is None else {"swivel": sw[sel]}
    for opts in ({"position_only": True}, {"position_only": False}, {"tol": 2e-16}):
        tiny = "tol" in opts          # residuals at the rounding level land on either side of 2e-16
        g = analytic_batch(robot, T, _impl="general", **opts, **kw)
        a = analytic_batch(robot, T, _impl=impl, **opts, **kw)
        assert a.branches == g.branches
        if tiny:
            assert np.nanmax(a.residuals, initial=0.0) <= 2e-16
            fk_kind = "no candidate passed the FK check"
            for ra, rg in zip(a.reasons, g.reasons):
                if rg is not None and not rg.startswith(fk_kind):
                    assert ra == rg                            # workspace / joint-limit reasons
                assert ra is None or ra == rg or ra.startswith(fk_kind)
            continue
        _assert_same_batch(a, g, robot)
        for k in range(0, len(T), 7):
            kws = {} if sw is None else {"swivel": float(kw["swivel"][k])}
            _assert_same_single(analytic(robot, T[k], _impl=impl, **opts, **kws),
                                analytic(robot, T[k], _impl="general", **opts, **kws))
