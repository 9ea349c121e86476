"""Fast paths of the QP step against the general code they replace.

Oracles: the tasks' own ``compute_qp_objective`` (and Task._objective on compute_jacobian /
compute_error), ``limits.combine``, ``quadprog.solve_qp`` called on the general assembly, and
the checked path of ``targets.as_se3``.
"""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik import qp
from anthroarm.ik.qp import _qpgen2
from anthroarm.ik.qp.limits.base import BIG, combine, combine_into
from anthroarm.ik.qp.step import _Workspace
from anthroarm.ik.qp.targets import as_rigid, as_se3

BACKENDS = ["osqp", "daqp", "quadprog", "proxqp"]


@pytest.fixture(scope="module")
def panda():
    return aa.load("panda")


@pytest.fixture(scope="module")
def human():
    return aa.load("human_arm7")


def _accumulated(tasks, conf):
    ws = _Workspace(conf.nv)
    ws.Hc[:] = np.nan  # the first task must overwrite, not add
    diag = 0.0
    for k, t in enumerate(tasks):
        diag += t._accumulate(conf, ws, k == 0)
    ws.Hd[:] += diag
    return ws.H.copy(), ws.c.copy()


def _summed(tasks, conf):
    H = np.zeros((conf.nv, conf.nv))
    c = np.zeros(conf.nv)
    for t in tasks:
        Ht, ct = t.compute_qp_objective(conf)
        H += Ht
        c += ct
    return H, c


class _MyFrameTask(qp.FrameTask):
    """A subclass that changes the objective: the in-place path must not bypass it."""

    def compute_qp_objective(self, conf):
        H, c = super().compute_qp_objective(conf)
        return 2.0 * H, 3.0 * c


