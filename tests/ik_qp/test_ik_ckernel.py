"""The compiled attempt kernel of ``aa.ik.solve`` (:mod:`anthroarm.ik.solve.ckernel`) against
its reference, the Python kernel (:func:`anthroarm.ik.solve.kernel.attempt`), and against
Pinocchio (FK, frame Jacobian, log3, log6); and the Python fallback (``ANTHROARM_IK_C=0``, no
compiler)."""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import cache
from anthroarm.ik.solve import ckernel, kernel
from anthroarm.ik.solve.targets import Target
from anthroarm.ik.solve.workspace import workspace

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "foundation"))
from test_chain import USER_URDF  # noqa: E402

HAS_CC = cache.compiler() is not None and ckernel.enabled()
needs_cc = pytest.mark.skipif(
    not HAS_CC, reason="no C compiler (or ANTHROARM_IK_C=0): the Python kernel is used"
)

ROBOTS = [
    ("panda", {}),
    ("kinova", {}),
    ("baxter", {"tool": "l_gripper_r_finger_tip"}),
    ("so101", {"tool": "gripper_frame_link", "locked": ["gripper"]}),
    ("human_arm7", {}),
    ("prosthetic_arm", {}),
    ("user", {"tool": "tool"}),
]
IDS = [n for n, _ in ROBOTS]


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


def _load(name, kw, user_urdf):
    return aa.load(str(user_urdf) if name == "user" else name, **kw)


def _kernel(robot):
    ws = workspace(robot, robot.frame_id(None))
    assert ckernel.ready(ws), ckernel.status()
    return ws, ckernel.kernel_for(ws.sh)


@needs_cc
@pytest.mark.parametrize("name,kw", ROBOTS, ids=IDS)
def test_generated_fk_and_jacobian_equal_pinocchio(name, kw, user_urdf):
    robot = _load(name, kw, user_urdf)
    ws, kern = _kernel(robot)
    sh, fid = ws.sh, ws.fid
    for q in robot.random_q(30, rng=3):
        th = sh.theta(q)
        R, p, J = kern.fk_jacobian(th)
        pin.computeJointJacobians(robot.model, ws.data, sh.q(th))
        M = pin.updateFramePlacement(robot.model, ws.data, fid)
        np.testing.assert_allclose(R, M.rotation, atol=1e-13)
        np.testing.assert_allclose(p, M.translation, atol=1e-13)
        np.testing.assert_allclose(
            J, pin.getFrameJacobian(robot.model, ws.data, fid, pin.LOCAL_WORLD_ALIGNED), atol=1e-13
        )


def _rotations():
    rng = np.random.default_rng(7)
    angles = [
        0.0,
        1e-14,
        1e-10,
        1e-7,
        6e-6,
        1e-5,
        1e-3,
        0.5,
        2.0,
        3.0,
        math.pi - 1e-2,
        math.pi - 1e-3,
        math.pi - 7e-6,
        math.pi - 5e-6,
        math.pi - 1e-8,
        math.pi - 1e-12,
        math.pi,
    ]
    for a in angles:
        for _ in range(20):
            ax = rng.normal(size=3)
            ax /= np.linalg.norm(ax)
            yield pin.exp3(ax * a), rng.normal(size=3)
    for _ in range(200):
        M = pin.SE3.Random()
        yield M.rotation, M.translation
    for k in range(
        3
    ):  # rotations by π about the axes (the singular branch picks the largest diagonal)
        yield pin.exp3(np.eye(3)[k] * math.pi), rng.normal(size=3)


@needs_cc
def test_log3_log6_are_pinocchios():
    ws, kern = _kernel(aa.load("panda"))
    for R, p in _rotations():
        R = np.ascontiguousarray(R)
        np.testing.assert_allclose(kern.log3(R), pin.log3(R), rtol=0, atol=1e-14)
        np.testing.assert_allclose(
            kern.log6(R, p), pin.log6(pin.SE3(R, p)).vector, rtol=0, atol=1e-14
        )


def _targets(robot, sh, mode, rng):
    """Reachable targets, half of them from configurations with joints at their limits."""
    Q = robot.random_q(12, rng=rng)
    Th = sh.theta(Q)
    lo, hi = sh.lo, sh.hi
    for k in range(0, len(Th), 2):
        at = rng.random(sh.n) < 0.4
        Th[k] = np.where(at & np.isfinite(lo), np.where(rng.random(sh.n) < 0.5, lo, hi), Th[k])
    Th = np.where(np.isfinite(Th), Th, 0.0)
    out = []
    for th in Th:
        M = ws_fk(robot, sh, th)
        tgt = (
            M
            if mode == "pose"
            else (M.translation.copy() if mode == "position" else M.rotation.copy())
        )
        out.append((th, Target(mode, tgt, 1e-6, 1e-6)))
    return out


def ws_fk(robot, sh, th):
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, sh.q(th))
    return data.oMf[sh.fid].copy()


