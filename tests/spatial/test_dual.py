"""Dual numbers (5-131)-(5-134), lines (5-135)-(5-144), dual matrices (5-145)-(5-150) vs Pinocchio
SE3."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rotation, small, unit3, vec3
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.spatial import dual as D
from anthroarm.spatial.dual import Dual, Line

H = settings(max_examples=40, deadline=None)
duals = st.tuples(small, small).map(lambda t: Dual(*t))


@H
@given(duals, duals)
def test_arithmetic_rules(a, b):
    assert (a + b).isclose(Dual(a.real + b.real, a.dual + b.dual))
    assert (a - b).isclose(Dual(a.real - b.real, a.dual - b.dual))
    # the OCR's rule (2) "(a + b) ± ε(a* + b*)" is wrong for the difference
    printed_minus = Dual(a.real + b.real, -(a.dual + b.dual))
    if abs(b.real) > 1e-3:
        assert not (a - b).isclose(printed_minus)
    assert (a * b).isclose(Dual(a.real * b.real, a.dual * b.real + a.real * b.dual))
    assert (a * b).isclose(b * a)
    if abs(b.real) > 1e-3:
        assert ((a / b) * b).isclose(a, atol=1e-9)


@H
@given(duals)
def test_function_extension_is_the_derivative(x):
    """f(a + εa*) = f(a) + ε a* f'(a): compare the dual part with a central difference."""
    h = 1e-6
    fns = [(D.sin, np.sin), (D.cos, np.cos), (D.exp, np.exp)]
    if abs(np.cos(x.real)) > 0.1:
        fns.append((D.tan, np.tan))
    if x.real > 0.1:
        fns += [(D.sqrt, np.sqrt), (D.log, np.log)]
    if abs(x.real) < 0.9:
        fns += [(D.acos, np.arccos), (D.asin, np.arcsin)]
    for fd, fr in fns:
        y = fd(x)
        assert np.isclose(y.real, fr(x.real))
        assert np.isclose(y.dual, x.dual * (fr(x.real + h) - fr(x.real - h)) / (2 * h), atol=1e-6)


@H
@given(duals)
def test_dual_trigonometry_5_134(t):
    s, c = D.sin(t), D.cos(t)
    assert s.isclose(Dual(np.sin(t.real), t.dual * np.cos(t.real)))
    assert c.isclose(Dual(np.cos(t.real), -t.dual * np.sin(t.real)))
    assert (s * s + c * c).isclose(Dual(1.0, 0.0), atol=1e-12)
    assert D.atan2(s, c).isclose(
        Dual(np.arctan2(np.sin(t.real), np.cos(t.real)), t.dual), atol=1e-12
    )
    if abs(t.real) > 1e-3:
        assert D.sqrt(t * t).isclose(Dual(abs(t.real), np.sign(t.real) * t.dual), atol=1e-9)


