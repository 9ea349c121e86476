"""The IK benchmark's peer adapters (benchmarks/ik_peers.py) and the result writer's quick-run rule.

The adapters must describe the robot anthroarm loads exactly (their FK equals Pinocchio's) and
hand back a Pinocchio q, with (cos, sin) for continuous joints; TRAC-IK (pytracik) and RTB are
bench-extra packages, so their tests skip without them.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from benchmarks import common, ik_peers  # noqa: E402


@pytest.fixture(scope="module")
def load_odd(tmp_path_factory):
    """anthroarm.load of ODD_ARM (below) with the given joints locked."""
    path = tmp_path_factory.mktemp("urdf") / "oddarm.urdf"
    path.write_text(ODD_ARM)
    return lambda **locked: aa.load(path, tool="tool", locked=locked)


# 6 revolute joints: two continuous, one about -y, one about a skew axis; a revolute joint before
# the first and one after the last (locked in some tests); the tool hangs past the jaw
ODD_ARM = """<robot name="oddarm">
  <link name="root"/><link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="l5"/><link name="l6"/><link name="jaw_link"/><link name="tool"/>
  <joint name="pre" type="revolute"><parent link="root"/><child link="base"/><origin xyz="0.1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0.05 0.2"/><axis xyz="0 -1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="j4" type="continuous"><parent link="l3"/><child link="l4"/><origin xyz="0.25 0 0" rpy="0.1 0.2 0.3"/>
    <axis xyz="1 0 0"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/><origin xyz="0.05 0 0"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="l5"/><child link="l6"/><origin xyz="0.05 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="jaw" type="revolute"><parent link="l6"/><child link="jaw_link"/><origin xyz="0.02 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tj" type="fixed"><parent link="jaw_link"/><child link="tool"/><origin xyz="0.1 0 0.02" rpy="0 0.5 0"/></joint>