def _task_zoo(robot, rng):
    qa, qb = robot.random_q(2, rng=rng)
    T = robot.fk(qb)
    root = robot.frame_names[len(robot.frame_names) // 2]
    conf_b = qp.IKConfiguration(robot, qb)
    rel = qp.RelativeFrameTask(robot, robot.tool, root, position_cost=0.7, lm_damping=1e-2)
    rel.set_target_from_configuration(conf_b)
    w = rng.uniform(0.1, 2.0, robot.nv)
    tasks = [
        qp.FrameTask(robot, target=T),  # W = I
        qp.FrameTask(
            robot, position_cost=0.4, orientation_cost=0.4, lm_damping=1e-3, gain=0.6, target=T
        ),
        qp.FrameTask(
            robot, position_cost=[1.0, 0.5, 2.0], orientation_cost=0.3, lm_damping=1e-2, target=T
        ),
        _MyFrameTask(robot, lm_damping=1e-3, target=T),
        qp.PostureTask(robot, cost=1e-3, target=qb),
        qp.PostureTask(robot, cost=w, gain=0.5, target=qb),
        qp.PostureTask(robot, cost=0.2, lm_damping=0.3, target=qb),
        qp.DampingTask(0.05),
        qp.DampingTask(w),
        qp.PositionTask(robot, cost=[1.0, 0.0, 2.0], target=T[:3, 3]),
        qp.OrientationTask(robot, cost=0.5, lm_damping=1e-3, target=T[:3, :3]),
        rel,
        qp.JointCouplingTask(robot, robot.joint_names[:2], [1.0, -2.0], offset=0.1),
    ]
    return qa, tasks


@pytest.mark.parametrize("name", ["panda", "human_arm7", "ur5"])
def test_in_place_objectives_equal_compute_qp_objective(name):
    """Every task alone, first or after another, and all together: the in-place sum equals the
    sum of compute_qp_objective (1e-14 relative)."""
    robot = aa.load(name)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, tasks = _task_zoo(robot, rng)
        conf = qp.IKConfiguration(robot, q)
        lead = qp.PostureTask(robot, cost=0.1, target=robot.random_q(rng=rng))
        for group in [[t] for t in tasks] + [[lead, t] for t in tasks] + [tasks]:
            Ha, ca = _accumulated(group, conf)
            Hs, cs = _summed(group, conf)
            scale = 1.0 + np.abs(Hs).max() + np.abs(cs).max()
            assert np.abs(Ha - Hs).max() <= 1e-14 * scale, group
            assert np.abs(ca - cs).max() <= 1e-14 * scale, group


def test_duck_typed_task_still_accepted(panda):
    """An object with compute_qp_objective only (not a Task subclass) is summed as before."""
    rng = np.random.default_rng(12)
    q, qt = panda.random_q(2, rng=rng)
    post = qp.PostureTask(panda, cost=0.1, target=qt)

    class Duck:
        def compute_qp_objective(self, conf):
            return post.compute_qp_objective(conf)

    conf = qp.IKConfiguration(panda, q)
    v1 = qp.step(conf, None, [Duck()], 0.01, solver="daqp")
    v2 = qp.step(conf, None, [post], 0.01, solver="daqp")
    assert np.abs(v1 - v2).max() < 1e-12


def test_frame_task_weights_follow_reassigned_cost_and_gain(panda):
    """Oracle: Task._objective on compute_jacobian / compute_error (the unspecialised formula)."""
    rng = np.random.default_rng(2)
    q, qt = panda.random_q(2, rng=rng)
    conf = qp.IKConfiguration(panda, q)
    t = qp.FrameTask(panda, lm_damping=1e-2, target=panda.fk(qt))
    _accumulated([t], conf)  # caches the weights of cost 1, gain 1
    t.gain = 0.3
    t.cost = np.array([0.5, 1.0, 2.0, 0.1, 0.2, 0.3])
    J, e = t.compute_jacobian(conf), t.compute_error(conf)
    H_ref, c_ref = t._objective(J, e, panda.nv)
    for H, c in (t.compute_qp_objective(conf), _accumulated([t], conf)):
        assert np.abs(H - H_ref).max() < 1e-12 and np.abs(c - c_ref).max() < 1e-12


def _box_cases(robot, rng):
    q_in = robot.random_q(rng=rng, margin=0.05)
    q_above = q_in.copy()
    q_above[1] = robot.upper[1] + 0.3
    q_below = q_in.copy()
    q_below[0] = robot.lower[0] - 0.2
    q_edge = q_in.copy()
    q_edge[2] = robot.upper[2]
    lo_inf = robot.lower.copy()
    lo_inf[3] = -np.inf
    v_inf = robot.velocity_limit.copy()
    v_inf[4] = np.inf
    lim_sets = [
        [qp.ConfigurationLimit(robot), qp.VelocityLimit(robot)],
        [qp.VelocityLimit(robot), qp.ConfigurationLimit(robot, gain=0.3)],
        [qp.ConfigurationLimit(robot, gain=1.0)],
        [
            qp.ConfigurationLimit(robot, gain=0.5, lower=lo_inf),
            qp.VelocityLimit(robot, v_max=v_inf),
        ],
        [qp.VelocityLimit(robot, v_max=np.full(robot.nv, np.inf))],
        [
            qp.ConfigurationLimit(robot),
            qp.VelocityLimit(robot),
            qp.AccelerationLimit(robot, a_max=2.0),
        ],
        [],
    ]
    acc = lim_sets[5][2]
    acc.reset(rng.uniform(-1, 1, robot.nv))
    return [q_in, q_above, q_below, q_edge], lim_sets


@pytest.mark.parametrize("name", ["panda", "human_arm7"])
def test_in_place_box_equals_combine(name):
    """combine_into gives combine()'s box bit for bit (±inf read as ±BIG): inside the limits,
    outside them (start-outside branch), at a limit, with unbounded joints, an acceleration limit
    whose box may exclude 0, no limits, and gains that are and are not powers of two."""
    robot = aa.load(name)
    rng = np.random.default_rng(8)
    qs, lim_sets = _box_cases(robot, rng)
    ws = _Workspace(robot.nv)
    for q in qs:
        conf = qp.IKConfiguration(robot, q)
        for lims in lim_sets:
            for dt in (0.01, 0.3):
                ws.B[:] = np.nan
                combine_into(lims, conf, dt, ws)
                lo, hi = combine(lims, conf, dt)
                assert np.array_equal(ws.lo, np.clip(lo, -BIG, BIG)), (lims, q)
                assert np.array_equal(ws.hi, np.clip(hi, -BIG, BIG)), (lims, q)
                assert np.array_equal(ws.B[robot.nv :], -ws.hi)


def test_in_place_box_skips_combine_inside_the_limits(panda, monkeypatch):
    """Inside the limits the default pair takes the in-place path (combine() is not called);
    outside them it is."""
    from anthroarm.ik.qp.limits import base

    calls = []
    real = base.combine
    monkeypatch.setattr(base, "combine", lambda *a: calls.append(1) or real(*a))
    ws = _Workspace(panda.nv)
    q = panda.random_q(rng=0, margin=0.05)
    combine_into(qp.default_limits(panda), qp.IKConfiguration(panda, q), 0.01, ws)
    assert calls == []
    q[3] = panda.upper[3] + 0.1
    combine_into(qp.default_limits(panda), qp.IKConfiguration(panda, q), 0.01, ws)
    assert calls == [1]


def test_velocity_limit_cache_follows_v_max_and_dt(panda):
    lim = qp.VelocityLimit(panda)
    conf = qp.IKConfiguration(panda)
    with pytest.raises(ValueError):
        lim.v_max[0] = 1.0  # read-only: replace it instead
    ws = _Workspace(panda.nv)
    for v_max, dt in [(None, 0.01), (None, 0.02), (np.full(7, 0.5), 0.02)]:
        if v_max is not None:
            lim.v_max = v_max
        combine_into([lim], conf, dt, ws)
        assert np.array_equal(ws.hi, lim.v_max * dt) and np.array_equal(ws.lo, -lim.v_max * dt)


def test_as_se3_fast_path_equals_checked_path(panda):
    rng = np.random.default_rng(4)
    for q in panda.random_q(20, rng=rng):
        T = panda.fk(q)
        M = as_se3(T)
        assert np.array_equal(M.rotation, T[:3, :3]) and np.array_equal(M.translation, T[:3, 3])
        # same answer from a pin.SE3 input (the checked path)
        M2 = as_se3(pin.SE3(T[:3, :3].copy(), T[:3, 3].copy()))
        assert np.array_equal(M.homogeneous, M2.homogeneous)
    # within the rigid tolerance but not orthonormal to 1e-12: re-orthonormalised
    T = panda.fk(panda.neutral())
    T[:3, :3] *= 1.0 + 1e-9
    R = as_se3(T).rotation
    assert np.abs(R @ R.T - np.eye(3)).max() < 1e-14
    # bad inputs still raise
    bad = panda.fk(panda.neutral())
    for k, v in [((0, 0), np.nan), ((1, 3), np.inf), ((3, 0), 0.5)]:
        B = bad.copy()
        B[k] = v
        with pytest.raises(ValueError):
            as_se3(B)
    refl = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="not a rotation"):
        as_se3(refl)
    assert np.array_equal(as_se3(np.eye(4, dtype=int)).homogeneous, np.eye(4))


