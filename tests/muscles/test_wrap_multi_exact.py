"""Moment arms of a path over several wraps are the exact −∂l/∂q (issue 34).

arm26's TRIlong wraps over the TRI cylinder, the ``TRIlonghh`` ellipsoid and the TRIlongglen
cylinder, in OpenSim's passes: a later pass starts from the tangent points of the earlier ones,
and the length keeps the ground position a wrap point had when first computed in the state.
The complex step is carried through all of it (:mod:`anthroarm.muscles.wrap`), so r is the
derivative of the length as computed.  Expected values: central differences of our own
length and of OpenSim 4.6's ``Muscle.getLength`` (mathematics, not the code's derivative).

Measured (40 states, rng 21): r against central differences of our length median 6e-11,
max 9e-10 m (h = 1e-6); against those of OpenSim's length median 2e-10, max 7.8e-4 m (the
largest on states over the ellipsoid, about the shoulder, where OpenSim's tangent-point search
stops at a squared residual of 1e-8 and its length differs from ours by ~1e-6 m; the same in
h = 1e-4, 1e-5, 1e-6); OpenSim's own ``computeMomentArm`` median 2.5e-4, max 2.2e-2 m from
its length's differences.  Before: ours median 1.9e-4, max 9.3e-3 m from our own length's.
"""

from __future__ import annotations

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import muscles
from anthroarm.muscles.wrap import MANDATORY, NO_WRAP, WRAPPED, H, cylinder, sphere


@pytest.fixture(scope="module")
def trilong():
    path = aa.osim.path("arm26")
    robot = aa.load(path)
    return path, robot, muscles.read_muscles(path).select(["TRIlong"])


def _central(robot, ms, q, h):
    out = np.zeros(robot.nq)
    for k in range(robot.nq):
        e = np.zeros(robot.nq)
        e[k] = h
        out[k] = -(muscles.lengths(robot, ms, q + e) - muscles.lengths(robot, ms, q - e))[0] / (
            2 * h
        )
    return out


def test_trilong_moment_arms_are_the_derivative_of_our_length(trilong):
    _, robot, ms = trilong
    Q = robot.random_q(10, rng=31)
    R = muscles.moment_arms(robot, ms, Q)[:, 0]
    taken = (muscles.wrap_status(robot, ms, Q)["TRIlong"] == 1).sum(axis=1)
    assert (taken >= 2).sum() >= 4, taken  # several wraps on one path
    err = np.array([np.abs(r - _central(robot, ms, q, 1e-6)).max() for q, r in zip(Q, R)])
    assert err.max() < 1e-7, err


def test_trilong_moment_arms_against_opensims_length_derivative(trilong):
    opensim = pytest.importorskip("opensim")
    path, robot, ms = trilong
    model = opensim.Model(str(path))
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(n) for n in robot.joint_names]
    m = model.getMuscles().get("TRIlong")

    def length(q):
        for c, v in zip(coords, q):
            c.setValue(state, float(v), False)
        model.realizePosition(state)
        return m.getLength(state)

    Q = robot.random_q(16, rng=21)
    R = muscles.moment_arms(robot, ms, Q)[:, 0]
    h = 1e-5
    ours, theirs = [], []
    for q, r in zip(Q, R):
        fd = np.array([-(length(q + e) - length(q - e)) / (2 * h) for e in h * np.eye(robot.nq)])
        length(q)
        ma = np.array([m.computeMomentArm(state, c) for c in coords])
        ours.append(np.abs(r - fd).max())
        theirs.append(np.abs(ma - fd).max())
    # 2e-3: the tolerance of anthroarm check's row (OpenSim's tangent points converge to 1e-8)
    assert np.median(ours) < 1e-6 and max(ours) < 2e-3, ours
    assert np.median(theirs) > 100 * np.median(ours), (ours, theirs)


def _rows(p1, p2):
    """Complex-step rows of (p1, p2): row 0 real, row 1 + k moved by i h along coordinate k."""
    P = np.tile(np.concatenate([p1, p2]).astype(complex), (7, 1))
    P[np.arange(1, 7), np.arange(6)] += 1j * H
    return P[:, :3], P[:, 3:]


def _check_rows(f, p1, p2, h=1e-7):
    """f(p1 (D, 3), p2 (D, 3)) -> (code, r1, r2, arc, turn): its complex-step derivatives
    against central differences of its real evaluation (measured ~2e-9 for derivatives of
    order 1)."""
    code, r1, r2, arc, _ = f(*_rows(p1, p2))
    assert code != NO_WRAP and np.real(arc[0]) > 0
    p = np.concatenate([p1, p2])
    for k in range(6):
        e = np.zeros(6)
        e[k] = h
        plus = f((p + e)[None, :3], (p + e)[None, 3:])
        minus = f((p - e)[None, :3], (p - e)[None, 3:])
        assert abs((plus[3][0] - minus[3][0]) / (2 * h) - arc[1 + k].imag / H) < 1e-7
        for i in (1, 2):
            fd = (plus[i][0] - minus[i][0]) / (2 * h)
            assert np.abs(fd - [r1, r2][i - 1][1 + k].imag / H).max() < 1e-7
    return code


def test_complex_step_through_a_cylinder_with_its_tangent_points_slid():
    """A multi-wrap path's cylinder (single=False: OpenSim's sliding of the tangent points
    along the axis, 47 and 88 adjustments here) and a single one."""
    p1, p2 = np.array([0.025, 0.01, -0.08]), np.array([-0.022, 0.012, 0.02])
    for single in (False, True):

        def f(a, b, single=single):
            return cylinder(a, b, 0.02, 0.3, (0, 0), single)

        assert _check_rows(f, p1, p2) == MANDATORY
    # one-sided (quadrant -y): the wrap goes round the allowed side
    assert _check_rows(lambda a, b: cylinder(a, b, 0.02, 0.3, (1, -1), False), p1, p2) == WRAPPED


def test_complex_step_through_a_sphere():
    p1, p2 = np.array([0.05, 0.01, -0.02]), np.array([-0.04, 0.015, 0.03])
    assert _check_rows(lambda a, b: sphere(a, b, 0.02, (0, 0)), p1, p2) == WRAPPED
    assert _check_rows(lambda a, b: sphere(a, b, 0.02, (2, -1)), p1, p2) != NO_WRAP
