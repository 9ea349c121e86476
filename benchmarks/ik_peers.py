"""IK peers for the benchmarks, each wrapped as ``solve(T) -> q`` on the same anthroarm Robot.

Every adapter is built from the robot's own URDF — the Pinocchio model anthroarm builds from
``robot.info.text``, or that text itself — and checked against Pinocchio FK at construction
(``assert_same_fk``).  Peers:

* ``anthroarm``: :func:`anthroarm.ik.solve` (defaults).
* ``pink``: pink 4.4 ``solve_ik`` iterated to convergence — FrameTask (costs 1/1,
  lm_damping 1e-3), pink's default limits (configuration + velocity), daqp, dt = 0.1 s,
  at most 500 steps (peers.md §1.1).
* ``pin-clik``: Pinocchio's ``examples/inverse-kinematics.py`` recipe (DLS, damp 1e-6,
  DT 0.1, IT_MAX 1000, log6 error and Jlog6), no joint limits (peers.md §1.10).
* ``ikpy``: ikpy 4.2 ``Chain.inverse_kinematics`` (orientation_mode="all"); the chain is made
  of URDFLinks built from the Pinocchio joint placements (peers.md §1.5).
* ``rtb-ik_LM``: Robotics Toolbox ``ETS.ik_LM`` (C++, Chan damping, random restarts,
  joint limits on), ETS built from the joint placements of the URDF's Pinocchio model; its
  tolerance is on E = ½‖e‖², so tol = 5e-13 ⇔ ‖e‖ ≤ 1e-6 (peers.md §1.4).
* ``trac-ik``: the TRAC-IK C++ library through PyPI ``pytracik`` (peers.md §0b): it parses
  ``robot.info.text`` itself; Speed mode, 5 ms timeout, ε 1e-5, seeded at mid-range, joint
  limits set to the URDF's (pytracik's own parser reads them wrong where a joint has a
  ``safety_controller``).

Local methods (pink, CLIK, ikpy, RTB's first try, TRAC-IK) start from the same seed as
anthroarm's default (the comfortable posture of the human arm, the middle of the joint ranges
otherwise, angle 0 for a continuous joint).  The peers work in joint angles; a continuous joint
is (cos, sin) in Pinocchio's q, so their answers go through :class:`Angles`.
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
    return float(np.linalg.norm(M.translation - T[:3, 3])), float(
        np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3]))
    )


class Angles:
    """Joint angles (nv,) <-> Pinocchio configuration (nq,): a continuous joint (revolute
    unbounded) is (cos θ, sin θ) in q, every other joint its angle (or length).  Works on
    batches (..., nv) / (..., nq).  ``lower``/``upper``: limits in angles, ±inf for continuous
    joints."""

    def __init__(self, robot):
        model = robot.model
        one_q, one_v, two_q, two_v = [], [], [], []
        for jm in model.joints[1:]:
            if jm.nq == jm.nv == 1:
                one_q.append(jm.idx_q), one_v.append(jm.idx_v)
            elif jm.nq == 2 and jm.nv == 1:
                two_q.append(jm.idx_q), two_v.append(jm.idx_v)
            elif jm.nq or jm.nv:
                raise NotImplementedError(f"{robot.name}: joint type {jm.shortname()} has no angle")
        self.nq, self.nv = model.nq, model.nv
        self.one_q, self.one_v, self.two_q, self.two_v = (
            np.array(a, dtype=int) for a in (one_q, one_v, two_q, two_v)
        )
        self.lower = np.full(self.nv, -np.inf)
        self.upper = np.full(self.nv, np.inf)
        self.lower[self.one_v] = robot.lower[self.one_q]
        self.upper[self.one_v] = robot.upper[self.one_q]
        self.continuous = np.zeros(self.nv, dtype=bool)
        self.continuous[self.two_v] = True

    def to_q(self, th):
        th = np.asarray(th, dtype=float)
        q = np.empty(th.shape[:-1] + (self.nq,))
        q[..., self.one_q] = th[..., self.one_v]
        q[..., self.two_q] = np.cos(th[..., self.two_v])
        q[..., self.two_q + 1] = np.sin(th[..., self.two_v])
        return q

    def from_q(self, q):
        q = np.asarray(q, dtype=float)
        th = np.empty(q.shape[:-1] + (self.nv,))
        th[..., self.one_v] = q[..., self.one_q]
        th[..., self.two_v] = np.arctan2(q[..., self.two_q + 1], q[..., self.two_q])
        return th


def seed_for(robot):
    """anthroarm's reference posture, with every continuous joint a unit (cos, sin) pair."""
    ang = Angles(robot)
    return ang.to_q(ang.from_q(comfortable_posture(robot)))


