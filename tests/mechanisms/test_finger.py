"""Index-finger six-bar of §6-5 (Fig. 6-14, our bar lengths): the printed Chapter 3 curves, the
fingertip on f(x), Pinocchio closed loops and finite differences, bad geometry, the design
that reproduces the default."""

import numpy as np
import pytest

from anthroarm.mechanisms._util import fd_derivative
from anthroarm.mechanisms.closed_loop import ClosedLoop
from anthroarm.mechanisms.finger import FingerGeometry, design_finger, finger, finger_f, finger_spec
from anthroarm.mechanisms.thumb import thumb_f2, thumb_f3

FG = FingerGeometry.default()


def test_chapter3_curves_printed_values():
    # ch3-4.md E1/E3 derived values of the printed polynomials
    np.testing.assert_allclose(
        finger_f([0, 10, 20, 30, 40]), [55.61, 65.255, 71.618, 74.831, 75.026], atol=1e-3
    )
    np.testing.assert_allclose(thumb_f2([30, 60]), [6.9247, 19.8264], atol=1e-4)
    np.testing.assert_allclose(thumb_f3([20, 30]), [40.3547, 55.6754], atol=1e-4)


def test_finger_follows_the_chapter3_curve():
    ph = np.linspace(*FG.phi_range, 201)
    s = finger(FG, ph)
    assert (np.asarray(s.status) == "ok").all()
    tip = s.tip * 1e3
    assert abs(tip[0, 0]) < 1e-3 and abs(tip[-1, 0] - 40) < 5e-3
    assert np.max(np.abs(tip[:, 1] - finger_f(tip[:, 0]))) < 0.1  # mm
    flex = np.sign(FG.phi_range[1] - FG.phi_range[0]) * (s.q - s.q[0])
    # PIP and DIP flex with the MCP (human-like), apart from < 0.1 deg of extension at the start
    assert (flex[:, 1:] >= np.deg2rad(-0.1)).all() and (flex[-1, 1:] > 0.1).all()
    assert np.max(np.abs(s.residual)) < 1e-15


def test_finger_against_pinocchio_and_finite_differences():
    loop = ClosedLoop(finger_spec(FG))
    p0, p1 = FG.phi_range
    ph = p0 + 0.6 * (p1 - p0)
    w, a = 1.1, -0.5
    Q, ok = loop.track(np.linspace(0, ph - p0, 7)[:, None])
    st_ = loop.solve([ph - p0], [w], [a], q0=Q[-1])
    s = finger(FG, ph, w, a)
    L = FG.length_scale
    assert ok.all() and st_.ok
    sc = max(1.0, np.abs(s.accelerations["P8"]).max() / L)
    np.testing.assert_allclose(loop.frame_position(st_.q, "P8")[:2], s.tip, atol=1e-14 * L)
    np.testing.assert_allclose(
        loop.frame_velocity(st_.q, st_.v, "P8")[:2], s.velocities["P8"], atol=1e-12 * L * sc
    )
    np.testing.assert_allclose(
        loop.frame_acceleration(st_.q, st_.v, st_.a, "P8")[:2],
        s.accelerations["P8"],
        atol=1e-11 * L * sc,
    )
    np.testing.assert_allclose(
        st_.v[[loop.joint_q_index(n) for n in ("pip", "dip")]], s.qdot[1:], atol=1e-12 * sc
    )

    def traj(t):
        return finger(FG, ph + w * t + 0.5 * a * t * t, w + a * t, a)

    for k in ("P6", "P8"):
        np.testing.assert_allclose(
            fd_derivative(lambda t: traj(t).points[k], 2.5e-4), s.velocities[k], atol=1e-10 * L * sc
        )
        np.testing.assert_allclose(
            fd_derivative(lambda t: traj(t).velocities[k], 2.5e-4),
            s.accelerations[k],
            atol=1e-10 * L * sc,
        )


def test_finger_out_of_range_and_bad_geometry():
    s = finger(FG, FG.phi_range[1] - 2.5)
    assert s.status != "ok" and np.isfinite(s.tip).all()
    with pytest.raises(ValueError, match="R1..R8"):
        FingerGeometry(P1=[0, 0], P4=[1, 0], R=(1, 1, 1, 1, 1, 1, 1, -1), alpha=(0, 0, 0))
    with pytest.raises(ValueError, match="P4"):
        FingerGeometry(P1=[0, 0], P4=[1, 0, 0], R=(1,) * 8, alpha=(0, 0, 0))


def test_design_finger_reproduces_the_default():
    g, res, pose = design_finger(max_nfev=200)
    s = finger(g, np.linspace(*g.phi_range, 101))
    tip = s.tip * 1e3
    assert np.max(np.abs(tip[:, 1] - finger_f(tip[:, 0]))) < 0.1
