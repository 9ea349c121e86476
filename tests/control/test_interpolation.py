"""Line and arc interpolation against geometry: equal radius, passing through the points,
constant speed, slerp against pinocchio's exp3/log3."""

import numpy as np
import pinocchio as pin
import pytest

from anthroarm.control.interpolation import arc_poses, circle_through, line_poses, slerp
from anthroarm.errors import ControlError, DegenerateArcError


def random_rotation(rng):
    return pin.exp3(rng.normal(size=3))


def test_arc_has_equal_radius_and_passes_through_the_three_points():
    rng = np.random.default_rng(3)
    for _ in range(40):
        p1, p2, p3 = rng.normal(size=(3, 3))
        arc = circle_through(p1, p2, p3)
        for p in (p1, p2, p3):
            assert np.linalg.norm(p - arc.center) == pytest.approx(arc.radius, rel=1e-10)
        # the centre is in the plane of the three points, the normal is perpendicular to it
        assert abs(np.dot(arc.normal, p2 - p1)) < 1e-9 and abs(np.dot(arc.normal, p3 - p1)) < 1e-9
        assert abs(np.dot(arc.normal, arc.center - p1)) < 1e-9
        assert np.allclose(arc.points(0.0), p1, atol=1e-10)
        assert np.allclose(arc.points(1.0), p3, atol=1e-10)
        assert 0 < arc.via_angle < arc.sweep < 2 * np.pi
        assert np.allclose(arc.points(arc.via_angle / arc.sweep), p2, atol=1e-9)
        # every sample on the circle, equal chords for equal steps (constant speed)
        pts = arc.points(np.linspace(0, 1, 33))
        assert np.allclose(np.linalg.norm(pts - arc.center, axis=1), arc.radius, rtol=1e-10)
        chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        assert np.allclose(chords, 2 * arc.radius * np.sin(arc.sweep / 64), rtol=1e-9)


def test_arc_of_a_known_circle():
    # three points of the unit circle in the xy plane, counter-clockwise at 0, π/2, π
    arc = circle_through([1, 0, 0], [0, 1, 0], [-1, 0, 0])
    assert np.allclose(arc.center, 0) and arc.radius == pytest.approx(1.0)
    assert np.allclose(arc.normal, [0, 0, 1]) and arc.sweep == pytest.approx(np.pi)
    assert arc.length == pytest.approx(np.pi)
    # the long way round: via a point below
    arc2 = circle_through([1, 0, 0], [0, -1, 0], [0, 1, 0])
    assert np.allclose(arc2.normal, [0, 0, -1]) and arc2.sweep == pytest.approx(1.5 * np.pi)
    # tangent = derivative of the points / (sweep r)
    s, h = 0.3, 1e-6
    fd = (arc2.points(s + h) - arc2.points(s - h)) / (2 * h) / (arc2.sweep * arc2.radius)
    assert np.allclose(arc2.tangents(s), fd, atol=1e-8)


@pytest.mark.parametrize("scale", [1e-150, 1e-6, 1.0, 1e6, 1e150])
def test_arc_at_any_scale(scale):
    p = (
        np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]) * scale
        + np.array([2.0, 0.0, 0.0]) * scale
    )
    arc = circle_through(*p)
    assert arc.radius == pytest.approx(scale, rel=1e-12)
    assert np.allclose(
        arc.center / scale, [2.0, 0.0, 0.0], atol=1e-12
    ) and arc.sweep == pytest.approx(np.pi)


def test_collinear_and_coincident_points_raise():
    with pytest.raises(DegenerateArcError, match="collinear"):
        circle_through([0, 0, 0], [1, 1, 1], [2, 2, 2])
    with pytest.raises(DegenerateArcError, match="coincide"):
        circle_through([0, 0, 0], [0, 0, 0], [1, 0, 0])
    with pytest.raises(ControlError):
        circle_through([0, 0], [1, 0, 0], [0, 1, 0])


def test_slerp_matches_pinocchio_and_line_poses():
    rng = np.random.default_rng(5)
    for _ in range(10):
        R0, R1 = random_rotation(rng), random_rotation(rng)
        w = pin.log3(R0.T @ R1)
        for s in (0.0, 0.25, 0.7, 1.0):
            assert np.allclose(slerp(R0, R1, s), R0 @ pin.exp3(s * w), atol=1e-10)
        T0, T1 = np.eye(4), np.eye(4)
        T0[:3, :3], T1[:3, :3] = R0, R1
        T0[:3, 3], T1[:3, 3] = rng.normal(size=3), rng.normal(size=3)
        P = line_poses(T0, T1, np.linspace(0, 1, 11))
        assert np.allclose(P[0], T0, atol=1e-10) and np.allclose(P[-1], T1, atol=1e-10)
        d = np.diff(P[:, :3, 3], axis=0)
        assert np.allclose(d, (T1[:3, 3] - T0[:3, 3]) / 10)  # straight, constant speed
        # constant angular speed: equal rotation angles between samples
        ang = [np.linalg.norm(pin.log3(P[k][:3, :3].T @ P[k + 1][:3, :3])) for k in range(10)]
        assert np.allclose(ang, np.linalg.norm(w) / 10, atol=1e-9)


def test_arc_poses_ends_and_bad_s():
    T1, T3 = np.eye(4), np.eye(4)
    T1[:3, 3], T3[:3, 3] = [0.3, 0, 0.2], [0, 0.3, 0.2]
    T3[:3, :3] = pin.exp3(np.array([0, 0, np.pi / 2]))
    P = arc_poses(
        T1, [0.3 * np.cos(np.pi / 4), 0.3 * np.sin(np.pi / 4), 0.2], T3, np.linspace(0, 1, 5)
    )
    assert np.allclose(P[0], T1) and np.allclose(P[-1], T3, atol=1e-12)
    assert np.allclose(np.linalg.norm(P[:, :2, 3], axis=1), 0.3)
    # here the arc angle and the rotation angle grow together: the hand turns with the arc
    for k, s in enumerate(np.linspace(0, 1, 5)):
        assert np.allclose(P[k][:3, :3], pin.exp3(np.array([0, 0, s * np.pi / 2])), atol=1e-12)
    with pytest.raises(ControlError):
        line_poses(T1, T3, 1.5)