class Chain:
    """The revolute joints from the root to ``robot.tool`` in joint angles.

    ``joints``: Pinocchio joint ids; ``axes``: unit axis of each in its joint frame;
    ``vidx``: their places in the angle vector; ``lower``/``upper``: their angle limits (±inf
    for continuous); ``seed``: their angles at :func:`seed_for`."""

    def __init__(self, robot):
        model = robot.model
        self.frame = model.frames[robot.tool_id]
        self.joints = list(model.supports[self.frame.parentJoint][1:])
        self.names = [model.names[j] for j in self.joints]
        self.angles = Angles(robot)
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        self.axes = []
        for j in self.joints:
            S = np.asarray(data.joints[j].S, dtype=float).reshape(6, -1)  # motion subspace
            if S.shape[1] != 1 or np.abs(S[:3, 0]).max() > 0:
                raise NotImplementedError(
                    f"{robot.name}: joint {model.names[j]} ({model.joints[j].shortname()}) "
                    "is not revolute"
                )
            self.axes.append(S[3:, 0] / np.linalg.norm(S[3:, 0]))
        self.vidx = np.array([model.joints[j].idx_v for j in self.joints], dtype=int)
        self.lower, self.upper = self.angles.lower[self.vidx], self.angles.upper[self.vidx]
        self.continuous = self.angles.continuous[self.vidx]
        self._seed_th = self.angles.from_q(seed_for(robot))
        self.seed = self._seed_th[self.vidx]

    def limits(self, span: float):
        """(lower, upper) with each continuous joint's replaced by ±``span``."""
        return np.where(self.continuous, -span, self.lower), np.where(
            self.continuous, span, self.upper
        )

    def to_q(self, angles):
        """q with the chain at ``angles`` and every other joint at the seed."""
        th = self._seed_th.copy()
        th[self.vidx] = angles
        return self.angles.to_q(th)

    def of_q(self, q):
        return self.angles.from_q(q)[self.vidx]


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
        from ikpy.chain import Chain as IkpyChain
        from ikpy.link import OriginLink, URDFLink

        model = robot.model
        self.chain = ch = Chain(robot)
        lo, hi = ch.limits(2 * np.pi)
        links = [OriginLink()]
        for k, j in enumerate(ch.joints):
            M = model.jointPlacements[j]
            links.append(
                URDFLink(
                    name=model.names[j],
                    origin_translation=M.translation.copy(),
                    origin_orientation=pin.rpy.matrixToRpy(M.rotation),
                    rotation=ch.axes[k],
                    bounds=(float(lo[k]), float(hi[k])),
                )
            )
        links.append(
            URDFLink(
                name="tool",
                origin_translation=ch.frame.placement.translation.copy(),
                origin_orientation=pin.rpy.matrixToRpy(ch.frame.placement.rotation),
                joint_type="fixed",
            )
        )
        self.ikpy_chain = IkpyChain(
            links, active_links_mask=[False] + [True] * len(ch.joints) + [False]
        )
        self.robot = robot

    def full(self, angles):
        return np.concatenate([[0.0], angles, [0.0]])

    def fk(self, q):
        return self.ikpy_chain.forward_kinematics(self.full(self.chain.of_q(q)))

    def solve(self, T):
        out = self.ikpy_chain.inverse_kinematics(
            target_position=T[:3, 3],
            target_orientation=T[:3, :3],
            orientation_mode="all",
            initial_position=self.full(self.chain.seed),
        )
        return self.chain.to_q(out[1:-1])


