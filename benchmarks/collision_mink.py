"""mink's CollisionAvoidanceLimit as the third peer of benchmarks/bench_collision.py.

The scene on MuJoCo: the robot's URDF loaded by MuJoCo (``fusestatic="false"``; its
``<visual>`` and ``<collision>`` elements removed, joints that anthroarm holds locked deleted, so
MuJoCo's qpos is Pinocchio's q permuted) and, as MuJoCo geoms, exactly the bodies of the
``pin.GeometryModel`` that ours and pink use (:func:`anthroarm.collision.model`): each on the
MuJoCo body of its Pinocchio parent joint at its Pinocchio placement (the world body for joint
0); a coal ``Box`` / ``Capsule`` / ``Sphere`` / ``Cylinder`` as the MuJoCo primitive of the same
half sizes; a coal ``Convex`` (panda's meshes, which anthroarm replaces by their convex hulls)
as a MuJoCo mesh whose vertices are the hull's points (MuJoCo collides a mesh through its
convex hull, which here is the same polytope).  The obstacles are geoms of one mocap body at
their poses (a body welded to the world would make mink drop every pair of the world's child
body against them as "parent-child").  :class:`Scene` checks the tool's FK against Pinocchio and
measures mink's distances (``mujoco.mj_geomDistance``) against anthroarm's (coal).

Geom pairs: one group pair per active pair of ours and pink (the robot's self pairs that
anthroarm's filter keeps, every moving body against every obstacle); :attr:`Scene.dropped`
lists those that mink's own filter drops (on panda: panda_link6–panda_hand, the hand being
welded to link 7, the child of link 6).  The QP rows and their gain: see
benchmarks/bench_collision.py.
"""

from __future__ import annotations

import re
from importlib.metadata import version

import coal
import mink
import mujoco
import numpy as np
import pinocchio as pin

from anthroarm import collision as C

#: mink's collision-limit gain (its default) and the detection distance beyond d_min (our d_i)
GAIN = 0.85
DETECT = 0.03
_STRIP = re.compile(r"<(visual|collision)\b.*?</\1>", re.S)


def _quat(R) -> np.ndarray:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return q


def _add_geom(spec, body, name: str, shape, M: pin.SE3) -> None:
    """``shape`` (a coal geometry) as a geom of ``body`` at placement ``M`` (in the body)."""
    kw = dict(name=name, pos=np.array(M.translation), quat=_quat(M.rotation))
    kw.update(contype=1, conaffinity=1)
    if isinstance(shape, coal.Box):
        kw.update(type=mujoco.mjtGeom.mjGEOM_BOX, size=np.asarray(shape.halfSide))
    elif isinstance(shape, coal.Capsule):
        kw.update(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[shape.radius, shape.halfLength, 0])
    elif isinstance(shape, coal.Cylinder):
        kw.update(type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[shape.radius, shape.halfLength, 0])
    elif isinstance(shape, coal.Sphere):
        kw.update(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[shape.radius, 0, 0])
    elif isinstance(shape, coal.ConvexBase):
        pts = np.asarray(shape.points(), dtype=float)
        spec.add_mesh(name=f"{name}_hull", uservert=pts.ravel())
        kw.update(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"{name}_hull")
    else:
        raise TypeError(f"{name}: no MuJoCo geom for {type(shape).__name__}")
    body.add_geom(**kw)


