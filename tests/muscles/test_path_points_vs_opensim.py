"""The muscles' paths as points (``muscles.path_points``, issue 34 "the path drawn in the
viewer") against OpenSim 4.6 itself: on arm26 as shipped (BIClong over an ellipsoid, TRIlat,
TRImed and BRA over a cylinder, TRIlong over two cylinders and an ellipsoid) at 20 random
states, every point of ``GeometryPath.getCurrentPath(state)`` (the active PathPoints and each
wrap's two ``PathWrapPoint``\\ s), by ``getLocationInGround(state)``, equals ours to 1e-6 m
(1e-4 m on a path over an ellipsoid, whose tangent points OpenSim converges to a squared
residual of 1e-8 only), in the same order.

The polyline through our points (the arcs on the wrap surfaces included) is as long as
OpenSim's ``getLength`` and our ``lengths`` to the same tolerances on every state where the
path wraps over one object at most.  With two wraps or more OpenSim reports each wrap point
where it was first placed in the state (its ground position is cached) while the arc is the
last pass's: the polyline then joins the two by short straight pieces and differs from the
length; measured here, bounded at 1 cm.

gait2392 (ConditionalPathPoints and MovingPathPoints, no wraps) at 20 states, every muscle,
to 1e-6 m.  Two variants as in test_paths_vs_opensim.py: the TRI cylinder one-sided (quadrant
-y: far-side arcs, longer than half a turn) and the ellipsoids made spheres (great-circle
arcs), to 1e-6 m.
"""

from __future__ import annotations

import numpy as np
import pytest
from arm26_variants import no_ellipsoids, spheres, tri_quadrant, variant

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import ParameterError
from anthroarm.osim.checks import OpenSimModel

pytest.importorskip("opensim")

TOL = 1e-6
TOL_ELLIPSOID = 1e-4
ELLIPSOID_PATHS = ("BIClong", "TRIlong")


@pytest.fixture(scope="module")
def arm26():
    path = aa.osim.path("arm26")
    robot = aa.load(path)
    return robot, muscles.read_muscles(path), OpenSimModel(path, robot.joint_names)


def _opensim_path(osm, name):
    """OpenSim's (points (k, 3) of getCurrentPath in ground, their names, getLength) of the
    muscle ``name`` at the state set."""
    return osm.current_path([m.getName() for m in osm.muscles].index(name))


def test_points_and_lengths_against_opensim_20_states(arm26):
    robot, ms, osm = arm26
    Q = robot.random_q(20, rng=7)
    paths = muscles.path_points(robot, ms, Q)
    L = muscles.lengths(robot, ms, Q)
    err = {m: 0.0 for m in ms.names}
    err_len = {m: 0.0 for m in ms.names}
    multi_excess = []
    wrapped = {m: 0 for m in ms.names}
    for s, q in enumerate(Q):
        osm.set_state(q)
        assert list(paths[s]) == ms.names
        for i, name in enumerate(ms.names):
            mp = paths[s][name]
            theirs, names, length = _opensim_path(osm, name)
            assert mp.current.shape == theirs.shape, (name, s, mp.labels, names)
            # the same points in the same order: PathPoints by name, wrap points by position
            ours_names = [lb for lb, on in zip(mp.labels, mp.surface) if not on]
            for a, b in zip(ours_names, names):
                assert a == b or b.startswith("pwpt"), (name, s, ours_names, names)
            err[name] = max(err[name], np.abs(mp.current - theirs).max())
            nwraps = len({lb for lb in mp.labels if lb in ms.wrap_objects})
            wrapped[name] += nwraps > 0
            if nwraps <= 1:
                err_len[name] = max(
                    err_len[name], abs(mp.length - length), abs(mp.length - L[s, i])
                )
            else:
                multi_excess.append(mp.length - length)
    for name in ms.names:
        tol = TOL_ELLIPSOID if name in ELLIPSOID_PATHS else TOL
        assert err[name] < tol and err_len[name] < tol, (name, err[name], err_len[name])
    # the wraps are there: every muscle but BICshort wraps on some of these states
    assert all(wrapped[m] > 0 for m in ms.names if m != "BICshort"), wrapped
    assert wrapped["BICshort"] == 0
    assert multi_excess and max(np.abs(multi_excess)) < 1e-2, multi_excess


def test_gait2392_conditional_and_moving_points():
    """gait2392 (no wraps; ConditionalPathPoints and MovingPathPoints, spline knees through
    the coupling): all 92 muscles at 20 states, the active points and the length against
    OpenSim to 1e-6 m; inactive conditional points are left out as OpenSim leaves them."""
    path = aa.osim.path("gait2392")
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    osm = OpenSimModel(path, robot.joint_names)
    Q = robot.random_q(20, rng=0)
    paths = muscles.path_points(robot, ms, Q)
    err = err_len = 0.0
    dropped = 0
    for s, q in enumerate(Q):
        osm.set_state(q)
        for m in ms.muscles:
            mp = paths[s][m.name]
            theirs, names, length = _opensim_path(osm, m.name)
            assert list(mp.labels) == names, (m.name, s)
            err = max(err, np.abs(mp.points - theirs).max())
            err_len = max(err_len, abs(mp.length - length))
            dropped += len(mp.points) < len(m.points)
    assert err < TOL and err_len < TOL, (err, err_len)
    assert dropped > 50  # conditional points out of their range on many (state, muscle) pairs


