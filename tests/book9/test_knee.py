"""Four-bar polycentric knee (book §2-5, Fig. 2-18) on the §5-3 four-bar solver: flexion against
a Pinocchio closed loop, the ICR against the zero-velocity point of finite differences and a
direct line intersection, Radcliffe's (1994) TKA stability margin, and bad input."""

import numpy as np
import pytest

from anthroarm.mechanisms.closed_loop import ClosedLoop
from anthroarm.mechanisms.knee import (
    KneeGeometry,
    default_knee,
    icr_path,
    knee_flexion,
    knee_pose,
    stability_margin,
)
from anthroarm.mechanisms.pin_models import fourbar_spec
from anthroarm.models.book_tables import lower_limb_limits

K = default_knee()


def wrap(a):
    return np.angle(np.exp(1j * np.asarray(a)))


def test_extension_is_the_given_geometry():
    st = knee_flexion(K, 0.0)
    assert st.ok[0] and abs(st.flexion[0]) < 1e-12
    np.testing.assert_allclose(st.dist_ant[0], K.dist_ant, atol=1e-12)
    np.testing.assert_allclose(st.dist_post[0], K.dist_post, atol=1e-12)
    np.testing.assert_allclose(st.ankle[0], K.ankle, atol=1e-12)


def test_link_lengths_are_kept_over_flexion():
    st = icr_path(K, np.radians(120), 25)
    assert st.ok.all()
    r1, r2, r3, r4 = K.lengths
    np.testing.assert_allclose(np.linalg.norm(st.dist_ant - K.prox_ant, axis=1), r2, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(st.dist_post - K.prox_post, axis=1), r4, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(st.dist_post - st.dist_ant, axis=1), r3, atol=1e-12)
    # the ankle is rigid with the distal link
    np.testing.assert_allclose(
        np.linalg.norm(st.ankle - st.dist_ant, axis=1),
        np.linalg.norm(K.ankle - K.dist_ant),
        atol=1e-12,
    )


def test_table_2_4_knee_flexion_is_reached():
    lo, hi = lower_limb_limits()["knee_flexion"]
    st = knee_flexion(K, [lo, hi])
    assert st.ok.all()
    np.testing.assert_allclose(st.flexion, [0.0, np.radians(120)], atol=1e-10)


def test_flexion_equals_pinocchio_closed_loop():
    """The same linkage as a Pinocchio tree + RigidConstraint closure (mechanisms.closed_loop),
    ground rotated onto +x: the coupler angle for the same crank input."""
    r1, r2, r3, r4 = K.lengths
    g = K.prox_post - K.prox_ant
    gam = np.arctan2(g[1], g[0])
    loop = ClosedLoop(fourbar_spec(r1, r2, r3, r4))
    st = icr_path(K, np.radians(110), 12)
    th3_ext = np.arctan2(*(K.dist_post - K.dist_ant)[::-1])
    for th2, flex, A, B in zip(st.theta2, st.flexion, st.dist_ant, st.dist_post):
        c = B - A
        guess = np.arctan2(c[1], c[0]) - gam
        d = K.prox_post + 0 * A
        th4 = np.arctan2(*(B - d)[::-1]) - gam
        sol = loop.solve([th2 - gam], q0=[th2 - gam, guess - (th2 - gam) + 0.01, th4 - 0.01])
        assert sol.ok
        th3_pin = sol.q[0] + sol.q[1] + gam
        assert abs(wrap(-(th3_pin - th3_ext) - flex)) < 1e-9


def test_icr_is_the_zero_velocity_point_by_finite_differences():
    st = icr_path(K, np.radians(120), 13)
    h = 1e-6
    for th2, icr in zip(st.theta2, st.icr):
        p, m = knee_pose(K, th2 + h), knee_pose(K, th2 - h)
        v = (p.dist_ant[0] - m.dist_ant[0]) / (2 * h)  # dA/dθ2
        w = -(p.flexion[0] - m.flexion[0]) / (2 * h)  # dθ3/dθ2 (flexion = -Δθ3)
        A = knee_pose(K, th2).dist_ant[0]
        c = A + np.array([-v[1], v[0]]) / w  # C = P + k × v / ω
        np.testing.assert_allclose(icr, c, atol=1e-7)


