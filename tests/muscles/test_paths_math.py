"""Moment arms against mathematics: the exact derivative −∂l/∂q equals central differences of
our own lengths (step 1e-6: truncation ~1e-12 m, rounding ~1e-10 m) where the path is smooth,
and the bad inputs of the issue give typed errors (never NaN)."""

from __future__ import annotations

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import MuscleError

H = 1e-6


def _central(robot, ms, Q, wrap):
    """−(l(q + h e_k) − l(q − h e_k)) / 2h for every coordinate k, in one batch."""
    n, nq = Q.shape
    E = np.eye(nq) * H
    batch = np.concatenate([Q[:, None] + E[None], Q[:, None] - E[None]], axis=1)
    lengths = muscles.lengths(robot, ms, batch.reshape(-1, nq), wrap=wrap)
    lengths = lengths.reshape(n, 2, nq, len(ms))
    return -np.moveaxis(lengths[:, 0] - lengths[:, 1], 1, 2) / (2 * H)


def test_gait2392_moment_arms_are_the_derivative_of_lengths():
    path = aa.osim.path("gait2392")
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    Q = robot.random_q(15, rng=4, margin=0.01)
    L, R = muscles.lengths_and_moment_arms(robot, ms, Q)
    fd = _central(robot, ms, Q, wrap=False)
    # a ConditionalPathPoint switching inside the +-h interval makes l jump: leave those out
    err = np.abs(fd - R)
    conditional = [
        i for i, m in enumerate(ms.muscles) if any(p.kind == "conditional" for p in m.points)
    ]
    smooth = np.ones(len(ms), dtype=bool)
    smooth[conditional] = False
    assert err[:, smooth].max() < 1e-8, err[:, smooth].max()
    assert np.median(err[:, conditional]) < 1e-8
    # the knee's moving points and spline coupling are in the derivative
    knee = robot.joint_names.index("knee_angle_r")
    assert np.abs(R[:, ms.names.index("rect_fem_r"), knee]).min() > 0.005


def test_unwrapped_arm26_moment_arms_are_the_derivative_of_lengths():
    robot = aa.load(aa.osim.path("arm26"))
    ms = muscles.read_muscles(aa.osim.path("arm26"))
    Q = robot.random_q(50, rng=5)
    R = muscles.moment_arms(robot, ms, Q, wrap=False)
    assert np.abs(_central(robot, ms, Q, wrap=False) - R).max() < 1e-8


def test_batched_equals_one_by_one():
    robot = aa.load(aa.osim.path("gait2392"))
    Q = robot.random_q(5, rng=6)
    L, R = muscles.lengths_and_moment_arms(robot, None, Q)
    for q, lq, rq in zip(Q, L, R):
        l1, r1 = muscles.lengths_and_moment_arms(robot, None, q)
        np.testing.assert_allclose(l1, lq, atol=1e-14)
        np.testing.assert_allclose(r1, rq, atol=1e-14)


def _edited(tmp_path, old, new, count=1):
    text = aa.osim.path("arm26").read_text()
    assert old in text
    p = tmp_path / "bad.osim"
    p.write_text(text.replace(old, new, count))
    return p


def test_zero_optimal_fibre_length(tmp_path):
    p = _edited(tmp_path, "<optimal_fiber_length>0.13400000000000001<", "<optimal_fiber_length>0<")
    with pytest.raises(MuscleError, match="optimal_fiber_length"):
        muscles.read_muscles(p)


def test_negative_max_force(tmp_path):
    p = _edited(
        tmp_path, "<max_isometric_force>798.51999999999998<", "<max_isometric_force>-798.5<"
    )
    with pytest.raises(MuscleError, match="max_isometric_force"):
        muscles.read_muscles(p)


def test_coinciding_path_points(tmp_path):
    ms = muscles.read_muscles(aa.osim.path("arm26"))
    bic = ms["BICshort"]
    a, b = bic.points[2], bic.points[3]  # both on r_humerus
    assert a.frame == b.frame
    text = aa.osim.path("arm26").read_text()
    old = " ".join(repr(float(x)) for x in b.location)
    loc_a = " ".join(repr(float(x)) for x in a.location)
    i = text.index(f'<PathPoint name="{b.name}">')
    j = text.index("</location>", i)
    k = text.index("<location>", i)
    p = tmp_path / "coincide.osim"
    p.write_text(text[: k + 10] + loc_a + text[j:])
    assert old  # the edited point's old location
    robot = aa.load(p)
    with pytest.raises(MuscleError, match="coincide"):
        muscles.lengths(robot, p, robot.default_q(), wrap=False)


def test_unsafe_xml_refused(tmp_path):
    p = tmp_path / "bomb.osim"
    p.write_text('<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "aaaa">]><OpenSimDocument/>')
    with pytest.raises(aa.errors.OsimSecurityError):
        muscles.read_muscles(p)


def test_not_an_osim_robot():
    robot = aa.load(aa.models.names()[0])  # a catalog arm: no .osim file, no muscles
    with pytest.raises(aa.errors.ParameterError, match="OpenSim"):
        muscles.lengths(robot, None, robot.neutral())