def test_as_rigid_is_as_se3_as_an_array(panda):
    """``as_rigid`` (the pose targets of ``aa.ik.solve``) gives the matrix of ``as_se3`` as a
    C-order float array: the same checks, the same re-orthonormalisation, never the caller's
    array."""
    T = panda.fk(panda.random_q(rng=5))
    H = as_rigid(T)
    assert H is not T and H.flags.c_contiguous and np.array_equal(H, T)
    Tf = np.asfortranarray(T)
    assert as_rigid(Tf).flags.c_contiguous and np.array_equal(as_rigid(Tf), T)
    T2 = T.copy()
    T2[:3, :3] *= 1.0 + 1e-9
    assert np.array_equal(as_rigid(T2), as_se3(T2).homogeneous)
    assert np.abs(as_rigid(T2)[:3, :3] @ as_rigid(T2)[:3, :3].T - np.eye(3)).max() < 1e-14
    with pytest.raises(ValueError, match="not a rotation"):
        as_rigid(np.diag([1.0, 1.0, -1.0, 1.0]))


def _random_box_qp(rng, n, active=True):
    J = rng.normal(size=(6, n))
    H = J.T @ J + rng.choice([1e-6, 1e-3, 1.0]) * np.eye(n)
    c = rng.normal(size=n) * (1.0 if active else 1e-3)
    lo = -rng.random(n) * 0.5 - 0.01
    hi = rng.random(n) * 0.5 + 0.01
    return H, c, lo, hi