@needs_cc
@pytest.mark.parametrize("mode", ["pose", "position", "orientation"])
@pytest.mark.parametrize("name,kw", ROBOTS, ids=IDS)
def test_compiled_attempt_equals_the_python_kernel(name, kw, mode, user_urdf):
    """Same seeds, same target: the same iteration count and converged flag for every attempt,
    the same final and best θ and errors to rounding.  The two FKs and Cholesky factorisations
    differ in the last bits, which an ill-conditioned step (λ ≈ 1e-10 near a singularity) can
    amplify: typically the iterates agree to 1e-15, rarely to 1e-10; at a singular wrist a
    converged θ may drift along the self-motion it does not see (then the poses agree).  Seeds
    near the target (as the seed table gives), far ones, and targets at joint limits (the
    active set)."""
    robot = _load(name, kw, user_urdf)
    ws, _ = _kernel(robot)
    sh = ws.sh
    rng = np.random.default_rng(11)
    diffs, hits, conv = [], 0, 0
    for th_t, tg in _targets(robot, sh, mode, rng):
        seeds = [
            th_t + rng.normal(scale=0.3, size=sh.n),
            sh.lo_s + (sh.hi_s - sh.lo_s) * rng.random(sh.n),
            np.where(rng.random(sh.n) < 0.5, th_t + 0.5, th_t - 0.5),
        ]
        for s in seeds:
            s = np.minimum(np.maximum(s, sh.lo), sh.hi)
            a = kernel.attempt(ws, tg, s.copy(), math.inf)
            b = ckernel.attempt(ws, tg, s.copy(), math.inf)
            assert (a[1], a[2]) == (b[1], b[2]), (a, b)
            d = max(np.abs(a[0] - b[0]).max(), np.abs(a[5] - b[5]).max())
            if d > 1e-9:  # a singular configuration's self-motion: the same pose
                for x, y in ((a[0], b[0]), (a[5], b[5])):
                    Ma, Mb = ws_fk(robot, sh, x), ws_fk(robot, sh, y)
                    assert np.abs(Ma.homogeneous - Mb.homogeneous).max() < 1e-9, (a, b)
            for x, y in ((a[3], b[3]), (a[4], b[4]), (a[6], b[6])):
                assert x == y or abs(x - y) <= 1e-6 * abs(x) + 1e-16, (a, b)  # squared errors
            diffs.append(d)
            conv += a[1]
            hits += bool(((a[0] == sh.lo) | (a[0] == sh.hi)).any())
    diffs = np.array(diffs)
    assert np.median(diffs) < 1e-13 and np.quantile(diffs, 0.75) < 1e-11, np.sort(diffs)[-5:]
    assert conv >= len(diffs) // 3
    if np.isfinite(sh.lo).sum() > sh.n // 2:
        assert hits > 0  # the active set was exercised


@needs_cc
@pytest.mark.parametrize("name,kw", ROBOTS[:4] + ROBOTS[6:], ids=IDS[:4] + IDS[6:])
def test_solve_same_answers_with_either_kernel(name, kw, user_urdf, monkeypatch):
    robot = _load(name, kw, user_urdf)
    Q = robot.random_q(15, rng=5)
    Ts = robot.fk(Q)
    res_c = [aa.ik.solve(robot, T) for T in Ts]
    monkeypatch.setenv("ANTHROARM_IK_C", "0")
    res_py = [aa.ik.solve(robot, T) for T in Ts]
    for a, b in zip(res_c, res_py):
        assert a.success and b.success
        assert a.iterations == b.iterations and a.restarts == b.restarts
        np.testing.assert_allclose(a.q, b.q, atol=1e-8)


_CHILD = r"""
import numpy as np, anthroarm as aa
from anthroarm.ik.solve import ckernel
from anthroarm.ik.solve.workspace import workspace
r = aa.load("panda")
Ts = r.fk(r.random_q(20, rng=2))
res = [aa.ik.solve(r, T) for T in Ts]
ws = workspace(r, r.frame_id(None))
print(all(x.success for x in res), ws.cbuf is None, ckernel.status())
"""


@pytest.mark.parametrize(
    "env,compiled",
    [({"ANTHROARM_IK_C": "0"}, False), ({"CC": "/nonexistent/cc"}, False)],
    ids=["switched_off", "no_compiler"],
)
def test_python_kernel_without_the_compiled_one(env, compiled):
    """The fallback is real: with ``ANTHROARM_IK_C=0`` or without a C compiler every target is
    still solved, by the Python kernel."""
    out = subprocess.run(
        [sys.executable, "-c", _CHILD],
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    ok, no_buffers, status = out.stdout.strip().split(" ", 2)
    assert ok == "True" and no_buffers == str(not compiled), out.stdout
    assert "ANTHROARM_IK_C=0" in status or "compiler" in status


@needs_cc
def test_library_comes_from_the_verified_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path))
    robot = aa.load("ur5")
    sh = workspace(robot, robot.frame_id(None)).sh
    src = ckernel.c_source(sh)
    ckernel._LIBS.clear()
    kern = ckernel.build(sh)
    assert (
        Path(kern.path).parent == tmp_path / "ik"
        and cache.read("ik", Path(kern.path).name) is not None
    )
    assert ckernel.c_source(sh) == src  # deterministic source: one cache entry
