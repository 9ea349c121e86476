"""mink's rows of the collision benchmark (benchmarks/collision_mink.py, bench_collision.py).

The MuJoCo scene must describe what ours and pink see: the tool's FK equal to Pinocchio's, every
primitive geom where Pinocchio places the same body, mj_geomDistance equal to coal's distance on
separated pairs (panda's hulls included), and MuJoCo's qpos a permutation of Pinocchio's q (a
wrong permutation is caught).  The quick benchmark's mink rows run and are checked like the
others.  mink and MuJoCo are the optional bench extra: skipped without them.
"""

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("mink")
import mujoco  # noqa: E402

from anthroarm import collision as C  # noqa: E402
from anthroarm.collision.checks import start_and_targets  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from benchmarks import bench_collision, collision_mink  # noqa: E402

SCENES = {
    name: (robot, C.environment(obs), d) for name, robot, obs, _, d in bench_collision.scenes()
}


@pytest.fixture(scope="module", params=list(SCENES))
def scene(request):
    robot, env, d_min = SCENES[request.param]
    return robot, env, d_min, collision_mink.Scene(robot, env, d_min + collision_mink.DETECT)


def _mj_tool(sc, robot, q, perm=None):
    data = mujoco.MjData(sc.model)
    data.qpos[perm if perm is not None else sc.perm] = q
    mujoco.mj_kinematics(sc.model, data)
    b = mujoco.mj_name2id(sc.model, mujoco.mjtObj.mjOBJ_BODY, robot.tool)
    return data, data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy()


def test_tool_fk_matches_pinocchio(scene):
    robot, _, _, sc = scene
    assert sc.model.nq == robot.nq
    for q in robot.random_q(20, rng=7):
        _, p, R = _mj_tool(sc, robot, q)
        T = robot.fk(q)
        assert np.abs(p - T[:3, 3]).max() < 1e-9
        assert np.abs(R - T[:3, :3]).max() < 1e-9


def test_wrong_joint_order_is_caught(scene):
    """Control: the FK comparison above fails when MuJoCo's joints are mapped in another order."""
    robot, _, _, sc = scene
    q = robot.random_q(rng=8)
    _, p, _ = _mj_tool(sc, robot, q, perm=sc.perm[::-1])
    assert np.abs(p - robot.fk(q)[:3, 3]).max() > 1e-3


def test_primitive_geoms_where_pinocchio_puts_them(scene):
    robot, _, _, sc = scene
    cm = C.model(robot)
    gd = pin.GeometryData(cm.geometry)
    data = robot.model.createData()
    q = robot.random_q(rng=9)
    mj, _, _ = _mj_tool(sc, robot, q)
    pin.updateGeometryPlacements(robot.model, data, cm.geometry, gd, q)
    checked = 0
    for i, g in enumerate(cm.geometry.geometryObjects):
        gid = mujoco.mj_name2id(sc.model, mujoco.mjtObj.mjOBJ_GEOM, g.name)
        if sc.model.geom_type[gid] == mujoco.mjtGeom.mjGEOM_MESH:  # recentred by MuJoCo
            continue
        assert np.abs(mj.geom_xpos[gid] - gd.oMg[i].translation).max() < 1e-9
        assert np.abs(mj.geom_xmat[gid].reshape(3, 3) - gd.oMg[i].rotation).max() < 1e-9
        checked += 1
    assert checked >= 8  # panda's finger boxes, the limb's capsules and boxes


def test_mujoco_distances_match_coal(scene):
    """Every pair within the detection distance, separated by coal, at random configurations:
    mj_geomDistance (what mink's limit sees) equals anthroarm's coal distance."""
    robot, env, d_min, sc = scene
    data = mujoco.MjData(sc.model)
    fromto = np.zeros(6)
    n = 0
    for q in robot.random_q(30, rng=10):
        data.qpos[sc.perm] = q
        mujoco.mj_kinematics(sc.model, data)
        D = C.distances(robot, q, env, cutoff=d_min + collision_mink.DETECT)
        for (a, b), d in zip(D.names, D.distance):
            if d <= 0:
                continue
            ga = mujoco.mj_name2id(sc.model, mujoco.mjtObj.mjOBJ_GEOM, a)
            gb = mujoco.mj_name2id(sc.model, mujoco.mjtObj.mjOBJ_GEOM, b)
            dm = mujoco.mj_geomDistance(sc.model, data, ga, gb, 1.0, fromto)
            assert abs(dm - d) < 1e-6, (a, b, d, dm)
            n += 1
    assert n >= 20


def test_mink_steps_toward_the_target(scene):
    """MinkIK moves the tool: after 40 steps it is at most half as far from its target."""
    robot, env, d_min, _ = scene
    q0, targets = start_and_targets(robot, 1, rng=0, d_clear=d_min + 1e-3, obstacles=env)
    q0 = bench_collision.PANDA_READY if robot.name == "panda" else q0
    T = targets[0]
    mk = collision_mink.MinkIK(robot, env, q0, d_min, bench_collision.DT, bench_collision.EE_KW)
    mk.reset(T)
    for _ in range(40):
        q = mk.step()
    e0 = np.linalg.norm(robot.fk(q0)[:3, 3] - T[:3, 3])
    assert np.linalg.norm(robot.fk(q)[:3, 3] - T[:3, 3]) < 0.5 * e0


@pytest.mark.slow
def test_quick_benchmark_mink_rows():
    out = bench_collision.run(quick=True, n_targets=2)
    cols = out["columns"]
    rows = [dict(zip(cols, r)) for r in out["rows"]]
    for name in SCENES:
        res = out["results"][name]
        for m in bench_collision.MINK_GAINS:
            r = res[m]
            assert r["steps"] == 2 * 40 and np.isfinite(r["min_distance"])
            assert r["fk_error"] < 1e-9 and r["distance_error"] < 1e-6 and r["sign_errors"] == 0
            row = next(x for x in rows if x["scene"] == name and x["method"] == m)
            assert row["mink / ours"] == pytest.approx(r["median_ms"] / res["ours"]["median_ms"])
            assert row["steps < d_min - 1e-4"] == r["violations"]
    assert "mink 1." in out["notes"] and "mink, gain 0.85·dt" in out["notes"]