</robot>
"""


def _targets(robot, n, rng=5):
    ang = ik_peers.Angles(robot)
    qs = ang.to_q(ang.from_q(robot.random_q(n, rng=rng)))  # unit (cos, sin) pairs
    return robot.fk(qs)


def _solved(robot, adapter, Ts):
    ok = 0
    for T in Ts:
        q = adapter.solve(T)
        if q is None:
            continue
        assert q.shape == (robot.nq,)
        pe, re = ik_peers.pose_errors(robot, q, T)
        ok += pe <= 1e-5 and re <= 1e-4 and bool(robot.within_limits(q))
    return ok


def test_angles_round_trip_continuous(load_odd):
    robot = load_odd(pre=0.3, jaw=-0.2)
    ang = ik_peers.Angles(robot)
    assert (robot.nq, robot.nv) == (8, 6)
    assert ang.continuous.sum() == 2 and np.isinf(ang.lower[ang.continuous]).all()
    th = np.random.default_rng(0).uniform(-3, 3, (7, robot.nv))
    q = ang.to_q(th)
    assert np.allclose(ang.to_q(ang.from_q(q)), q, atol=1e-15)
    assert np.allclose(np.cos(ang.from_q(q) - th), 1.0)
    # the seed of every peer is a valid configuration: (cos, sin) of a continuous joint has norm 1
    seed = ik_peers.seed_for(robot)
    assert np.allclose(np.hypot(seed[ang.two_q], seed[ang.two_q + 1]), 1.0)


def test_trac_ik_chain_moves_base_and_tip_past_locked_joints(load_odd):
    pytest.importorskip("pytracik")
    robot = load_odd(pre=0.3, jaw=-0.2)
    a, why = ik_peers.make("trac-ik", robot)  # make() checks its FK against Pinocchio's
    assert a is not None, why
    assert (a.base, a.tip) == ("base", "l6")
    assert _solved(robot, a, _targets(robot, 12)) >= 10


def test_trac_ik_pins_a_locked_joint_inside_the_chain(load_odd):
    pytest.importorskip("pytracik")
    robot = load_odd(pre=0.3, j3=0.7, jaw=-0.2)
    a, why = ik_peers.make("trac-ik", robot)
    assert a is not None, why
    assert (a.base, a.tip) == ("base", "l6")
    assert a.seed[2] == pytest.approx(0.7) and list(a.active) == [0, 1, 3, 4, 5]


@pytest.mark.parametrize("peer, at_least", [("rtb-ik_LM", 6), ("ikpy", 3)])  # ikpy: local, ~90 %
def test_peers_on_continuous_and_skew_axes(load_odd, peer, at_least):
    pytest.importorskip({"rtb-ik_LM": "roboticstoolbox", "ikpy": "ikpy"}[peer])
    robot = load_odd(pre=0.3, jaw=-0.2)
    a, why = ik_peers.make(peer, robot)
    assert a is not None, why
    assert _solved(robot, a, _targets(robot, 6)) >= at_least


@pytest.mark.parametrize("name", ["panda", "ur5", "prosthetic_arm"])
def test_trac_ik_on_catalog_arms(name):
    pytest.importorskip("pytracik")
    robot = aa.load(name)
    a, why = ik_peers.make("trac-ik", robot)
    assert a is not None, why
    assert a.base == robot.info.root_link and a.tip == robot.tool
    # the URDF's limits, not pytracik's reading of the safety controller (all zero for the panda)
    import pytracik

    assert np.allclose(pytracik.get_joint_lower_bounds(a.ik), robot.lower, atol=1e-6)
    assert np.allclose(pytracik.get_joint_upper_bounds(a.ik), robot.upper, atol=1e-6)
    assert _solved(robot, a, robot.fk(robot.random_q(20, rng=1))) >= 16


def _result(quick):
    return {
        "title": "t",
        "columns": ["a"],
        "rows": [[1]],
        "notes": "",
        "quick": quick,
        "environment": {
            "processor": "p",
            "cpus": 1,
            "python": "3",
            "numpy": "2",
            "pinocchio": "4",
            "date": "d",
        },
    }


def test_quick_results_never_land_in_results(tmp_path, monkeypatch):
    monkeypatch.setattr(common, "RESULTS_DIR", tmp_path / "results")
    monkeypatch.setattr(common, "QUICK_DIR", tmp_path / "results" / "quick")
    jp, mp = common.write_result("x", _result(True))
    assert jp.parent == tmp_path / "results" / "quick" and mp.read_text().startswith(
        "# t (quick run)"
    )
    assert json.loads(jp.read_text())["quick"] is True
    with pytest.raises(ValueError, match="quick run"):
        common.write_result("x", _result(True), tmp_path / "results")
    jp, _ = common.write_result("x", _result(False))
    assert jp.parent == tmp_path / "results"
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["quick", "x.json", "x.md"]


def test_result_figures_are_saved_next_to_the_tables(tmp_path):
    import matplotlib.pyplot as plt

    fig = plt.figure()
    res = dict(_result(False), figures={"f.png": fig, "none.png": None})
    jp, _ = common.write_result("x", res, tmp_path)
    assert (tmp_path / "f.png").is_file() and not (tmp_path / "none.png").exists()
    assert "figures" not in json.loads(jp.read_text())


@pytest.mark.parametrize("strict", [True, False])
def test_warm_benchmarks_refuse_the_interpreter(strict, tmp_path):
    """A warm table times compiled kernels: a process whose kernels run in the interpreter
    (``ANTHROARM_JIT=reference``) is refused a full run into results/ and warned otherwise."""
    env = dict(os.environ, ANTHROARM_JIT="reference", ANTHROARM_CACHE=str(tmp_path))
    code = (
        f"from benchmarks.common import compiled_kernels; compiled_kernels({strict}); print('ran')"
    )
    p = subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True
    )
    assert "kernels run in the interpreter (reference (ANTHROARM_JIT=reference))" in (
        p.stderr + p.stdout
    )
    assert (p.returncode != 0 and "ran" not in p.stdout) if strict else p.stdout.endswith("ran\n")