def test_dual_bad_input():
    with pytest.raises(ValueError, match="atan2"):
        D.atan2(Dual(0.0, 1.0), Dual(0.0, 0.0))
    with pytest.raises(ValueError, match="negative"):
        D.sqrt(Dual(-1.0, 0.0))
    with pytest.raises(ValueError, match="not a dual number"):
        D.sqrt(Dual(0.0, 1.0))
    from anthroarm.errors import DualDivisionError

    with pytest.raises(
        DualDivisionError, match="zero real part"
    ):  # a ValueError, not ZeroDivisionError
        Dual(1.0, 1.0) / Dual(0.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        Dual(np.nan, 0.0)
    with pytest.raises(ValueError, match=r"\|real part\| < 1"):
        D.acos(Dual(1.0, 0.1))
    assert np.isinf(Dual(0.0, 2.0).pitch) and Dual(2.0, 1.0).pitch == 0.5  # (5-132)


# ----------------------------------------------------------------------------- lines
@H
@given(vec3, unit3, vec3)
def test_line_5_135_to_5_140_and_5_144(p, u, A):
    L = Line.from_point_direction(p, u)
    assert np.isclose(L.u @ L.u, 1.0) and abs(L.u @ L.moment) < 1e-12  # (5-144)
    d = L.foot()  # (5-138)
    assert (
        abs(d @ L.u) < 1e-12 and L.distance_to_point(d) < 1e-12 and L.distance_to_point(p) < 1e-12
    )
    assert np.allclose(np.cross(d, L.u), L.moment)  # (5-137)
    LA = L.moved(A)  # (5-140): the same line referred to A
    assert np.allclose(LA.moment, np.cross(p - A, u))
    n = D.norm(L.as_dual())
    assert n.isclose(Dual(1.0, 0.0), atol=1e-12)  # (5-143)


@H
@given(vec3, unit3, rotation(), vec3)
def test_line_transforms_like_pinocchio_motion(p, u, R, t):
    L = Line.from_point_direction(p, u)
    M = pin.SE3(R, t)
    Lt = L.transformed(R, t)
    m = M.act(L.as_motion())
    assert np.allclose(Lt.u, m.angular) and np.allclose(Lt.moment, m.linear)
    # passive dual matrix (5-145): coordinates of the line in the frame M
    A = D.dual_matrix_from_se3(R, t)
    L2 = D.transform_line(A, L)
    mi = M.actInv(L.as_motion())
    assert np.allclose(L2.u, mi.angular, atol=1e-12) and np.allclose(
        L2.moment, mi.linear, atol=1e-12
    )
    R2, t2 = D.se3_from_dual_matrix(A)
    assert np.allclose(R2, R) and np.allclose(t2, t)


@H
@given(vec3, unit3, vec3, unit3)
def test_dual_angle_5_133_and_products_5_141(p1, u1, p2, u2):
    a, b = Line.from_point_direction(p1, u1), Line.from_point_direction(p2, u2)
    th, n = D.line_dual_angle(a, b)
    if n is None:
        return
    A, B = a.as_dual(), b.as_dual()
    assert D.dot(A, B).isclose(D.cos(th), atol=1e-9)  # â·b̂ = cos θ̂
    if np.linalg.norm(np.cross(u1, u2)) > 1e-3:
        # common perpendicular line through the foot on a
        pa = p1 + u1 * (np.linalg.solve(np.c_[u1, -u2, n], p2 - p1)[0])
        S = Line(n, np.cross(pa, n)).as_dual()
        assert D.cross(A, B).isclose(S * D.sin(th), atol=1e-9)  # â×b̂ = ŝ sin θ̂
        # θ* is the shortest distance between the lines
        assert np.isclose(abs(th.dual), abs((p2 - p1) @ n))


def test_dual_angle_special_cases():
    x = Line.from_point_direction([0, 0, 0], [1, 0, 0])
    assert D.line_dual_angle(x, Line.from_point_direction([0, 0, 0], [0, 1, 0]))[0].isclose(
        Dual(np.pi / 2, 0.0)
    )  # intersecting
    th, n = D.line_dual_angle(x, Line.from_point_direction([0, 0, 2], [1, 0, 0]))
    assert th.isclose(Dual(0.0, 2.0)) and np.allclose(n, [0, 0, 1])  # parallel: pure dual angle
    assert D.line_dual_angle(x, x)[1] is None
    with pytest.raises(ValueError, match="not a line"):
        Line([1.0, 0, 0], [1.0, 0, 0])
    with pytest.raises(ValueError, match="zero length"):
        Line.from_point_direction([0, 0, 0], [0, 0, 0])


# ----------------------------------------------------------------------------- dual matrices
@H
@given(angle, small)
def test_basic_screw_matrices_5_146_to_5_149(phi, ps):
    for k, (fn, ax) in enumerate(((D.screw_x, "x"), (D.screw_y, "y"), (D.screw_z, "z"))):
        A = fn(phi, ps)
        e = np.eye(3)[k]
        M = pin.exp6(
            pin.Motion(ps * e, phi * e)
        )  # rotation φ about and translation φ* along the axis
        B = D.dual_matrix_from_se3(M.rotation, M.translation)
        assert np.allclose(A.real, B.real, atol=1e-14) and np.allclose(A.dual, B.dual, atol=1e-14)
        assert np.allclose(A.dual, A.real @ (ps * D.P_matrix(ax)))  # = φ_x (I + ε φ* P_x)
        assert np.allclose(A.real, pin.utils.rotate(ax, phi).T)  # passive
        D.check_dual_orthogonal(A)
        assert (A @ A.T).isclose(Dual(np.eye(3), np.zeros((3, 3))), atol=1e-12)


def test_pure_translation_5_150():
    A = D.screw_x(0, 0.3) @ D.screw_y(0, -0.2) @ D.screw_z(0, 0.5)
    B = D.translation_dual(0.3, -0.2, 0.5)
    assert A.isclose(B)
    R, p = D.se3_from_dual_matrix(B)
    assert np.allclose(R, np.eye(3)) and np.allclose(p, [0.3, -0.2, 0.5])


@H
@given(rotation(), vec3, rotation(), vec3)
def test_dual_matrix_composition_matches_se3(R1, p1, R2, p2):
    M1, M2 = pin.SE3(R1, p1), pin.SE3(R2, p2)
    A1, A2 = D.dual_matrix_from_se3(R1, p1), D.dual_matrix_from_se3(R2, p2)
    M = M1 * M2  # frame 3 in frame 1; passive composition reverses the order
    A = A2 @ A1
    R, p = D.se3_from_dual_matrix(A)
    assert np.allclose(R, M.rotation, atol=1e-12) and np.allclose(p, M.translation, atol=1e-12)
    Ai = A.T  # inverse = transpose (principle of transference)
    Ri, pi_ = D.se3_from_dual_matrix(Ai)
    assert np.allclose(Ri, M.inverse().rotation, atol=1e-12) and np.allclose(
        pi_, M.inverse().translation, atol=1e-12
    )


def test_non_dual_orthogonal_rejected():
    A = D.screw_x(0.3, 0.1)
    bad = Dual(A.real, A.dual + 0.1 * np.eye(3))
    with pytest.raises(ValueError, match="not dual-orthogonal"):
        D.se3_from_dual_matrix(bad)
    with pytest.raises(ValueError, match="not orthogonal"):
        D.check_dual_orthogonal(Dual(2 * np.eye(3), np.zeros((3, 3))))
