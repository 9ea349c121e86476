"""IK peers for the benchmarks, each wrapped as ``solve(T) -> q`` on the same anthroarm Robot.

Every adapter is built from the robot's Pinocchio model (the same kinematics for everyone) and
checked against Pinocchio FK at construction (``assert_same_fk``).  Peers:

* ``anthroarm``: :func:`anthroarm.ik.solve` (defaults).
* ``pink``: pink 4.4 ``solve_ik`` iterated to convergence — FrameTask (costs 1/1,
  lm_damping 1e-3), pink's default limits (configuration + velocity), daqp, dt = 0.1 s,
  at most 500 steps (peers.md §1.1).
* ``pin-clik``: Pinocchio's ``examples/inverse-kinematics.py`` recipe (DLS, damp 1e-6,
  DT 0.1, IT_MAX 1000, log6 error and Jlog6), no joint limits (peers.md §1.10).
* ``ikpy``: ikpy 4.2 ``Chain.inverse_kinematics`` (orientation_mode="all"); the chain is made
  of URDFLinks built from the Pinocchio joint placements (peers.md §1.5).
* ``rtb-ik_LM``: Robotics Toolbox ``ETS.ik_LM`` (C++, Chan damping, random restarts,
  joint limits on), ETS built from the joint placements; its tolerance is on
  E = ½‖e‖², so tol = 5e-13 ⇔ ‖e‖ ≤ 1e-6 (peers.md §1.4).

Local methods (pink, CLIK, ikpy) start from the same seed as anthroarm's default (the
comfortable posture of the human arm, the middle of the joint ranges otherwise).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import anthroarm as aa
from anthroarm.ik.qp import comfortable_posture

LOCAL = pin.ReferenceFrame.LOCAL


def pose_errors(robot, q, T):
    """(position error m, rotation error rad) of robot.tool at q against T (fresh pin Data)."""
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, np.asarray(q, dtype=float))
    M = d.oMf[robot.tool_id]
    return float(np.linalg.norm(M.translation - T[:3, 3])), float(np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3])))


def seed_for(robot):
    return comfortable_posture(robot)


def _chain_joints(robot):
    model = robot.model
    frame = model.frames[robot.tool_id]
    return [j for j in model.supports[frame.parentJoint][1:]], frame


# ------------------------------------------------------------------------------ anthroarm
class Ours:
    name = "anthroarm"

    def __init__(self, robot, **kw):
        self.robot = robot
        self.kw = kw

    def solve(self, T):
        return aa.ik.solve(self.robot, T, **self.kw).q


# ------------------------------------------------------------------------------ pink
class Pink:
    name = "pink"

    def __init__(self, robot, solver="daqp", dt=0.1, max_steps=500, tol=1e-6):
        import pink
        from pink.tasks import FrameTask

        self.pink = pink
        self.robot = robot
        self.task = FrameTask(robot.tool, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
        self.solver, self.dt, self.max_steps, self.tol = solver, dt, max_steps, tol
        self.seed = seed_for(robot)
        self.data = robot.model.createData()

    def solve(self, T):
        pink = self.pink
        conf = pink.Configuration(self.robot.model, self.data, self.seed)
        self.task.set_target(pin.SE3(T))
        for _ in range(self.max_steps):
            e = self.task.compute_error(conf)
            if np.linalg.norm(e[:3]) <= self.tol and np.linalg.norm(e[3:]) <= self.tol:
                break
            try:
                v = pink.solve_ik(conf, [self.task], self.dt, solver=self.solver)
            except Exception:  # NoSolutionFound / NotWithinConfigurationLimits: a failure
                break
            conf.integrate_inplace(v, self.dt)
        return conf.q.copy()


# ------------------------------------------------------------------------------ Pinocchio CLIK
class PinCLIK:
    name = "pin-clik"

    def __init__(self, robot, eps=1e-6, it_max=1000, dt=1e-1, damp=1e-6):
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        self.eps, self.it_max, self.dt, self.damp = eps, it_max, dt, damp
        self.seed = seed_for(robot)
        self.fid = robot.tool_id

    def solve(self, T):
        model, data, fid = self.model, self.data, self.fid
        oMdes = pin.SE3(T)
        q = self.seed.copy()
        for _ in range(self.it_max):
            pin.framesForwardKinematics(model, data, q)
            iMd = data.oMf[fid].actInv(oMdes)
            err = pin.log(iMd).vector
            if np.linalg.norm(iMd.translation) <= self.eps and np.linalg.norm(err[3:]) <= self.eps:
                break
            J = pin.computeFrameJacobian(model, data, q, fid, LOCAL)
            J = -np.dot(pin.Jlog6(iMd.inverse()), J)
            v = -J.T.dot(np.linalg.solve(J.dot(J.T) + self.damp * np.eye(6), err))
            q = pin.integrate(model, q, v * self.dt)
        return q


# ------------------------------------------------------------------------------ ikpy
class Ikpy:
    name = "ikpy"

    def __init__(self, robot):
        from ikpy.chain import Chain
        from ikpy.link import OriginLink, URDFLink

        model = robot.model
        joints, frame = _chain_joints(robot)
        links = [OriginLink()]
        for j in joints:
            M = model.jointPlacements[j]
            kind = model.joints[j].shortname()[-2:]          # RX / RY / RZ
            axis = {"X": [1, 0, 0], "Y": [0, 1, 0], "Z": [0, 0, 1]}[kind[-1]]
            i = model.joints[j].idx_q
            links.append(URDFLink(name=model.names[j], origin_translation=M.translation.copy(),
                                  origin_orientation=pin.rpy.matrixToRpy(M.rotation), rotation=axis,
                                  bounds=(float(robot.lower[i]), float(robot.upper[i]))))
        links.append(URDFLink(name="tool", origin_translation=frame.placement.translation.copy(),
                              origin_orientation=pin.rpy.matrixToRpy(frame.placement.rotation),
                              joint_type="fixed"))
        self.chain = Chain(links, active_links_mask=[False] + [True] * len(joints) + [False])
        self.robot = robot
        self.idx = [model.joints[j].idx_q for j in joints]
        self.seed = seed_for(robot)

    def full(self, q):
        return np.concatenate([[0.0], np.asarray(q)[self.idx], [0.0]])

    def fk(self, q):
        return self.chain.forward_kinematics(self.full(q))

    def solve(self, T):
        out = self.chain.inverse_kinematics(target_position=T[:3, 3], target_orientation=T[:3, :3],
                                            orientation_mode="all", initial_position=self.full(self.seed))
        q = self.seed.copy()
        q[self.idx] = out[1:-1]
        return q


# ------------------------------------------------------------------------------ RTB
class RtbLM:
    name = "rtb-ik_LM"

    def __init__(self, robot):
        import roboticstoolbox as rtb
        import spatialmath as sm

        model = robot.model
        joints, frame = _chain_joints(robot)
        ets = rtb.ETS()
        self.idx = []
        for k, j in enumerate(joints):
            ets = ets * rtb.ET.SE3(sm.SE3(model.jointPlacements[j].homogeneous, check=False))
            kind = model.joints[j].shortname()[-2:]
            ctor = {"RX": rtb.ET.Rx, "RY": rtb.ET.Ry, "RZ": rtb.ET.Rz}[kind]
            i = model.joints[j].idx_q
            ets = ets * ctor(jindex=k, qlim=[float(robot.lower[i]), float(robot.upper[i])])
            self.idx.append(i)
        ets = ets * rtb.ET.SE3(sm.SE3(frame.placement.homogeneous, check=False))
        self.ets = ets
        self.robot = robot
        self.seed = seed_for(robot)

    def fk(self, q):
        return np.asarray(self.ets.fkine(np.asarray(q)[self.idx]))

    def solve(self, T):
        sol = self.ets.ik_LM(T, q0=self.seed[self.idx], tol=5e-13, joint_limits=True)
        q = self.seed.copy()
        q[self.idx] = sol.q
        return q


def assert_same_fk(robot, fk, n=5, tol=1e-9):
    """The adapter's own FK equals Pinocchio's at random configurations."""
    for q in robot.random_q(n, rng=99):
        A = np.asarray(fk(q), dtype=float)
        B = robot.fk(q)
        err = float(np.abs(A - B).max())
        if err > tol:
            raise AssertionError(f"{robot.name}: peer FK differs from Pinocchio by {err:.3g}")


def make(name, robot):
    """Adapter by name, or None if the peer package is missing (reason in the second item)."""
    try:
        if name == "anthroarm":
            return Ours(robot), ""
        if name == "pink":
            return Pink(robot), ""
        if name == "pin-clik":
            return PinCLIK(robot), ""
        if name == "ikpy":
            a = Ikpy(robot)
            assert_same_fk(robot, a.fk)
            return a, ""
        if name == "rtb-ik_LM":
            a = RtbLM(robot)
            assert_same_fk(robot, a.fk)
            return a, ""
    except ImportError as exc:
        return None, f"{name} not installed ({exc})"
    raise ValueError(name)