# ------------------------------------------------------------------------------ RTB
def _rtb_revolute(rtb, sm, axis, k, qlim):
    """ETS of a revolute joint about ``axis`` (joint frame): Rx/Ry/Rz (flipped for a negative
    axis), else Rz conjugated by a rotation taking z onto the axis."""
    for i, ctor in enumerate((rtb.ET.Rx, rtb.ET.Ry, rtb.ET.Rz)):
        if abs(abs(axis[i]) - 1.0) < 1e-12:
            return rtb.ETS([ctor(jindex=k, qlim=qlim, flip=bool(axis[i] < 0))])
    R = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis).matrix()
    return (
        rtb.ET.SE3(sm.SE3(pin.SE3(R, np.zeros(3)).homogeneous, check=False))
        * rtb.ET.Rz(jindex=k, qlim=qlim)
        * rtb.ET.SE3(sm.SE3(pin.SE3(R.T, np.zeros(3)).homogeneous, check=False))
    )


class RtbLM:
    name = "rtb-ik_LM"

    def __init__(self, robot):
        import roboticstoolbox as rtb
        import spatialmath as sm

        model = robot.model
        self.chain = ch = Chain(robot)
        lo, hi = ch.limits(2 * np.pi)  # continuous joints: the ±2π TRAC-IK restarts from too
        ets = rtb.ETS()
        for k, j in enumerate(ch.joints):
            ets = ets * rtb.ET.SE3(sm.SE3(model.jointPlacements[j].homogeneous, check=False))
            ets = ets * _rtb_revolute(rtb, sm, ch.axes[k], k, [float(lo[k]), float(hi[k])])
        self.ets = ets * rtb.ET.SE3(sm.SE3(ch.frame.placement.homogeneous, check=False))
        self.robot = robot

    def fk(self, q):
        return np.asarray(self.ets.fkine(self.chain.of_q(q)))

    def solve(self, T):
        sol = self.ets.ik_LM(T, q0=self.chain.seed, tol=5e-13, joint_limits=True)
        return self.chain.to_q(sol.q)


# ------------------------------------------------------------------------------ TRAC-IK
_F32 = float(np.finfo(np.float32).max)  # TRAC-IK's "no limit" (a continuous joint)


def urdf_chain(robot, chain):
    """(base link, tip link, [(URDF joint, locked value or None)]) for a URDF-reading solver.

    The tip is the link owning ``robot.tool``; the base is the URDF's root.  Joints anthroarm
    locks (``robot.locked``) are kept out of the chain by moving the base below those before the
    first active joint and the tip above those after the last one; a locked joint between two
    active ones stays in the chain with its locked value (the caller pins it)."""
    model, info = robot.model, robot.info
    f = model.frames[robot.tool_id]
    while f.type != pin.FrameType.BODY:
        f = model.frames[f.parentFrame]
    link = f.name
    child_of = {j["child"]: n for n, j in info.joints.items()}
    path = []
    while link in child_of:
        path.append(child_of[link])
        link = info.joints[child_of[link]]["parent"]
    path.reverse()  # URDF joints root -> tool link
    movable = [n for n in path if info.joints[n]["type"] != "fixed"]
    active = [n for n in movable if n not in robot.locked]
    if active != chain.names:
        raise NotImplementedError(
            f"{robot.name}: URDF path {active} is not the model's chain {chain.names}"
        )
    first, last = movable.index(active[0]), movable.index(active[-1])
    base = info.joints[movable[first - 1]]["child"] if first > 0 else link
    tip = info.joints[movable[last + 1]]["parent"] if last + 1 < len(movable) else f.name
    return base, tip, [(n, robot.locked.get(n)) for n in movable[first : last + 1]]


