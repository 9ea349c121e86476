"""Bad input to the muscles (issue 34's list): a typed error or a status, never NaN.

* a wrap object the path starts inside: OpenSim lets the path pass straight through
  (``insideRadius``); so do we — the length is finite, equals the straight path and OpenSim's,
  and :func:`anthroarm.muscles.wrap_status` reports -1;
* a wrapped path whose points coincide: :class:`~anthroarm.errors.MuscleError`;
* muscle parameters that are not positive (zero optimal fibre length, negative maximum force),
  from a file or built in code: :class:`~anthroarm.errors.MuscleError`;
* activations outside [0, 1] or NaN: :class:`~anthroarm.errors.MuscleError` from the forces and
  the joint torques.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from arm26_variants import variant

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import MuscleError


def _big_ellipsoid(text):
    i = text.index('<WrapEllipsoid name="BIClonghh">')
    j = text.index("</WrapEllipsoid>", i)
    block = re.sub(
        r"<dimensions>[^<]*</dimensions>", "<dimensions>0.05 0.05 0.05</dimensions>", text[i:j]
    )
    return text[:i] + block + text[j:]


def test_path_starting_inside_a_wrap_object(tmp_path):
    path = variant(tmp_path, "inside", _big_ellipsoid)
    robot = aa.load(path)
    ms = muscles.read_muscles(path).select(["BIClong"])
    Q = robot.random_q(8, rng=3)
    L, R = muscles.lengths_and_moment_arms(robot, ms, Q)
    assert np.all(np.isfinite(L)) and np.all(np.isfinite(R))
    straight = muscles.lengths(robot, ms, Q, wrap=False)
    assert np.allclose(L, straight, rtol=0, atol=1e-15)
    status = muscles.wrap_status(robot, ms, Q)
    assert status["BIClong"].shape == (8, 1) and np.all(status["BIClong"] == -1)
    assert muscles.wrap_status(robot, ms, Q[0])["BIClong"].tolist() == [-1]
    opensim = pytest.importorskip("opensim")
    model = opensim.Model(str(path))
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(n) for n in robot.joint_names]
    m = model.getMuscles().get("BIClong")
    for q, lq in zip(Q, L[:, 0]):
        for c, v in zip(coords, q):
            c.setValue(state, float(v), False)
        model.realizePosition(state)
        assert abs(m.getLength(state) - lq) < 1e-12


def test_wrap_status_of_the_shipped_arm26():
    path = aa.osim.path("arm26")
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    Q = robot.random_q(10, rng=4)
    status = muscles.wrap_status(robot, ms, Q)
    assert set(status) == {"TRIlong", "TRIlat", "TRImed", "BIClong", "BRA"}
    assert status["TRIlong"].shape == (10, 3)
    L = muscles.lengths(robot, ms, Q)
    straight = muscles.lengths(robot, ms, Q, wrap=False)
    i = ms.names.index("BIClong")
    # wrapped exactly where the length differs from the straight path
    assert np.array_equal(status["BIClong"][:, 0] == 1, L[:, i] - straight[:, i] > 1e-12)


def _coinciding(text):
    i = text.index('<PathPoint name="BIClong-P3">')
    j = text.index("</PathPoint>", i)
    block = text[i:j].replace("/bodyset/r_humerus", "/bodyset/base")
    block = re.sub(
        r"<location>[^<]*</location>",
        "<location>-0.028944999999999999 0.01391 0.15639</location>",
        block,
    )
    return text[:i] + block + text[j:]


def test_wrapped_path_with_coinciding_points(tmp_path):
    path = variant(tmp_path, "coincide_wrapped", _coinciding)
    robot = aa.load(path)
    ms = muscles.read_muscles(path).select(["BIClong"])
    with pytest.raises(MuscleError, match="coincide"):
        muscles.lengths(robot, ms, robot.default_q())
    with pytest.raises(MuscleError, match="coincide"):
        muscles.lengths(robot, ms, robot.default_q(), wrap=False)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("optimal_fiber_length", 0.0),
        ("max_isometric_force", -10.0),
        ("tendon_slack_length", np.nan),
    ],
)
def test_muscle_parameters_built_in_code(field, value):
    ms = muscles.read_muscles(aa.osim.path("arm26"))
    bad = dataclasses.replace(ms["BRA"], **{field: value})
    sub = muscles.MuscleSet(ms.path, [bad], ms.wrap_objects, [])
    with pytest.raises(MuscleError, match=field):
        muscles.equilibrium(sub, np.array([0.2]), 0.5)


@pytest.mark.parametrize("bad", [-0.01, 1.01, np.nan, np.inf])
def test_joint_torques_refuse_bad_activation(bad):
    path = aa.osim.path("arm26")
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    a = np.full(len(ms), 0.5)
    a[2] = bad
    with pytest.raises(MuscleError):
        muscles.joint_torques(robot, ms, robot.default_q(), a)
    tau, eq, _ = muscles.joint_torques(robot, ms, robot.default_q(), 0.5)
    assert np.all(np.isfinite(tau))
