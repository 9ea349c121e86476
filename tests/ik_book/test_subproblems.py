"""IK-Geo subproblems SP1–SP6 (anthroarm.ik.subproblems).

Oracles: random constructions with known answers (pick θ, build the data from rot(k, θ) with
scipy's rotation, not the module's); the equations themselves (residuals); hand-built
degenerate cases (parallel axes, zero vectors, tangent circles, no solution → least squares
flagged).  PyPI ik-geo 1.0.3 does not expose its subproblems to Python (only whole-robot IK),
so it is compared in test_subproblems_ikgeo.py on a full arm instead."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from anthroarm.errors import ParameterError
from anthroarm.ik import subproblems as sp

N = 400


def unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def R(k, t, p):
    """rot(k, θ) p through scipy (independent of the code under test)."""
    return Rotation.from_rotvec(np.asarray(k) * np.asarray(t)[..., None]).apply(p)


def angdiff(a, b):
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def found(theta, truth):
    """Per problem: smallest max-angle distance between a returned solution and the truth."""
    e = angdiff(theta, truth[:, None]).max(-1)
    return np.nanmin(np.where(np.isnan(e), np.inf, e), 1)


def test_rot_matches_scipy():
    rng = np.random.default_rng(0)
    k, t = unit(rng, 50), rng.uniform(-4, 4, 50)
    assert np.allclose(sp.rot(k, t), Rotation.from_rotvec(k * t[:, None]).as_matrix(), atol=1e-14)


def test_sp1_random():
    rng = np.random.default_rng(1)
    k, p1, t = unit(rng, N), rng.normal(size=(N, 3)), rng.uniform(-np.pi, np.pi, N)
    r = sp.sp1(p1, R(k, t, p1), k)
    assert r.theta.shape == (N, 1, 1) and r.exact.all() and not r.singular.any()
    assert angdiff(r.theta[:, 0, 0], t).max() < 1e-12


def test_sp1_least_squares_and_single():
    k, p1 = np.array([0, 0, 1.0]), np.array([1.0, 0, 0])
    r = sp.sp1(p1, [0, 2.0, 0.5], k)  # longer and higher: no exact rotation
    assert r.count == 1 and not r.exact[0] and abs(r.theta[0, 0] - np.pi / 2) < 1e-14
    r = sp.sp1(k, k, k)  # p1 ∥ k: every θ, singular, exact
    assert r.singular and r.exact[0] and r.theta[0, 0] == 0.0


def test_sp4_random_two_solutions():
    rng = np.random.default_rng(2)
    h, k, p, t = unit(rng, N), unit(rng, N), rng.normal(size=(N, 3)), rng.uniform(-np.pi, np.pi, N)
    d = np.einsum("ni,ni->n", h, R(k, t, p))
    r = sp.sp4(h, p, k, d)
    assert found(r.theta, t[:, None]).max() < 1e-6
    for s in range(2):  # every returned solution solves it
        ok = r.valid[:, s]
        res = np.einsum("ni,ni->n", h, R(k, r.theta[:, s, 0], p)) - d
        assert np.abs(res[ok]).max() < 1e-9 and r.exact[ok, s].all()
    assert (r.count == 2).mean() > 0.95


def test_sp4_tangent_and_least_squares():
    h, k, p = np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([2.0, 0, 0.3])
    r = sp.sp4(h, p, k, 2.0)  # plane tangent to the circle: θ = 0 once
    assert r.count == 1 and r.exact[0] and abs(r.theta[0, 0]) < 1e-12
    r = sp.sp4(h, p, k, 3.0)  # out of reach: LS = the closest point
    assert r.count == 1 and not r.exact[0] and abs(r.theta[0, 0]) < 1e-12
    r = sp.sp4(h, p, k, -2.5)
    assert r.count == 1 and not r.exact[0] and abs(abs(r.theta[0, 0]) - np.pi) < 1e-12
    r = sp.sp4(k, p, k, 0.3)  # h ∥ k: height independent of θ
    assert r.singular and r.exact[0]
    r = sp.sp4(k, p, k, 0.4)
    assert r.singular and not r.exact[0]


def test_sp3_random_and_cases():
    rng = np.random.default_rng(3)
    k, p1, p2, t = (
        unit(rng, N),
        rng.normal(size=(N, 3)),
        rng.normal(size=(N, 3)),
        rng.uniform(-np.pi, np.pi, N),
    )
    d = np.linalg.norm(R(k, t, p1) - p2, axis=1)
    r = sp.sp3(p1, p2, k, d)
    for s in range(2):
        ok = r.valid[:, s]
        res = np.linalg.norm(R(k, r.theta[:, s, 0], p1) - p2, axis=1) - d
        assert np.abs(res[ok]).max() < 1e-9
    e = found(r.theta, t[:, None])
    assert np.all((e < 1e-6) | (r.count == 1))  # a merged near-tangent pair is exact to tol
    assert r.exact[r.valid].all()
    k, p1 = np.array([0, 0, 1.0]), np.array([1.0, 0, 0])
    r = sp.sp3(p1, [3.0, 0, 0], k, 2.0)  # sphere touches the circle at θ = 0
    assert r.count == 1 and r.exact[0] and abs(r.theta[0, 0]) < 1e-6
    r = sp.sp3(p1, [3.0, 0, 0], k, 1.0)  # too small: LS, closest point θ = 0
    assert r.count == 1 and not r.exact[0] and abs(r.theta[0, 0]) < 1e-12
    r = sp.sp3(p1, [0, 0, 0.0], k, 1.0)  # zero p2: every θ (distance ‖p1‖)
    assert r.singular and r.exact[0]


def test_sp2_random_and_cases():
    rng = np.random.default_rng(4)
    k1, k2, p1 = unit(rng, N), unit(rng, N), rng.normal(size=(N, 3))
    t = rng.uniform(-np.pi, np.pi, (N, 2))
    p2 = R(k2, -t[:, 1], R(k1, t[:, 0], p1))
    r = sp.sp2(p1, p2, k1, k2)
    assert found(r.theta, t).max() < 1e-6
    for s in range(2):
        ok = r.valid[:, s]
        res = np.linalg.norm(R(k1, r.theta[:, s, 0], p1) - R(k2, r.theta[:, s, 1], p2), axis=1)
        assert res[ok].max() < 1e-9 and r.exact[ok, s].all()
    x, z = np.array([1.0, 0, 0]), np.array([0, 0, 1.0])
    r = sp.sp2([1.0, 0, 0], [0, 0, 2.0], z, x)  # different norms: LS, flagged
    assert not r.exact[r.valid].any()
    r = sp.sp2([1.0, 0, 0.2], [0, 1.0, 0.2], z, z)  # parallel axes: a family
    assert r.singular and r.exact[0]
    r = sp.sp2([0, 0, 0.0], [0, 0, 0.0], z, x)  # zero vectors
    assert r.singular and r.exact[0]


def test_sp5_random():
    rng = np.random.default_rng(5)
    k1, k2, k3 = unit(rng, N), unit(rng, N), unit(rng, N)
    p1, p2, p3 = (rng.normal(size=(N, 3)) for _ in range(3))
    t = rng.uniform(-np.pi, np.pi, (N, 3))
    p0 = R(k2, t[:, 1], p2 + R(k3, t[:, 2], p3)) - R(k1, t[:, 0], p1)
    r = sp.sp5(p0, p1, p2, p3, k1, k2, k3)
    assert r.theta.shape == (N, 4, 3)
    assert found(r.theta, t).max() < 1e-6
    for s in range(4):
        ok = r.valid[:, s]
        th = np.nan_to_num(r.theta[:, s])
        res = np.linalg.norm(
            p0 + R(k1, th[:, 0], p1) - R(k2, th[:, 1], p2 + R(k3, th[:, 2], p3)), axis=1
        )
        assert res[ok].max() < 1e-7
    r = sp.sp5(p0[0], p1[0], p2[0], p3[0], k1[0], k1[0], k3[0])  # k2 ∥ k1: outside SP5's form
    assert r.singular and r.count == 0


def test_sp6_random_and_no_solution():
    rng = np.random.default_rng(6)
    H, K, P = (
        unit(rng, 4 * N).reshape(N, 4, 3),
        unit(rng, 4 * N).reshape(N, 4, 3),
        rng.normal(size=(N, 4, 3)),
    )
    t = rng.uniform(-np.pi, np.pi, (N, 2))
    term = lambda i, tt: np.einsum("ni,ni->n", H[:, i], R(K[:, i], tt, P[:, i]))  # noqa: E731
    d1, d2 = term(0, t[:, 0]) + term(1, t[:, 1]), term(2, t[:, 0]) + term(3, t[:, 1])
    r = sp.sp6(H, K, P, d1, d2)
    assert found(r.theta, t).max() < 1e-6
    for s in range(4):
        ok = r.valid[:, s]
        th = np.nan_to_num(r.theta[:, s])
        assert np.abs(term(0, th[:, 0]) + term(1, th[:, 1]) - d1)[ok].max() < 1e-7
        assert np.abs(term(2, th[:, 0]) + term(3, th[:, 1]) - d2)[ok].max() < 1e-7
    big = np.abs(P).sum((1, 2)) * 10
    r = sp.sp6(H, K, P, big, big)  # unreachable heights
    assert (r.count == 0).all() and not r.valid.any()


def test_single_and_broadcast_shapes():
    rng = np.random.default_rng(7)
    k, p = unit(rng, 1)[0], rng.normal(size=3)
    one = sp.sp4(k, p, [0, 0, 1.0], 0.1)
    assert one.theta.shape == (2, 1) and isinstance(one.count, int)
    many = sp.sp4(k, np.tile(p, (5, 1)), [0, 0, 1.0], np.full(5, 0.1))  # single h, k broadcast
    assert many.theta.shape == (5, 2, 1)
    assert np.allclose(np.nan_to_num(many.theta[3]), np.nan_to_num(one.theta))


@pytest.mark.parametrize(
    "call",
    [
        lambda: sp.sp1([1, 0, 0], [0, 1, 0], [0, 0, 2.0]),  # axis not unit
        lambda: sp.sp1([1, 0, 0], [0, 1, 0], [0, 0, 0.0]),  # zero axis
        lambda: sp.sp1([1, 0], [0, 1, 0], [0, 0, 1.0]),  # shape
        lambda: sp.sp1([1, np.nan, 0], [0, 1, 0], [0, 0, 1.0]),  # NaN
        lambda: sp.sp4([1, 0, 0], np.zeros((3, 3)), [0, 0, 1.0], np.zeros(4)),  # batch sizes
        lambda: sp.sp3([1, 0, 0], [0, 1, 0], [0, 0, 1.0], -1.0),  # negative radius
        lambda: sp.sp1([1, 0, 0], [0, 1, 0], [0, 0, 1.0], tol=0),  # tol
        lambda: sp.sp6(np.eye(3), np.eye(3), np.eye(3), 0, 0),  # SP6 needs 4 rows
        lambda: sp.sp1("abc", [0, 1, 0], [0, 0, 1.0]),
    ],
)
def test_bad_input_is_typed(call):
    with pytest.raises(ParameterError):
        call()


def test_compiled_atan2_is_the_c_librarys_within_two_ulps():
    """vec3.atan2 (Cephes' rational atan, branch-free) against math.atan2 (the C library):
    within 2 units in the last place over ratios spanning the doubles, and the same value —
    sign of zero included — at zeros, infinities, NaN and subnormals."""
    import math

    import numba

    from anthroarm.ik.vec3 import atan2

    @numba.njit
    def rows(Y, X, out):
        for i in range(len(Y)):
            out[i] = atan2(Y[i], X[i])

    rng = np.random.default_rng(3)
    N = 400_000
    Y = rng.normal(size=N) * 10.0 ** rng.uniform(-300, 300, N)
    X = rng.normal(size=N) * 10.0 ** rng.uniform(-300, 300, N)
    Y[: N // 2], X[: N // 2] = rng.normal(size=N // 2), rng.normal(size=N // 2)
    got = np.empty(N)
    rows(Y, X, got)
    ref = np.array([math.atan2(y, x) for y, x in zip(Y, X)])
    assert (np.abs(got - ref) <= 2 * np.spacing(np.abs(ref))).all()
    special = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        2.0,
        math.inf,
        -math.inf,
        math.nan,
        5e-324,
        -5e-324,
        1e308,
        -1e308,
    ]
    for y in special:
        for x in special:
            a, b = math.atan2(y, x), atan2(y, x)
            assert (math.isnan(a) and math.isnan(b)) or (
                a == b and math.copysign(1.0, a) == math.copysign(1.0, b)
            ), (y, x, a, b)