def test_quadprog_direct_call_is_bit_identical():
    n = 7
    box = _qpgen2.make(n)
    if box is None:
        pytest.skip("direct qpgen2_ call not available for this quadprog build")
    import quadprog

    rng = np.random.default_rng(9)
    C = np.hstack([np.eye(n), -np.eye(n)])
    for _ in range(300):
        H, c, lo, hi = _random_box_qp(rng, n)
        B = np.concatenate([lo, -hi])
        rc, x = box.solve(H, c, B)
        assert rc == 0
        assert np.array_equal(x, quadprog.solve_qp(H, -c, C, B, 0)[0])


def _ws_from(H, c, lo, hi):
    ws = _Workspace(len(c))
    ws.H[:] = H
    ws.c[:] = c
    ws.B[: len(c)] = lo
    ws.B[len(c) :] = -hi
    ws.hi[:] = hi
    return ws


@pytest.mark.parametrize("solver", BACKENDS)
def test_solve_ws_matches_dense_reference(solver):
    """The workspace entry of every backend (persistent/warm-started paths included) against
    quadprog.solve_qp, on a sequence of random QPs and on a slowly varying one."""
    import quadprog

    n = 7
    rng = np.random.default_rng(10)
    be = qp.make_backend(solver, n)
    C = np.hstack([np.eye(n), -np.eye(n)])
    H0, c0, lo0, hi0 = _random_box_qp(rng, n)
    seq = [_random_box_qp(rng, n, active=k % 3 != 0) for k in range(120)]
    seq += [(H0 + 0.01 * k * np.eye(n), c0 * np.cos(0.05 * k), lo0, hi0) for k in range(60)]
    for H, c, lo, hi in seq:
        x, status = be.solve_ws(_ws_from(H, c, lo, hi))
        ref = quadprog.solve_qp(H, -c, C, np.concatenate([lo, -hi]), 0)[0]
        assert status == "optimal"
        assert np.abs(x - ref).max() < 1e-8, (solver, np.abs(x - ref).max())
        assert np.all(x >= lo) and np.all(x <= hi)


def test_quadprog_singular_hessian_falls_back(panda):
    """A positive semi-definite H (no damping, one task of rank 6 < 7): the direct call reports
    it and the backend retries with a tiny Tikhonov term, as solve() does."""
    conf = qp.IKConfiguration(panda, panda.random_q(rng=3, margin=0.1))
    ee = qp.FrameTask(panda, target=panda.fk(panda.random_q(rng=4)))
    out = qp.step(conf, None, [ee], 0.01, solver="quadprog", damping=0.0, full=True)
    assert out.ok and np.all(np.isfinite(out.v))


@pytest.mark.parametrize("name", ["panda", "human_arm7", "ur5"])
def test_step_equals_general_assembly(name):
    """qp.step (in-place assembly, in-place box, direct solver calls) against the general
    pieces: Σ compute_qp_objective + damping, combine(), and quadprog.solve_qp; from inside and
    from outside the limits."""
    import quadprog

    robot = aa.load(name)
    rng = np.random.default_rng(6)
    n = robot.nv
    C = np.hstack([np.eye(n), -np.eye(n)])
    lims = qp.default_limits(robot)
    for k in range(8):
        q, qt = robot.random_q(2, rng=rng)
        if k % 4 == 3:
            q = q.copy()
            q[k % n] = robot.upper[k % n] + 0.2
        conf = qp.IKConfiguration(robot, q)
        tasks = [
            qp.FrameTask(
                robot,
                lm_damping=1e-3,
                position_cost=[1.0, 1.0, 0.5],
                target=robot.fk(q + 0.1 * (qt - q)),
            ),
            qp.PostureTask(robot, cost=1e-2, target=qt),
        ]
        H, c = _summed(tasks, conf)
        H += 1e-12 * np.eye(n)
        lo, hi = combine(lims, conf, 0.01)
        ref = quadprog.solve_qp(H, -c, C, np.concatenate([lo, -hi]), 0)[0] / 0.01
        for solver in BACKENDS:
            v = qp.step(conf, None, tasks, 0.01, solver=solver)
            assert np.abs(v - ref).max() * 0.01 < 1e-9, (solver, np.abs(v - ref).max())


