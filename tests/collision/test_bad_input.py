"""Bad input to the collision layer: typed errors, never a hang or a wrong answer."""

from __future__ import annotations

import time

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm.errors import CollisionError

URDF = """<?xml version="1.0"?>
<robot name="onelink">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
</robot>
"""


def one_link(tmp_path, mesh_name, content=None):
    if content is not None:
        (tmp_path / mesh_name).write_bytes(content)
    p = tmp_path / "onelink.urdf"
    p.write_text(URDF.format(mesh=mesh_name))
    return aa.load(p, check_meshes=False)


def test_missing_mesh_names_link_and_file(tmp_path):
    robot = one_link(tmp_path, "forearm.stl")
    with pytest.raises(CollisionError, match=r"forearm\.stl.*link 'arm'.*not found") as e:
        C.model(robot)
    assert e.value.link == "arm" and e.value.path.endswith("forearm.stl")


@pytest.mark.parametrize(
    "content", [b"", b"solid nothing\nthis is not a mesh\n" * 3, b"\x00\x01garbage" * 50]
)
def test_corrupt_mesh_names_link_and_file(tmp_path, content):
    robot = one_link(tmp_path, "bad.stl", content)
    with pytest.raises(CollisionError, match=r"bad\.stl.*link 'arm'") as e:
        C.model(robot)
    assert e.value.link == "arm"


@pytest.mark.parametrize(
    "make",
    [
        lambda: C.sphere(0.0),
        lambda: C.sphere(-1),
        lambda: C.sphere(float("nan")),
        lambda: C.capsule(0.0, 0.1),
        lambda: C.capsule(0.1, 0.0),
        lambda: C.cylinder(0.1, float("inf")),
        lambda: C.box((0.1, 0.0, 0.1)),
        lambda: C.box((0.1, 0.1)),
        lambda: C.sphere(0.1, xyz=(0, np.nan, 0)),
        lambda: C.sphere(0.1, pose=np.diag([2.0, 1, 1, 1])),
        lambda: C.sphere("big"),
    ],
)
def test_degenerate_shapes(make):
    with pytest.raises(CollisionError):
        make()


def test_a_million_obstacles_refused_at_once():
    ball = C.sphere(0.01, xyz=(3, 3, 3))
    t0 = time.perf_counter()
    with pytest.raises(CollisionError, match="at most 100000"):
        C.environment([ball] * 1_000_000)
    assert time.perf_counter() - t0 < 2.0


def test_not_an_obstacle():
    with pytest.raises(CollisionError, match="entry 1 is tuple"):
        C.environment([C.sphere(0.1), ("sphere", 0.1)])


def test_bad_configuration_is_typed():
    robot = aa.load("prosthetic_arm")
    with pytest.raises(aa.errors.AnthroarmError):
        C.min_distance(robot, np.full(robot.nq, np.nan))
