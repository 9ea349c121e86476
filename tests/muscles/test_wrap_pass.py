"""The compiled pass loop of a path over its wrap objects (:mod:`anthroarm.muscles.wrap_pass`)
on paths whose length is known in closed form, and its failures.

A path from p1 = (−a, b, 0) to p2 = (a, b, 0) past a circle of radius r at the origin
(a sphere, or the cross-section z = 0 of a cylinder along z), 0 < b < r: the shortest path is
the two tangent lines, each of length s = √(ρ² − r²) (ρ = |p1| = |p2|), and the arc between
the tangent points, whose directions are the end points' turned towards +y by α = acos(r / ρ):
an arc of angle θ = 2(φ − α), φ = atan2(a, b).  So

    l = 2 s + r θ,   ∂l/∂a = 2 (a s + r b) / ρ²,   ∂l/∂b = 2 (b s − r a) / ρ²

(the end points move apart with a, sideways with b).  An ellipsoid of equal radii gives the
same tangent points, and its surface path is OpenSim's polyline of n = ⌊|r1 − r2| / 1 mm⌋ equal
chords 2 r sin(θ / 2n) (rays at equal angles from the centre, the point where the wrap plane
meets the axis most normal to it).  Expected values: this geometry, not the code.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from anthroarm import jit
from anthroarm.errors import MuscleError
from anthroarm.muscles import wrap
from anthroarm.muscles.reader import PathWrap, WrapObject

R_, A_, B_ = 0.02, 0.05, 0.01


def _obj(kind, name="w", active=True, quadrant="all", translation=(0.0, 0.0, 0.0)):
    dims = np.full(3, R_) if kind == "WrapEllipsoid" else None
    return WrapObject(
        name, kind, "body", np.array(translation), np.eye(3), quadrant, active, R_, 1.0, dims
    )


def _path(objs, a=A_, b=B_, n=3, ranges=None):
    """wrapped_length of p1 (−a, b, 0) → p2 (a, b, 0) on n identical states, q = (a, b)."""
    xs = np.tile([[-a, b, 0.0], [a, b, 0.0]], (n, 1, 1))
    dxs = np.zeros((n, 2, 3, 2))
    dxs[:, 0, 0, 0], dxs[:, 1, 0, 0] = -1.0, 1.0  # ∂/∂a
    dxs[:, :, 1, 1] = 1.0  # ∂/∂b
    T, J = np.tile(np.eye(4), (n, 1, 1)), np.zeros((n, 6, 2))
    ranges = ranges or [(-1, -1)] * len(objs)
    sub = [(PathWrap(w.name, "hybrid", rg), w, T, J) for w, rg in zip(objs, ranges)]
    codes = np.zeros((n, len(objs)), dtype=int)
    muscle = SimpleNamespace(name="m", points=[None, None])
    L, D = wrap.wrapped_length(xs, dxs, np.arange(2), sub, muscle, codes)
    return L, D, codes


def _closed_form(a=A_, b=B_, r=R_):
    rho = math.hypot(a, b)
    s = math.sqrt(rho * rho - r * r)
    theta = 2.0 * (math.atan2(a, b) - math.acos(r / rho))
    dl = np.array([2 * (a * s + r * b), 2 * (b * s - r * a)]) / rho**2
    return s, theta, dl


@pytest.mark.parametrize(
    "kind, up", [("WrapSphere", 0.0), ("WrapCylinder", 0.0), ("WrapCylinder", -0.001)]
)
def test_one_wrap_closed_form(kind, up):
    """In the cylinder's mid-plane (both end points have the same point on its axis: the
    compiled kernel divided a complex zero there, which raised ZeroDivisionError) and 1 mm off
    it."""
    s, theta, dl = _closed_form()
    L, D, codes = _path([_obj(kind, translation=(0.0, 0.0, up))])
    assert np.all(codes == wrap.WRAPPED)
    assert np.abs(L - (2 * s + R_ * theta)).max() < 1e-15
    assert np.abs(D - dl).max() < 1e-13, (D, dl)


def test_one_ellipsoid_of_equal_radii_closed_form():
    s, theta, _ = _closed_form()
    L, D, codes = _path([_obj("WrapEllipsoid")])
    assert np.all(codes == wrap.WRAPPED)
    n = int(2 * R_ * math.sin(theta / 2) / 0.001)  # the chord between the tangent points, mm
    assert n == 8
    assert np.abs(L - (2 * s + 2 * n * R_ * math.sin(theta / (2 * n)))).max() < 1e-14

    # the derivative: the same polyline (n fixed) as a function of (a, b)
    def length(a, b):
        s, theta, _ = _closed_form(a, b)
        return 2 * s + 2 * n * R_ * math.sin(theta / (2 * n))

    h = 1e-7
    fd = [(length(A_ + h, B_) - length(A_ - h, B_)) / (2 * h)]
    fd.append((length(A_, B_ + h) - length(A_, B_ - h)) / (2 * h))
    assert np.abs(D - fd).max() < 1e-7, (D, fd)


def test_two_wraps_on_separate_segments_add_up():
    """p1 → p2 → p3 with a sphere on each segment (ranges 1-2 and 2-3): the passes (two or
    more wraps) converge on the sum of two closed forms."""
    s, theta, dl = _closed_form()
    one = 2 * s + R_ * theta
    n = 2
    xs = np.tile([[-A_, B_, 0.0], [A_, B_, 0.0], [3 * A_, B_, 0.0]], (n, 1, 1))
    dxs = np.zeros((n, 3, 3, 1))
    dxs[:, :, 1, 0] = 1.0  # every point moves along y: ∂l/∂b of each span
    T, J = np.tile(np.eye(4), (n, 1, 1)), np.zeros((n, 6, 1))
    w1, w2 = _obj("WrapSphere", "w1"), _obj("WrapSphere", "w2", translation=(2 * A_, 0, 0))
    objs = [
        (PathWrap("w1", "hybrid", (1, 2)), w1, T, J),
        (PathWrap("w2", "hybrid", (2, 3)), w2, T, J),
    ]
    codes = np.zeros((n, 2), dtype=int)
    muscle = SimpleNamespace(name="m", points=[None] * 3)
    L, D = wrap.wrapped_length(xs, dxs, np.arange(3), objs, muscle, codes)
    assert np.all(codes == wrap.WRAPPED)
    assert np.abs(L - 2 * one).max() < 1e-15
    assert np.abs(D[:, 0] - 2 * dl[1]).max() < 1e-13
    # drawn: point, two tangent points and an arc per wrap, point between, point
    trace = wrap.current_path(xs[0], np.arange(3), [(pw, w, T[0]) for pw, w, T, _ in objs], muscle)
    kinds = [k for k, *_ in trace]
    assert kinds == ["point", "tangent", "surface", "tangent"] * 2 + ["point"]
    pts = np.concatenate([np.atleast_2d(x) for _, _, x in trace])
    assert (
        abs(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum() - 2 * one) < 2 * wrap.ARC_TOLERANCE
    )


def test_inactive_and_missing_wraps():
    L, D, codes = _path([_obj("WrapSphere", active=False)])
    assert np.all(codes == 0) and np.abs(L - 2 * A_).max() < 1e-16
    assert np.abs(D - [2.0, 0.0]).max() < 1e-15
    # a torus is not evaluated: refused when active, skipped when not
    with pytest.raises(MuscleError, match="is a WrapTorus"):
        _path([_obj("WrapTorus")])
    L, _, _ = _path([_obj("WrapTorus", active=False)])
    assert np.abs(L - 2 * A_).max() < 1e-16


def test_failures_are_typed_errors():
    # through the sphere's centre: the wrap plane is undefined
    with pytest.raises(MuscleError, match="sphere's centre"):
        _path([_obj("WrapSphere")], b=0.0)
    p1, p2 = np.array([[-A_, 0.0, 0.0]]), np.array([[A_, 0.0, 0.0]])
    with pytest.raises(MuscleError, match="sphere's centre"):
        wrap.sphere(p1, p2, R_, (0, 0))
    # coinciding points beside a wrap they do not touch
    with pytest.raises(MuscleError, match="coincide"):
        _path([_obj("WrapSphere", translation=(0.0, 1.0, 0.0))], a=0.0)


def test_reference_and_compiled_passes_agree(monkeypatch):
    """The interpreter's run of the kernel source and the compiled one (arm26's TRIlong-like
    three wraps here: two spheres, one ellipsoid)."""
    objs = [_obj("WrapSphere", "s"), _obj("WrapEllipsoid", "e"), _obj("WrapCylinder", "c")]
    L, D, codes = _path(objs)
    monkeypatch.setattr(wrap, "passes", jit.reference(wrap.passes))
    L2, D2, codes2 = _path(objs)
    assert np.array_equal(codes, codes2)
    assert np.abs(L - L2).max() < 1e-14 and np.abs(D - D2).max() < 1e-10