def _variant_against_opensim(path, names, n, seed):
    """(largest point error, largest length error on paths over one wrap at most, the arcs
    tangent point to tangent point of those paths) of ``names`` in the model at ``path``."""
    robot = aa.load(path)
    ms = muscles.read_muscles(path).select(names)
    osm = OpenSimModel(path, robot.joint_names)
    Q = robot.random_q(n, rng=seed)
    paths = muscles.path_points(robot, ms, Q)
    err = err_len = 0.0
    arcs = []
    for s, q in enumerate(Q):
        osm.set_state(q)
        for name in ms.names:
            mp = paths[s][name]
            theirs, _, length = _opensim_path(osm, name)
            assert mp.current.shape == theirs.shape
            err = max(err, np.abs(mp.current - theirs).max())
            if len({lb for lb in mp.labels if lb in ms.wrap_objects}) > 1:
                continue
            err_len = max(err_len, abs(mp.length - length))
            on = np.flatnonzero(mp.surface)
            if on.size:
                arcs.append(mp.points[on[0] - 1 : on[-1] + 2])
    return err, err_len, arcs


def _arc_length(X):
    return np.linalg.norm(np.diff(X, axis=0), axis=1).sum()


def test_one_sided_cylinder_far_side_arcs(tmp_path):
    """arm26 with its ellipsoids inactive and the TRI cylinder's quadrant -y: TRIlat and BRA
    then go round the cylinder's far side on many states (arcs longer than half a turn, π r);
    40 states, points and lengths against OpenSim to 1e-6 m."""
    path = variant(tmp_path, "arm26_tri_minus_y", no_ellipsoids, tri_quadrant("-y"))
    err, err_len, arcs = _variant_against_opensim(path, ["TRIlat", "BRA"], 40, 1)
    assert err < TOL and err_len < TOL, (err, err_len)
    assert sum(_arc_length(X) > np.pi * 0.016 for X in arcs) >= 10


def test_spheres(tmp_path):
    """arm26 with its ellipsoids made 2 cm spheres: BIClong and TRIlong over a sphere (great
    circles), 30 states, points and lengths against OpenSim to 1e-6 m."""
    path = variant(tmp_path, "arm26_spheres", spheres)
    err, err_len, arcs = _variant_against_opensim(path, ["BIClong", "TRIlong"], 30, 3)
    assert err < TOL and err_len < TOL, (err, err_len)
    assert len(arcs) >= 20


def test_surface_points_lie_on_their_wrap_surface(arm26):
    """Mathematics: a cylinder arc's points are at the cylinder's radius from its axis, an
    ellipsoid arc's on (x/a)² + (y/b)² + (z/c)² = 1 (OpenSim's chords join surface points), in
    the wrap object's own frame (body pose from robot.fk, the wrap's placement from the file)."""
    robot, ms, _ = arm26
    q = robot.random_q(8, rng=3)
    paths = muscles.path_points(robot, ms, q)
    checked = set()
    for s, P in enumerate(paths):
        for mp in P.values():
            for wname in {lb for lb, on in zip(mp.labels, mp.surface) if on}:
                w = ms.wrap_objects[wname]
                X = mp.points[mp.surface & (np.array(mp.labels) == wname)]
                T = robot.fk(q[s], w.frame)
                body = (X - T[:3, 3]) @ T[:3, :3]
                local = (body - w.translation) @ np.asarray(w.rotation)
                if w.kind == "WrapCylinder":
                    r = np.linalg.norm(local[:, :2], axis=1)
                    np.testing.assert_allclose(r, w.radius, atol=1e-12)
                else:
                    e = np.sum((local / w.dimensions) ** 2, axis=1) - 1.0
                    assert np.abs(e).max() < 1e-9, np.abs(e).max()
                checked.add(w.kind)
    assert checked == {"WrapCylinder", "WrapEllipsoid"}


def test_one_state_and_bad_tolerance(arm26):
    robot, ms, _ = arm26
    q = robot.default_q()
    one = muscles.path_points(robot, ms, q)
    many = muscles.path_points(robot, ms, q[None])
    assert isinstance(one, dict) and isinstance(many, list) and len(many) == 1
    for name, mp in one.items():
        np.testing.assert_array_equal(mp.points, many[0][name].points)
    # straight segments only: the active path points themselves
    straight = muscles.path_points(robot, ms, q, wrap=False)["BRA"]
    assert not straight.surface.any()
    bra = ms.names.index("BRA")
    assert straight.length == pytest.approx(muscles.lengths(robot, ms, q, wrap=False)[bra])
    for bad in (0.0, -1e-6, float("nan"), True, "1e-6"):
        with pytest.raises(ParameterError):
            muscles.path_points(robot, ms, q, tolerance=bad)