def test_icr_is_the_intersection_of_the_link_lines():
    st = knee_flexion(K, np.radians([0, 30, 90]))
    for icr, A, B in zip(st.icr, st.dist_ant, st.dist_post):
        M = np.column_stack([A - K.prox_ant, -(B - K.prox_post)])
        t = np.linalg.solve(M, K.prox_post - K.prox_ant)
        np.testing.assert_allclose(icr, K.prox_ant + t[0] * (A - K.prox_ant), atol=1e-12)


def test_moving_centrode_maps_back_to_the_fixed_one():
    st = icr_path(K, np.radians(120), 13)
    for f, icr, ics, A in zip(st.flexion, st.icr, st.icr_shank, st.dist_ant):
        c, s = np.cos(-f), np.sin(-f)  # shank turned by -flexion
        R = np.array([[c, -s], [s, c]])
        np.testing.assert_allclose(A + R @ (ics - K.dist_ant), icr, atol=1e-12)


def test_radcliffe_stability_margin():
    """TKA line vertical through x0: the margin is x0 - x_ICR (exact); stable (> 0) with the hip
    above the ankle, unstable when the hip is aligned 6 cm posterior."""
    icr = knee_flexion(K, 0.0).icr[0]
    assert icr[1] > 0.05  # a high (proximal) ICR at extension
    assert stability_margin(K, (0.0, 0.45)) == pytest.approx(0.0 - icr[0], abs=1e-12)
    assert stability_margin(K, (0.0, 0.45)) > 0
    # hip 6 cm posterior: at the height of the ICR the TKA line passes behind it
    hip = np.array([-0.06, 0.45])
    x_line = hip[0] + (K.ankle[0] - hip[0]) * (icr[1] - hip[1]) / (K.ankle[1] - hip[1])
    assert x_line < icr[0]
    assert stability_margin(K, hip) < 0


def test_unreachable_flexion_is_a_status_not_nan():
    st = knee_flexion(K, np.radians([60, 400]))
    assert st.ok.tolist() == [True, False]
    assert st.status[1] == "cannot_assemble"
    assert (
        np.isfinite(st.icr).all() and np.isfinite(st.flexion).all() and np.isfinite(st.ankle).all()
    )


def test_parallel_links_have_no_finite_icr():
    # a parallelogram: the links stay parallel, the ICR is at infinity
    par = KneeGeometry(
        prox_ant=(0.01, 0.03),
        prox_post=(-0.01, 0.03),
        dist_ant=(0.01, -0.01),
        dist_post=(-0.01, -0.01),
        ankle=(0.0, -0.4),
    )
    st = knee_pose(par, -np.pi / 2)
    assert st.status[0] == "parallel_links" and not st.ok[0]
    assert np.isfinite(st.icr).all()
    with pytest.raises(ValueError, match="no finite ICR"):
        stability_margin(par, (0.0, 0.45))


def test_bad_geometry_is_a_value_error():
    with pytest.raises(ValueError, match="anterior link has zero length"):
        KneeGeometry(
            prox_ant=(0, 0),
            prox_post=(-0.01, 0),
            dist_ant=(0, 0),
            dist_post=(-0.01, -0.04),
            ankle=(0, -0.4),
        )
    with pytest.raises(ValueError):
        KneeGeometry(
            prox_ant=(np.nan, 0),
            prox_post=(-0.01, 0),
            dist_ant=(0, -0.04),
            dist_post=(-0.01, -0.04),
            ankle=(0, -0.4),
        )
    with pytest.raises(ValueError, match="n must be"):
        icr_path(K, 1.0, n=1)
