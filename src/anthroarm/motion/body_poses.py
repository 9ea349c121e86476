"""The world pose of every body along a motion, in one batched pass over the kinematic tree.

A recorded motion (marker IK's q for N frames) is played back, plotted or exported as the
poses of all bodies in every frame.  :func:`body_poses` computes them for a whole batch
Q (N, nq) in one walk down ``robot.chain`` (Pinocchio's joint order: a parent before its
children), each joint's placement once for all N configurations:

    ⁰T_j = ⁰T_parent(j) · M_j · exp(a_j θ_j)

with M_j the joint's constant placement in its parent, a_j its unit axis (revolute: the
rotation of Rodrigues' formula, R exp([a]× θ) = R + sin θ R[a]× + (1 − cos θ) R[a]×², each
product with a constant matrix one (3N × 3) matrix product; prismatic: a translation along it), θ_j its value — for a model
read from OpenSim the Pinocchio configuration φ(Q) of its coupling map (``robot.coupling``),
one unaligned joint per moving transform axis.  A body (any frame of the chain) is its joint's
pose times its placement.  Where :meth:`anthroarm.robot.Robot.fk` evaluates one frame's serial
chain from the base (and so recomputes the shared trunk of a tree for every body), this walks
the tree once.  Checked against Pinocchio's ``framesForwardKinematics`` (tests) and OpenSim
(``benchmarks/bench_osim_ik.py``).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..joint_kinds import PRISMATIC


def _skew(a: np.ndarray) -> np.ndarray:
    x, y, z = (float(v) for v in a)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _times(R: np.ndarray, M: np.ndarray) -> np.ndarray:
    """R @ M for a batch R (N, 3, 3) and a constant M (3, 3) or (3,): one matrix product
    (N·3, 3) @ M."""
    N = R.shape[0]
    out = R.reshape(3 * N, 3) @ M
    return out.reshape(N, 3, 3) if M.ndim == 2 else out.reshape(N, 3)


def body_poses(robot, Q, frames=None) -> dict:
    """World poses of frames of ``robot`` for a batch of configurations.

    Parameters
    ----------
    robot : anthroarm.Robot
        Any robot; for one read from OpenSim, ``Q`` is in its coordinates and goes through
        ``robot.coupling``.
    Q : (N, nq) or (nq,)
    frames : iterable of str, optional
        Frame names (default: the body frames of the chain, ``Frame.is_body``).

    Returns
    -------
    dict
        Frame name -> (N, 4, 4) homogeneous poses in the world (m), or (4, 4) for one q.

    Raises
    ------
    ParameterError
        ``Q`` of the wrong shape or not finite (``robot.check_q``), a robot with continuous or
        mimic joints (their q layout is not one value per joint: use ``robot.fk``).
    UnknownFrameError
        A frame that is not in the chain.
    """
    q = robot.check_q(Q)
    one = q.ndim == 1
    q = q[None] if one else q
    coupling = getattr(robot, "coupling", None)
    qf = q if coupling is None else coupling.full(q)
    chain = robot.chain
    if chain.has_continuous or chain.has_mimic:
        raise ParameterError(
            f"{robot.name}: body_poses takes chains of revolute and prismatic joints; use "
            "robot.fk(Q, frame) for continuous or mimic joints"
        )
    N = qf.shape[0]
    Rs, ps = [], []
    for j in chain.joints:
        th = qf[:, j.idx_q]
        if j.parent < 0:
            R0 = np.repeat(j.rotation[None], N, axis=0)
            p0 = np.repeat(j.translation[None], N, axis=0)
        else:
            Rp, pp = Rs[j.parent], ps[j.parent]
            R0 = _times(Rp, j.rotation)
            p0 = pp + _times(Rp, j.translation)
        if j.kind == PRISMATIC:
            R, p = R0, p0 + _times(R0, j.axis) * th[:, None]
        else:
            # R0 exp([a]× θ) = R0 + sin θ · R0 K + (1 − cos θ) · R0 K²  (Rodrigues, K = [a]×)
            K = _skew(j.axis)
            R = R0 + np.sin(th)[:, None, None] * _times(R0, K)
            R += (1.0 - np.cos(th))[:, None, None] * _times(R0, K @ K)
            p = p0
        Rs.append(R)
        ps.append(p)
    names = [f.name for f in chain.frames if f.is_body] if frames is None else list(frames)
    out = {}
    for name in names:
        f = chain.frame(name)
        T = np.zeros((N, 4, 4))
        T[:, 3, 3] = 1.0
        if f.joint < 0:
            T[:, :3, :3] = f.rotation
            T[:, :3, 3] = f.translation
        else:
            T[:, :3, :3] = _times(Rs[f.joint], f.rotation)
            T[:, :3, 3] = ps[f.joint] + _times(Rs[f.joint], f.translation)
        out[name] = T[0] if one else T
    return out
