"""Human-arm dynamics analyses for ``human_arm7`` (book §6-3 arm with de Leva segment data).

* :func:`gravity_torque_map`: the static joint torques g(q) (N m) that hold the arm against
  gravity, over a grid of two joints' range of motion (the others fixed) — e.g. shoulder
  flexion × elbow flexion;
* :func:`reaching_torques`: τ(t) = M q̈ + C q̇ + g along a minimum-jerk reach in joint space,
  split into inertial, velocity (Coriolis/centrifugal) and gravity parts;
* plots of both.

Body parameters come from body height (m), mass (kg) and sex through
:func:`anthroarm.models.human.segment_parameters` (de Leva 1996, scaled).  The model hangs along
−z (arm down at q = 0), y forward, x right; the joint order is shoulder flexion, abduction,
rotation, elbow flexion, forearm pronation, wrist deviation, wrist flexion (rad).
Everything uses the generated Lagrange code of :mod:`.lagrange` (cached per body size).
"""

from __future__ import annotations

import numpy as np

from ..models import PERSON_ARM
from ..robot import load as load_robot
from .hand_model import minimum_jerk
from .lagrange import load


def human_arm(height: float = 1.75, mass: float = 75.0, sex: str = "male"):
    """(robot, dynamics) of the catalog's arm of a person (:data:`anthroarm.models.PERSON_ARM`,
    ``human_arm7``) for the given height/mass/sex."""
    robot = load_robot(PERSON_ARM, height=height, mass=mass, sex=sex)
    return robot, load(robot)


def _joint_index(robot, j):
    if isinstance(j, (int, np.integer)):
        if not 0 <= j < robot.nq:
            raise ValueError(f"joint index {j} out of range 0..{robot.nq - 1}")
        return int(j)
    if j not in robot.joint_names:
        raise ValueError(f"unknown joint {j!r}; joints: {robot.joint_names}")
    return robot.joint_names.index(j)


def gravity_torque_map(
    joints=("shoulder_flexion", "elbow_flexion"),
    grid: int = 41,
    base_q=None,
    height: float = 1.75,
    mass: float = 75.0,
    sex: str = "male",
    robot=None,
    dyn=None,
) -> dict:
    """Gravity torques over the range of motion of two joints.

    Returns dict(x, y (the two joints' grid values, rad), names, tau (grid, grid, 7) N m with
    tau[i, k] at (x[k], y[i]), q (the configurations), params)."""
    if robot is None or dyn is None:
        robot, dyn = human_arm(height, mass, sex)
    if not (isinstance(grid, (int, np.integer)) and 2 <= grid <= 2000):
        raise ValueError(f"grid must be an integer in 2..2000, got {grid}")
    a, b = (_joint_index(robot, j) for j in joints)
    if a == b:
        raise ValueError("choose two different joints")
    q0 = robot.neutral() if base_q is None else robot.check_q(base_q, "base_q")
    x = np.linspace(robot.lower[a], robot.upper[a], grid)
    y = np.linspace(robot.lower[b], robot.upper[b], grid)
    X, Y = np.meshgrid(x, y)
    Q = np.tile(q0, (X.size, 1))
    Q[:, a] = X.ravel()
    Q[:, b] = Y.ravel()
    tau = dyn.gravity(Q).reshape(grid, grid, robot.nq)
    params = dict(height=height, mass=mass, sex=sex)
    spec_params = robot.spec.params if robot.spec is not None else {}
    params.update({k: spec_params[k] for k in params if k in spec_params})  # the body actually used
    return dict(
        x=x,
        y=y,
        names=(robot.joint_names[a], robot.joint_names[b]),
        joint_names=robot.joint_names,
        tau=tau,
        q=Q.reshape(grid, grid, robot.nq),
        params=params,
    )


def reaching_torques(
    q_start,
    q_goal,
    duration: float = 0.8,
    samples: int = 101,
    height: float = 1.75,
    mass: float = 75.0,
    sex: str = "male",
    robot=None,
    dyn=None,
) -> dict:
    """Joint torques along a minimum-jerk reach from ``q_start`` to ``q_goal`` (rad) in
    ``duration`` s.  Returns dict(t, q, qd, qdd, tau, inertial = M q̈, velocity = C q̇,
    gravity = g, peak = max |τ| per joint)."""
    if robot is None or dyn is None:
        robot, dyn = human_arm(height, mass, sex)
    q0 = robot.check_q(q_start, "q_start")
    q1 = robot.check_q(q_goal, "q_goal")
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0 s, got {duration}")
    t = np.linspace(0.0, duration, samples)
    q, qd, qdd = minimum_jerk(q0, q1, duration, t)
    M = dyn.mass_matrix(q)
    inertial = np.einsum("nij,nj->ni", M, qdd)
    vel = dyn.coriolis(q, qd)
    grav = dyn.gravity(q)
    tau = dyn.tau(q, qd, qdd)
    return dict(
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        inertial=inertial,
        velocity=vel,
        gravity=grav,
        peak=np.max(np.abs(tau), axis=0),
        joint_names=robot.joint_names,
    )


def plot_gravity_map(result: dict, joint: int | str = 0, ax=None):
    """Contour plot of one joint's gravity torque over the two-joint grid (degrees on the axes)."""
    import matplotlib.pyplot as plt

    k = result["joint_names"].index(joint) if isinstance(joint, str) else int(joint)
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 4))
    cs = ax.contourf(
        np.degrees(result["x"]),
        np.degrees(result["y"]),
        result["tau"][:, :, k],
        levels=21,
        cmap="RdBu_r",
    )
    plt.colorbar(cs, ax=ax, label=f"{result['joint_names'][k]} torque [N m]")
    ax.set_xlabel(f"{result['names'][0]} [deg]")
    ax.set_ylabel(f"{result['names'][1]} [deg]")
    p = result["params"]
    ax.set_title(f"gravity torque, {p['sex']} {p['height']} m {p['mass']} kg")
    return ax


def plot_reaching(result: dict, axes=None):
    """τ(t) per joint and its split into inertial / velocity / gravity parts (joint with the
    largest peak)."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    t = result["t"]
    for j, name in enumerate(result["joint_names"]):
        axes[0].plot(t, result["tau"][:, j], label=name)
    axes[0].set_xlabel("t [s]")
    axes[0].set_ylabel("τ [N m]")
    axes[0].legend(fontsize=7)
    k = int(np.argmax(result["peak"]))
    for key in ("inertial", "velocity", "gravity"):
        axes[1].plot(t, result[key][:, k], label=key)
    axes[1].plot(t, result["tau"][:, k], "k--", label="total")
    axes[1].set_title(result["joint_names"][k])
    axes[1].set_xlabel("t [s]")
    axes[1].legend(fontsize=7)
    return axes