def test_returned_arrays_are_not_reused(panda):
    conf = qp.IKConfiguration(panda, panda.random_q(rng=1, margin=0.1))
    ee = qp.FrameTask(panda, target=panda.fk(panda.random_q(rng=2)), lm_damping=1e-3)
    for solver in BACKENDS:
        out = qp.step(conf, None, [ee], 0.01, solver=solver, full=True)
        v1, lo1 = out.v.copy(), out.lo.copy()
        conf.integrate_inplace(out.v, 0.01)
        qp.step(conf, None, [ee], 0.01, solver=solver, full=True)
        assert np.array_equal(out.v, v1) and np.array_equal(out.lo, lo1)
    # no limits: the StepResult box is ±inf, as combine() gives it
    out = qp.step(conf, None, [ee], 0.01, limits=None, full=True)
    assert np.all(out.lo == -np.inf) and np.all(out.hi == np.inf)


@pytest.mark.parametrize("name", ["panda", "human_arm7"])
def test_osqp_steps_print_nothing(name, capfd):
    """OSQP's C polish prints 'Polishing not needed' on stdout even with verbose=False when it
    runs without an active set; the backend keeps OSQP's polishing off (and polishes itself)."""
    robot = aa.load(name)
    conf = qp.IKConfiguration(robot, robot.random_q(rng=0, margin=0.1))
    ee = qp.FrameTask(robot, lm_damping=1e-3, target=robot.fk(robot.random_q(rng=1)))
    for _ in range(40):
        v = qp.step(conf, None, [ee, qp.PostureTask(robot, cost=1e-3)], 0.01, solver="osqp")
        conf.integrate_inplace(v, 0.01)
    be = conf._qp_state["backends"][("osqp", robot.nv, 0)]
    assert be.settings["polishing"] is False and be.settings["verbose"] is False
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def _circle_steps(robot, solver, n_steps, check):
    """The benchmark's tracking loop (frame + posture 1e-3, default limits, 5 cm circle); calls
    ``check(conf, out)`` after every step with the QP of that step still in the workspace."""
    q0 = robot.random_q(rng=7, margin=0.1)
    T0 = robot.fk(q0)
    conf = qp.IKConfiguration(robot, q0)
    ee = qp.FrameTask(robot, lm_damping=1e-3)
    post = qp.PostureTask(robot, cost=1e-3, target=q0)
    for k in range(n_steps):
        T = T0.copy()
        a = 2 * np.pi * k / 200.0
        T[:3, 3] += 0.05 * np.array([np.cos(a) - 1.0, np.sin(a), 0.0])
        ee.set_target(T)
        out = qp.step(conf, None, [ee, post], 0.01, solver=solver, full=True)
        check(conf, out)
        conf.integrate_inplace(out.v, 0.01)


def test_osqp_matches_dense_along_human_trajectory(human):
    """On human_arm7 (a bound active in most steps, H eigenvalues down to 1e-6) ADMM alone was
    up to 1e-5 off quadprog at eps 1e-11; with the certified polish every step is within 1e-10."""
    ref = qp.make_backend("quadprog", human.nv)
    errs = []

    def check(conf, out):
        ws = conf._qp_state["ws"]
        x, _ = ref.solve(ws.H, ws.c, ws.lo, ws.hi)
        errs.append(np.abs(out.v * 0.01 - x).max())
        assert out.ok and out.info["polished"]

    _circle_steps(human, "osqp", 120, check)
    assert max(errs) < 1e-10


def test_osqp_without_certificate_tightens_and_restores(human, monkeypatch):
    """When the polish finds no certificate, ADMM continues to eps 1e-11 and its x is used; the
    workspace returns to the box tolerance afterwards."""
    from anthroarm.ik.qp import backends

    monkeypatch.setattr(backends, "polish_box", lambda *a: None)
    ref = qp.make_backend("quadprog", human.nv)
    seen = []

    def check(conf, out):
        ws = conf._qp_state["ws"]
        be = conf._qp_state["backends"][("osqp", human.nv, 0)]
        assert out.ok and out.info["polished"] is False
        assert be.solver.settings.eps_abs == be.EPS_BOX
        assert np.all(out.v * 0.01 >= out.lo) and np.all(out.v * 0.01 <= out.hi)
        x, _ = ref.solve(ws.H, ws.c, ws.lo, ws.hi)
        seen.append(np.abs(out.v * 0.01 - x).max())

    _circle_steps(human, "osqp", 30, check)
    assert max(seen) < 1e-4  # ADMM's own accuracy at eps 1e-11 (the pre-polish behaviour)