class Scene:
    """The MuJoCo model of ``robot`` with ``env`` (see the module docstring).

    Attributes: ``model`` (MjModel), ``perm`` (qpos index of each Pinocchio joint),
    ``geom_pairs`` (mink's group pairs), ``dropped`` (active pairs mink's filter drops),
    ``fk_error`` (largest tool position/rotation difference to Pinocchio over 100 random q);
    over every pair closer than the detection distance at those q: ``distance_error`` (largest
    |mj_geomDistance − coal| of the separated pairs, m), ``depth_error`` (the same over the
    penetrating ones: MuJoCo's depth of a capsule deep in a box is not coal's EPA depth),
    ``sign_errors`` (pairs that one calls separated and the other penetrating) and
    ``distance_pairs`` / ``penetrating_pairs`` (how many pairs were compared).
    """

    def __init__(self, robot, env, d_detect: float, rng=11):
        cm = C.model(robot)
        txt = re.sub(
            r"(<robot[^>]*>)",
            r'\1<mujoco><compiler fusestatic="false" discardvisual="true"/></mujoco>',
            _STRIP.sub("", robot.info.text),
            count=1,
        )
        spec = mujoco.MjSpec.from_string(txt)
        keep = set(robot.model.names[1:])
        held = {j.name for j in spec.joints} - keep  # locked by anthroarm (panda's fingers)
        for e in list(spec.equalities):  # a URDF mimic of a held joint
            if {e.name1, e.name2} & held:
                spec.delete(e)
        for j in list(spec.joints):
            if j.name in held:
                spec.delete(j)
        body_of = {j.name: j.parent for j in spec.joints}
        for g in cm.geometry.geometryObjects:
            j = int(g.parentJoint)
            body = spec.worldbody if j == 0 else body_of[robot.model.names[j]]
            _add_geom(spec, body, g.name, g.geometry, g.placement)
        if len(env):
            holder = spec.worldbody.add_body(name="obstacles", mocap=True)
            for o in env.obstacles:
                _add_geom(spec, holder, o.name, o.geometry, o.pose)
        self.model = model = spec.compile()
        names = [model.joint(i).name for i in range(model.njnt)]
        self.perm = np.array([model.jnt_qposadr[names.index(n)] for n in robot.model.names[1:]])
        a = [cm.names[i] for i in cm.pairs[:, 0]]
        b = [cm.names[j] for j in cm.pairs[:, 1]]
        for o in env.obstacles:
            moving = [cm.names[i] for i in np.flatnonzero(cm.joint > 0)]
            a += moving
            b += [o.name] * len(moving)
        self.geom_pairs = [([x], [y]) for x, y in zip(a, b)]
        lim = mink.CollisionAvoidanceLimit(model, self.geom_pairs)
        kept = {tuple(sorted(p)) for p in lim.geom_id_pairs}
        gid = lambda n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
        self.dropped = [(x, y) for x, y in zip(a, b) if tuple(sorted((gid(x), gid(y)))) not in kept]
        self._check(robot, env, cm, d_detect, rng)

    def qpos(self, q) -> np.ndarray:
        qm = np.zeros(self.model.nq)
        qm[self.perm] = q
        return qm

    def _check(self, robot, env, cm, d_detect, rng):
        model, data = self.model, mujoco.MjData(self.model)
        tool = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, robot.tool)
        self.fk_error, self.distance_error, self.depth_error = 0.0, 0.0, 0.0
        self.distance_pairs, self.penetrating_pairs, self.sign_errors = 0, 0, 0
        fromto = np.zeros(6)
        for q in robot.random_q(100, rng=rng):
            data.qpos[:] = self.qpos(q)
            mujoco.mj_kinematics(model, data)
            T = robot.fk(q)
            self.fk_error = max(
                self.fk_error,
                float(np.abs(data.xpos[tool] - T[:3, 3]).max()),
                float(np.abs(data.xmat[tool].reshape(3, 3) - T[:3, :3]).max()),
            )
            D = C.distances(robot, q, env, cutoff=d_detect)
            for (na, nb), d in zip(D.names, D.distance):
                ga = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, na)
                gb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, nb)
                dm = mujoco.mj_geomDistance(model, data, ga, gb, d_detect + 0.01, fromto)
                self.sign_errors += (dm > 0) != (d > 0)
                if d > 0:
                    self.distance_error = max(self.distance_error, abs(dm - float(d)))
                    self.distance_pairs += 1
                else:
                    self.depth_error = max(self.depth_error, abs(dm - float(d)))
                    self.penetrating_pairs += 1


class MinkIK:
    """mink on bench_collision's targets: a FrameTask on the tool and a PostureTask (1e-3)
    toward the start with the costs ``ee_kw``, mink's ConfigurationLimit (gain 0.5, as pink's
    and ours) and VelocityLimit (Pinocchio's ``velocityLimit``), its CollisionAvoidanceLimit
    (``gain``, :data:`GAIN` by default; minimum distance d_min, detection distance d_min + :data:`DETECT`,
    no bound relaxation) on :class:`Scene`'s pairs; ``solve_ik(..., solver="daqp")`` with its
    default damping 1e-12 (pink's too)."""

    def __init__(self, robot, env, q0, d_min: float, dt: float, ee_kw: dict, gain: float = GAIN):
        self.scene = sc = Scene(robot, env, d_min + DETECT)
        model = sc.model
        self.q0, self.dt, self.no_solution = sc.qpos(q0), dt, 0
        self.ee = mink.FrameTask(robot.tool, "body", **ee_kw)
        post = mink.PostureTask(model, cost=1e-3)
        post.set_target(self.q0)
        self.tasks = [self.ee, post]
        vmax = {
            n: float(v)
            for n, v in zip(robot.model.names[1:], robot.model.velocityLimit)
            if np.isfinite(v)
        }
        self.limits = [
            mink.ConfigurationLimit(model, gain=0.5),
            mink.VelocityLimit(model, vmax),
            mink.CollisionAvoidanceLimit(
                model,
                sc.geom_pairs,
                gain=gain,
                minimum_distance_from_collisions=d_min,
                collision_detection_distance=d_min + DETECT,
            ),
        ]
        self.conf = mink.Configuration(model, self.q0)
        self.zero = np.zeros(model.nv)

    def reset(self, T) -> None:
        """Back to the start, ``T`` (4×4) the tool's target."""
        self.conf.update(self.q0)
        self.ee.set_target(mink.SE3.from_matrix(T))

    def step(self) -> np.ndarray:
        """One QP step, integrated; the new configuration in Pinocchio's order."""
        try:
            v = mink.solve_ik(self.conf, self.tasks, self.dt, solver="daqp", limits=self.limits)
        except mink.NoSolutionFound:  # zero velocity, as pink's failures: counted in success
            v = self.zero
            self.no_solution += 1
        self.conf.integrate_inplace(v, self.dt)
        return self.conf.q[self.scene.perm]

    def report(self) -> dict:
        """The scene's checks and the run's failures (for the notes)."""
        sc = self.scene
        return {
            "no_solution": self.no_solution,
            "fk_error": sc.fk_error,
            "distance_error": sc.distance_error,
            "distance_pairs": sc.distance_pairs,
            "depth_error": sc.depth_error,
            "penetrating_pairs": sc.penetrating_pairs,
            "sign_errors": sc.sign_errors,
            "dropped_pairs": sc.dropped,
            "pairs": len(sc.geom_pairs),
            "versions": f"mink {version('mink')}, MuJoCo {version('mujoco')}",
        }