class TracIK:
    name = "trac-ik"

    def __init__(self, robot, timeout=0.005, eps=1e-5, solve_type="Speed"):
        import pytracik

        self.robot = robot
        self.chain = ch = Chain(robot)
        self.base, self.tip, joints = urdf_chain(robot, ch)
        self.ik = pytracik.TRAC_IK(
            self.base,
            self.tip,
            robot.info.text,
            timeout,
            eps,
            getattr(pytracik.SolveType, solve_type),
        )
        if pytracik.get_num_joints(self.ik) != len(joints):
            raise AssertionError(
                f"{robot.name}: TRAC-IK chain {self.base} -> {self.tip} has "
                f"{pytracik.get_num_joints(self.ik)} joints, expected {len(joints)}"
            )
        self.active = np.array([k for k, (_, v) in enumerate(joints) if v is None], dtype=int)
        lo, hi = ch.limits(_F32)
        lower = np.array([v if v is not None else np.nan for _, v in joints])
        upper = lower.copy()
        lower[self.active], upper[self.active] = lo, hi
        pytracik.set_joint_limits(self.ik, lower.tolist(), upper.tolist())
        self.seed = lower.copy()
        self.seed[self.active] = ch.seed
        # the solver's chain sits at base; the tool is fixed to tip
        model, data = robot.model, robot.model.createData()
        pin.framesForwardKinematics(model, data, seed_for(robot))
        oMb = data.oMf[model.getFrameId(self.base, pin.FrameType.BODY)]
        oMt = data.oMf[model.getFrameId(self.tip, pin.FrameType.BODY)]
        self.bMo = oMb.inverse().homogeneous
        self.toolMt = (data.oMf[robot.tool_id].inverse() * oMt).homogeneous
        self._ik, self._fk = pytracik.ik, pytracik.fk

    def _angles(self, q):
        th = self.seed.copy()
        th[self.active] = self.chain.of_q(q)
        return th

    def fk(self, q):
        return (
            np.linalg.inv(self.bMo)
            @ self._fk(self.ik, self._angles(q))
            @ np.linalg.inv(self.toolMt)
        )

    def solve(self, T):
        M = self.bMo @ T @ self.toolMt
        x, y, z, w = pin.Quaternion(M[:3, :3]).coeffs()
        r = self._ik(self.ik, self.seed, M[0, 3], M[1, 3], M[2, 3], x, y, z, w)
        if r[0] < 0:  # no solution within the timeout
            return None
        return self.chain.to_q(r[1:][self.active])


def assert_same_fk(robot, fk, n=5, tol=1e-9):
    """The adapter's own FK equals Pinocchio's at random configurations (continuous joints:
    unit (cos, sin) pairs)."""
    ang = Angles(robot)
    for q in ang.to_q(ang.from_q(robot.random_q(n, rng=99))):
        A = np.asarray(fk(q), dtype=float)
        B = robot.fk(q)
        err = float(np.abs(A - B).max())
        if err > tol:
            raise AssertionError(f"{robot.name}: peer FK differs from Pinocchio by {err:.3g}")


PEERS = {
    "anthroarm": Ours,
    "pink": Pink,
    "pin-clik": PinCLIK,
    "ikpy": Ikpy,
    "rtb-ik_LM": RtbLM,
    "trac-ik": TracIK,
}


def make(name, robot):
    """Adapter by name, or None if the peer package is missing or cannot describe the robot
    (reason in the second item)."""
    if name not in PEERS:
        raise ValueError(name)
    try:
        a = PEERS[name](robot)
    except ImportError as exc:
        return None, f"{name} not installed ({exc})"
    except NotImplementedError as exc:
        return None, f"{name}: {exc}"
    if hasattr(a, "fk"):
        assert_same_fk(robot, a.fk)
    return a, ""
