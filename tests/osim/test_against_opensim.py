"""The .osim import against OpenSim itself (issue 32 item 4): for every shipped model, random
states inside the coordinate ranges — every body's pose in ground, every marker, the mass
matrix (``SimbodyMatterSubsystem.calcM``), gravity and inverse-dynamics torques
(``InverseDynamicsSolver``) — in the independent coordinates (see
:class:`anthroarm.osim.checks.OpenSimModel` for the mobility order and the projection of a
coupled coordinate).

The issue's tolerances: poses and markers to 1e-12 m where every transform is constant or
linear, 1e-9 m with splines; M, g and τ to 1e-9 relative (to the largest entry, at least 1).
500 states per model, as the issue asks (~15 s for the five models).  Skipped only when
``opensim`` is not installed (CI installs the test extra).
"""

from __future__ import annotations

import numpy as np
import pytest

opensim = pytest.importorskip("opensim")


import anthroarm as aa  # noqa: E402
from anthroarm.osim import names, path  # noqa: E402
from anthroarm.osim.checks import OpenSimModel  # noqa: E402

#: models whose transform axes hold splines (looser pose tolerance, as the issue says)
SPLINES = {"leg6dof9musc", "gait2392", "subject01_simbody"}


def compare(name: str, n: int, seed: int = 0) -> dict:
    """Largest differences between the import and OpenSim on ``n`` random states."""
    robot = aa.load(path(name))
    oracle = OpenSimModel(path(name), robot.joint_names)
    rng = np.random.default_rng(seed)
    Q = robot.random_q(n, rng)
    QD = rng.normal(size=Q.shape)
    QDD = rng.normal(size=Q.shape)
    bodies, markers = {}, {}
    err = dict(body=0.0, marker=0.0, M=0.0, g=0.0, tau=0.0)
    for i, (q, qd, qdd) in enumerate(zip(Q, QD, QDD)):
        C, _ = oracle.set_state(q)
        for b, H in oracle.poses().items():
            bodies.setdefault(b, np.empty((n, 4, 4)))[i] = H
        for mk, p in oracle.markers().items():
            markers.setdefault(mk, np.empty((n, 3)))[i] = p
        Mo = oracle.mass_matrix(C)
        go = oracle.inverse_dynamics(C, np.zeros(oracle.nu))
        err["M"] = max(err["M"], np.abs(robot.mass_matrix(q) - Mo).max() / max(1, np.abs(Mo).max()))
        err["g"] = max(err["g"], np.abs(robot.gravity(q) - go).max() / max(1, np.abs(go).max()))
        C, udot = oracle.set_state(q, qd, qdd)
        to = oracle.inverse_dynamics(C, udot)
        tau = robot.inverse_dynamics(q, qd, qdd)
        err["tau"] = max(err["tau"], np.abs(tau - to).max() / max(1, np.abs(to).max()))
    assert set(bodies) <= set(robot.frame_names), "every OpenSim body is a frame of the Robot"
    assert sorted(markers) == sorted(robot.markers)
    for b, H in bodies.items():  # batched FK (robot.chain) of all states at once
        err["body"] = max(err["body"], np.abs(robot.fk(Q, b) - H).max())
    for mk, P in markers.items():
        err["marker"] = max(err["marker"], np.abs(robot.fk(Q, mk)[:, :3, 3] - P).max())
    q = Q[0]  # and the one-configuration path (Pinocchio directly)
    oracle.set_state(q)
    for b, H in oracle.poses().items():
        err["body"] = max(err["body"], np.abs(robot.fk(q, b) - H).max())
    err.update(states=n, bodies=len(bodies), markers=len(markers), nq=robot.nq)
    return err


def check(name: str, n: int) -> None:
    e = compare(name, n)
    tol_pose = 1e-9 if name in SPLINES else 1e-12
    assert e["body"] <= tol_pose, e
    assert e["marker"] <= tol_pose, e
    for k in ("M", "g", "tau"):
        assert e[k] <= 1e-9, (k, e)


@pytest.mark.parametrize("name", names())
def test_model_agrees_with_opensim_500_states(name):
    check(name, 500)


def test_gait_knee_translates_along_its_spline():
    """The coupling is not dropped: gait2392's tibia moves relative to the femur by the knee
    splines (the issue: 27 mm over the knee's range), as OpenSim moves it."""
    robot = aa.load(path("gait2392"))
    oracle = OpenSimModel(path("gait2392"), robot.joint_names)
    k = robot.joint_names.index("knee_angle_r")
    q = np.zeros(robot.nq)
    shifts = []
    for a in (robot.lower[k], robot.upper[k]):
        q[k] = a
        oracle.set_state(q)
        H = oracle.poses()
        rel_o = np.linalg.inv(H["femur_r"]) @ H["tibia_r"]
        rel = np.linalg.inv(robot.fk(q, "femur_r")) @ robot.fk(q, "tibia_r")
        assert np.abs(rel - rel_o).max() < 1e-12
        shifts.append(rel[:3, 3])
    travel = np.linalg.norm(shifts[1] - shifts[0])
    assert 0.02 < travel < 0.04  # ~27 mm: a plain revolute knee would give 0


def test_coupled_jacobian_is_the_derivative_of_fk():
    """J = J_pin G against central differences of the (coupled) FK, and against OpenSim's
    marker velocity: v = J q̇ (Simbody's ``Marker.getVelocityInGround``)."""
    robot = aa.load(path("subject01_simbody"))
    oracle = OpenSimModel(path("subject01_simbody"), robot.joint_names)
    rng = np.random.default_rng(3)
    q = robot.random_q(None, rng, margin=0.05)
    qd = rng.normal(size=robot.nq)
    oracle.set_state(q, qd)
    for mk in ("R.Heel", "L.Toe.Tip", "R.Knee.Lat"):
        J = robot.jacobian(q, mk)
        v = oracle.model.getMarkerSet().get(mk).getVelocityInGround(oracle.state)
        assert np.allclose(J[:3] @ qd, [v.get(i) for i in range(3)], atol=1e-12, rtol=0)
        h = 1e-6
        fd = np.column_stack(
            [
                (robot.fk(q + h * e, mk)[:3, 3] - robot.fk(q - h * e, mk)[:3, 3]) / (2 * h)
                for e in np.eye(robot.nq)
            ]
        )
        assert np.abs(J[:3] - fd).max() < 1e-8
    Jb = robot.jacobian(np.stack([q, q]), "R.Heel")  # the batched path equals the single one
    assert np.abs(Jb[1] - robot.jacobian(q, "R.Heel")).max() < 1e-14
