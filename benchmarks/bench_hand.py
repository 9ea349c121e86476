"""Multi-finger IK on the 27-DOF human upper limb (and the Allegro hand): QP step and grasp solve,
anthroarm vs pink on the same tasks, limits and backend.

Part 1, QP step: ``human_upper_limb`` (7 arm + 20 finger joints) with six frame tasks (five
fingertips and the palm; position cost 1, orientation cost 0.1, lm_damping 1e-3), the four
DIP-PIP couplings of Rijpkema & Girard (DIP = 2/3 PIP, cost 1), a PostureTask (1e-3),
configuration (gain 0.5) and velocity limits, dt = 10 ms.  Ours: one MultiFrameTask (the six
frames) and one JointCouplingsTask; pink: six FrameTasks and one LinearHolonomicTask with the
four rows stacked (the same QP: tests/hand check that the stacked tasks' objective is the sum
of the single ones).  The targets
follow the frames of a configuration that moves smoothly from the start (every joint
0.15 rad · sin); one step = set six targets, solve, integrate.  A B A B blocks as in
bench_qp_step.  pink runs with ``safety_break=False``.

Part 2, grasp solve: ``hand.problems.reachable_grasps`` (cylinders, radius 15-40 mm, five
fingertips; each has a witness configuration: the arm drawn uniformly 0.2 rad inside its
limits, the hand closed on the object) solved with given contacts from the comfortable arm
posture with the hand open (:func:`anthroarm.hand.solve_grasp`, daqp).  The same loop (palm
approach, restarts, stall rule) runs on pink's ``solve_ik`` through ``step_fn=`` with pink
tasks equal to ours (FrameTask with orientation cost 0 for a fingertip position; a pink Task with
the ContactNormalTask's residual and Jacobian).  Success = every fingertip within 1 mm of its
contact, pad normal within 5°, inside the limits, checked on the returned configuration by
Pinocchio FK.  Also the Allegro hand (fixed palm) with sliding contacts.

Part 3, mink (MuJoCo): the QP step of part 1 on mink 1.x with the limb's URDF loaded by MuJoCo
(fixed links kept as bodies; FK checked against Pinocchio to 1e-9 before timing), the couplings
as a mink Task with the same rows, mink's configuration (gain 0.5) and velocity limits.  Skipped
when mink is not installed.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pinocchio as pin

import anthroarm as aa
from anthroarm import hand as H
from anthroarm.hand.problems import open_hand, reachable_grasps
from anthroarm.ik import qp
from anthroarm.ik.qp.tasks.contact_normal import ContactNormalTask, cross_matrix
from anthroarm.ik.qp.tasks.posture import comfortable_posture
from anthroarm.ik.qp.tasks.surface_contact import SurfaceContactTask

BACKENDS = ["osqp", "daqp", "quadprog", "proxqp"]
DT = 0.01
FRAMES = ["index_tip", "little_tip", "middle_tip", "ring_tip", "thumb_tip", "palm"]
COUPLED = [
    ("index_dip", "index_pip"),
    ("little_dip", "little_pip"),
    ("middle_dip", "middle_pip"),
    ("ring_dip", "ring_pip"),
]


# --------------------------------------------------------------------------- part 1: QP step
def _trajectory(robot, n):
    q0 = comfortable_posture(robot)
    rng = np.random.default_rng(3)
    phase = rng.uniform(0, 2 * np.pi, robot.nv)
    d = robot.model.createData()
    targets = []
    for k in range(n):
        q = np.clip(
            q0 + 0.15 * np.sin(2 * np.pi * k / 200.0 + phase) * np.sin(np.pi * k / n),
            robot.lower,
            robot.upper,
        )
        pin.framesForwardKinematics(robot.model, d, q)
        targets.append([d.oMf[robot.model.getFrameId(f)].homogeneous for f in FRAMES])
    return q0, targets


def _run_ours(robot, q0, targets, backend):
    conf = qp.IKConfiguration(robot, q0)
    frames = qp.MultiFrameTask(
        robot, FRAMES, position_cost=1.0, orientation_cost=0.1, lm_damping=1e-3
    )
    couplings = qp.JointCouplingsTask(
        robot, [qp.JointCouplingTask.mimic(robot, a, b, 2.0 / 3.0) for a, b in COUPLED]
    )
    tasks = [frames, couplings, qp.PostureTask(robot, cost=1e-3, target=q0)]
    t, Q = [], []
    for Ts in targets:
        t0 = time.process_time()
        frames.set_targets(Ts)
        v = qp.step(conf, None, tasks, DT, solver=backend)
        conf.integrate_inplace(v, DT)
        t.append(time.process_time() - t0)
        Q.append(conf.q.copy())
    return np.array(t), np.array(Q)


def _run_pink(pink, robot, q0, targets, backend):
    from pink.tasks import FrameTask, LinearHolonomicTask, PostureTask

    pconf = pink.Configuration(robot.model, robot.model.createData(), q0.copy())
    tasks = [FrameTask(f, position_cost=1.0, orientation_cost=0.1, lm_damping=1e-3) for f in FRAMES]
    # the four couplings as one stacked task (pink's cheapest form; = four JointCouplingTasks)
    A = np.vstack([qp.JointCouplingTask.mimic(robot, a, b, 2.0 / 3.0)._row for a, b in COUPLED])
    tasks.append(LinearHolonomicTask(A, np.zeros(len(COUPLED)), pin.neutral(robot.model), cost=1.0))
    post = PostureTask(cost=1e-3)
    post.set_target(q0)
    tasks.append(post)
    t, Q, errors = [], [], 0
    for Ts in targets:
        t0 = time.process_time()
        for task, T in zip(tasks, Ts):
            task.set_target(pin.SE3(T))
        try:
            v = pink.solve_ik(pconf, tasks, DT, solver=backend, safety_break=False)
        except Exception:  # NoSolutionFound: counted, zero velocity
            errors += 1
            v = np.zeros(robot.nv)
        pconf.integrate_inplace(v, DT)
        t.append(time.process_time() - t0)
        Q.append(pconf.q.copy())
    return np.array(t), np.array(Q), errors


def _mink_model(robot):
    """The robot's URDF as a MuJoCo model (fixed links kept as bodies, so the fingertip frames
    exist) and the map from Pinocchio's joint order to MuJoCo's qpos; FK is checked against
    Pinocchio before use."""
    import re

    import mujoco

    txt = aa.models.to_urdf(robot.spec)  # the catalog model's URDF text
    txt = re.sub(
        r"(<robot[^>]*>)",
        r'\1<mujoco><compiler fusestatic="false" discardvisual="true"/></mujoco>',
        txt,
        count=1,
    )
    model = mujoco.MjModel.from_xml_string(txt)
    names = [model.joint(i).name for i in range(model.njnt)]
    perm = np.array([model.jnt_qposadr[names.index(j.name)] for j in robot.chain.joints])
    q = robot.random_q(rng=5)
    d = mujoco.MjData(model)
    d.qpos[perm] = q
    mujoco.mj_kinematics(model, d)
    for f in FRAMES:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f)
        T = robot.fk(q, frame=f)
        assert (
            np.abs(d.xpos[b] - T[:3, 3]).max() < 1e-9
            and np.abs(d.xmat[b].reshape(3, 3) - T[:3, :3]).max() < 1e-9
        )
    return model, perm


def _run_mink(mink, robot, q0, targets, backend):
    model, perm = _mink_model(robot)

    class Linear(
        mink.Task
    ):  # the couplings: A q = 0 in MuJoCo's order (pink's LinearHolonomicTask)
        def __init__(self, A):
            super().__init__(cost=np.ones(len(A)))
            self.A = A

        def compute_error(self, configuration):
            return self.A @ configuration.q

        def compute_jacobian(self, configuration):
            return self.A

    A = np.zeros((len(COUPLED), model.nv))
    A[:, perm] = np.vstack(
        [qp.JointCouplingTask.mimic(robot, a, b, 2.0 / 3.0)._row for a, b in COUPLED]
    )
    qm = np.zeros(model.nq)
    qm[perm] = q0
    conf = mink.Configuration(model, qm)
    tasks = [
        mink.FrameTask(f, "body", position_cost=1.0, orientation_cost=0.1, lm_damping=1e-3)
        for f in FRAMES
    ]
    post = mink.PostureTask(model, cost=1e-3)
    post.set_target(qm)
    tasks += [Linear(A), post]
    vmax = {j.name: j.velocity for j in robot.chain.joints if np.isfinite(j.velocity)}
    limits = [mink.ConfigurationLimit(model, gain=0.5), mink.VelocityLimit(model, vmax)]
    t, Q = [], []
    for Ts in targets:
        t0 = time.process_time()
        for task, T in zip(tasks, Ts):
            task.set_target(mink.SE3.from_matrix(T))
        v = mink.solve_ik(conf, tasks, DT, solver=backend, damping=1e-12, limits=limits)
        conf.integrate_inplace(v, DT)
        t.append(time.process_time() - t0)
        Q.append(conf.q[perm].copy())
    return np.array(t), np.array(Q)


def _mink_rows(n_steps, backends):
    try:
        from importlib.metadata import version

        import mink
    except ImportError:  # mink and mujoco: the optional "bench" extra
        return []
    robot = aa.load("human_upper_limb")
    q0, targets = _trajectory(robot, n_steps)
    rows = []
    for backend in backends:
        to, Qo = _run_ours(robot, q0, targets, backend)
        tm, Qm = _run_mink(mink, robot, q0, targets, backend)
        to2, _ = _run_ours(robot, q0, targets, backend)
        tm2, _ = _run_mink(mink, robot, q0, targets, backend)
        t_o = np.concatenate([to[5:], to2[5:]]) * 1e6
        t_m = np.concatenate([tm[5:], tm2[5:]]) * 1e6
        rows.append(
            [
                "qp step vs mink (6 frame tasks + 4 couplings + posture)",
                "human_upper_limb (27 DOF)",
                backend,
                np.median(t_o),
                np.percentile(t_o, 90),
                np.median(t_m),
                np.percentile(t_m, 90),
                np.median(t_m) / np.median(t_o),
                "",
                "",
                len(to),
                f"peer = mink {version('mink')} on MuJoCo {version('mujoco')} (URDF -> MjModel, "
                f"FK checked against Pinocchio); max |q diff| {float(np.abs(Qo - Qm).max()):.1e} rad",
            ]
        )
    return rows


def _step_rows(pink, n_steps, backends):
    robot = aa.load("human_upper_limb")
    q0, targets = _trajectory(robot, n_steps)
    rows = []
    for backend in backends:
        to, Qo = _run_ours(robot, q0, targets, backend)
        if pink is None:
            rows.append(
                [
                    "qp step (6 frame tasks + 4 couplings + posture)",
                    "human_upper_limb (27 DOF)",
                    backend,
                    np.median(to[5:]) * 1e6,
                    np.percentile(to[5:], 90) * 1e6,
                    "",
                    "",
                    "",
                    "",
                    "",
                    len(to),
                    "",
                ]
            )
            continue
        tp, Qp, errs = _run_pink(pink, robot, q0, targets, backend)
        to2, _ = _run_ours(robot, q0, targets, backend)
        tp2, _, _ = _run_pink(pink, robot, q0, targets, backend)
        t_o = np.concatenate([to[5:], to2[5:]]) * 1e6
        t_p = np.concatenate([tp[5:], tp2[5:]]) * 1e6
        dev = float(np.abs(Qo - Qp).max())
        rows.append(
            [
                "qp step (6 frame tasks + 4 couplings + posture)",
                "human_upper_limb (27 DOF)",
                backend,
                np.median(t_o),
                np.percentile(t_o, 90),
                np.median(t_p),
                np.percentile(t_p, 90),
                np.median(t_p) / np.median(t_o),
                "",
                "",
                len(to),
                f"max |q diff| {dev:.1e} rad; pink exceptions {errs}",
            ]
        )
    return rows


# --------------------------------------------------------------------------- part 2: grasps
class _PinkStep:
    """``step_fn`` for :func:`anthroarm.hand.solve_grasp` that solves each iteration with
    pink.solve_ik on pink tasks equal to ours (built once per task object)."""

    def __init__(self, pink, robot):
        from pink.tasks import FrameTask, Task

        self.pink = pink
        self.robot = robot
        self.FrameTask = FrameTask
        self.model = robot.model
        self.lim_model = robot.model.copy()  # carries the limits of the current solve
        self.pconf = pink.Configuration(robot.model, robot.model.createData(), robot.neutral())
        self.cache = {}

        class Normal(Task):  # ContactNormalTask's residual and Jacobian, pink's Task API
            def __init__(self, frame, axis, target, cost, lm_damping):
                super().__init__(cost=cost, lm_damping=lm_damping)
                self.frame, self.axis, self.target = frame, axis, target

            def __repr__(self):
                return f"ContactNormal({self.frame})"

            def compute_error(self, configuration):
                return (
                    configuration.get_transform_frame_to_world(self.frame).rotation @ self.axis
                    - self.target
                )

            def compute_jacobian(self, configuration):
                R = configuration.get_transform_frame_to_world(self.frame).rotation
                J = configuration.get_frame_jacobian(self.frame)  # LOCAL
                return -cross_matrix(R @ self.axis) @ (R @ J[3:])

        class Surface(Task):  # SurfaceContactTask likewise
            def __init__(self, frame, axis, surface, cost, lm_damping):
                super().__init__(cost=cost, lm_damping=lm_damping)
                self.frame, self.axis, self.surface = frame, axis, surface

            def __repr__(self):
                return f"SurfaceContact({self.frame})"

            def compute_error(self, configuration):
                T = configuration.get_transform_frame_to_world(self.frame)
                p = T.translation
                return np.concatenate(
                    [[self.surface.distance(p)], T.rotation @ self.axis + self.surface.normal(p)]
                )

            def compute_jacobian(self, configuration):
                T = configuration.get_transform_frame_to_world(self.frame)
                R, p = T.rotation, T.translation
                J = configuration.get_frame_jacobian(self.frame)
                Jv, Jw = R @ J[:3], R @ J[3:]
                return np.vstack(
                    [
                        self.surface.normal(p) @ Jv,
                        -cross_matrix(R @ self.axis) @ Jw + self.surface.normal_jacobian(p) @ Jv,
                    ]
                )

        self.Normal, self.Surface = Normal, Surface

    def _task(self, t):
        pt = self.cache.get(id(t))
        if pt is not None and pt[0] is t:
            return pt[1]
        name = self.robot.chain.frame(t.frame_id).name
        if isinstance(t, ContactNormalTask):
            p = self.Normal(name, t.axis, t.target, float(t.cost[0]), t.lm_damping)
        elif isinstance(t, SurfaceContactTask):
            p = self.Surface(name, t.axis, t.surface, t.cost, t.lm_damping)
        elif isinstance(t, qp.PositionTask):
            p = self.FrameTask(
                name, position_cost=float(t.cost[0]), orientation_cost=0.0, lm_damping=t.lm_damping
            )
            p.set_target(pin.SE3(np.eye(3), np.asarray(t.target, dtype=float)))
        else:
            raise TypeError(f"no pink equivalent of {t!r}")
        self.cache[id(t)] = (t, p)
        return p

    def __call__(self, conf, tasks, limits, couplings, solver):
        from pink.limits import ConfigurationLimit, VelocityLimit

        cl, vl = limits
        held = cl.lower == cl.upper  # pink ignores a joint whose range is empty: give it 2e-9
        self.lim_model.lowerPositionLimit = np.where(held, cl.lower - 1e-9, cl.lower)
        self.lim_model.upperPositionLimit = np.where(held, cl.upper + 1e-9, cl.upper)
        plim = [
            ConfigurationLimit(self.lim_model, config_limit_gain=cl.gain),
            VelocityLimit(self.model, vl.v_max),
        ]
        self.pconf.update(conf.q)
        try:
            v = self.pink.solve_ik(
                self.pconf,
                [self._task(t) for t in tasks],
                1.0,
                solver=solver,
                damping=1e-9,
                limits=plim,
                safety_break=False,
            )
            return qp.StepResult(v, "optimal", solver, None, None)
        except Exception as e:  # NoSolutionFound
            return qp.StepResult(np.zeros(conf.nv), "failed", solver, None, None, {"error": str(e)})


def _check(robot, hand, pb, q, sliding):
    """The success criteria on q from Pinocchio FK (not from the solver's own report)."""
    if not (np.all(q >= robot.lower - 1e-9) and np.all(q <= robot.upper + 1e-9)):
        return False
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    for k, f in enumerate(hand.fingers):
        M = d.oMf[f.tip_id]
        c = pb.obj.project(M.translation) if sliding else pb.obj.project(pb.contacts[k])
        if np.linalg.norm(M.translation - c) > 1e-3:
            return False
        if -(M.rotation @ f.pad_axis) @ pb.obj.normal(c) < np.cos(np.radians(5.0)):
            return False
    return True


def _grasp_rows(pink, n, quick):
    rows = []
    cases = [
        ("human_upper_limb", dict(), False, 10),
        ("allegro_right_hand", dict(tool="link_3.0_tip"), True, 1),
    ]
    for name, kw, sliding, per_hand in cases:
        robot = aa.load(name, **kw)
        hand = H.Hand(robot)
        m = n if name == "human_upper_limb" else max(10, n // 5)
        t0 = time.perf_counter()
        problems = reachable_grasps(robot, m, rng=2026, hand=hand, per_hand=per_hand)
        t_gen = time.perf_counter() - t0
        q0 = open_hand(robot, hand, comfortable_posture(robot) if hand.arm_joints else None)
        pstep = _PinkStep(pink, robot) if pink is not None else None
        res = {"ours": ([], [], []), "pink": ([], [], [])}
        for pb in problems:
            for who in ("ours", "pink") if pstep is not None else ("ours",):
                t1 = time.process_time()
                r = H.solve_grasp(
                    robot,
                    pb.obj,
                    None if sliding else pb.contacts,
                    hand=hand,
                    q0=q0,
                    step_fn=None if who == "ours" else pstep,
                )
                res[who][0].append(time.process_time() - t1)
                res[who][1].append(_check(robot, hand, pb, r.q, sliding) and r.success)
                res[who][2].append(r.iterations)
        to, so, io = (np.array(a) for a in res["ours"])
        label = f"grasp solve ({'sliding' if sliding else 'given'} contacts, cylinder, {len(hand.fingers)} fingertips)"
        desc = f"{name} ({robot.nv} DOF{', arm + hand' if hand.arm_joints else ', palm fixed'})"
        note = (
            f"{len(problems)} reachable problems (generated in {t_gen:.0f} s"
            f"{f', {per_hand} arm poses per hand grasp' if per_hand > 1 else ''}); "
            f"median iterations ours {np.median(io):.0f}"
        )
        if pstep is None:
            rows.append(
                [
                    label,
                    desc,
                    "daqp",
                    np.median(to) * 1e3,
                    np.percentile(to, 90) * 1e3,
                    "",
                    "",
                    "",
                    100 * so.mean(),
                    "",
                    len(problems),
                    note,
                ]
            )
        else:
            tp, sp, ip = (np.array(a) for a in res["pink"])
            rows.append(
                [
                    label,
                    desc,
                    "daqp",
                    np.median(to) * 1e3,
                    np.percentile(to, 90) * 1e3,
                    np.median(tp) * 1e3,
                    np.percentile(tp, 90) * 1e3,
                    np.median(tp) / np.median(to),
                    100 * so.mean(),
                    100 * sp.mean(),
                    len(problems),
                    note + f", pink {np.median(ip):.0f}",
                ]
            )
    return rows


def run(quick: bool = False) -> dict:
    warnings.filterwarnings("ignore")
    import logging

    logging.disable(logging.WARNING)
    try:
        import pink
    except ImportError:  # peers are the optional "bench" extra
        pink = None
    rows = _step_rows(pink, 40 if quick else 400, BACKENDS[:2] if quick else BACKENDS)
    rows += _mink_rows(40 if quick else 400, ["daqp"] if quick else ["daqp", "quadprog", "osqp"])
    rows += _grasp_rows(pink, 20 if quick else 500, quick)
    logging.disable(logging.NOTSET)
    notes = (
        "QP step rows: times in us (CPU time of this process, time.process_time; 2 shared cores); ratio = peer "
        "median / ours with the same backend; runs A B A B; the peer is pink, or mink in the 'vs mink' rows (the "
        "same step on MuJoCo, model from the same URDF). Grasp rows: times in ms per solve (CPU time, all "
        "attempts and the palm approach included), success % checked on the returned q by Pinocchio FK "
        "(1 mm, 5 deg, limits); ours and pink run the same solve loop (hand.solve_grasp) and differ only in "
        "the QP step (step_fn=)."
        + ("" if pink is not None else " pink is not installed: ours only.")
    )
    return dict(
        title="Multi-finger IK: QP step on the 27-DOF limb and grasp solves, anthroarm vs pink and mink",
        columns=[
            "measure",
            "robot",
            "backend",
            "ours median",
            "ours p90",
            "peer median",
            "peer p90",
            "ratio peer/ours",
            "ours success %",
            "pink success %",
            "n",
            "note",
        ],
        rows=rows,
        notes=notes,
    )
