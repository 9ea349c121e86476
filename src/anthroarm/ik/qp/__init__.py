"""QP differential inverse kinematics on Pinocchio (one concept per module, as pink does it).

>>> import anthroarm as aa
>>> from anthroarm.ik import qp
>>> robot = aa.load("panda")
>>> conf = qp.IKConfiguration(robot)
>>> ee = qp.FrameTask(robot, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
>>> ee.set_target(robot.fk(robot.random_q(rng=0)))
>>> posture = qp.PostureTask(robot, cost=1e-3)
>>> v = qp.step(conf, None, [ee, posture], dt=0.01)   # OSQP, default limits
>>> conf.integrate_inplace(v, 0.01)

Tasks (``qp.tasks``): FrameTask, PositionTask, OrientationTask, RelativeFrameTask, PostureTask,
DampingTask, JointCouplingTask (mimic), SwivelTask, MarkerTask (body-fixed points),
ContactNormalTask, SurfaceContactTask (fingertip contacts, :mod:`anthroarm.hand`),
MultiFrameTask and JointCouplingsTask (several frames / relations in one objective).  Limits
(``qp.limits``): ConfigurationLimit, VelocityLimit, AccelerationLimit.  Backends (``qp.backends``):
persistent OSQP, daqp, quadprog, proxqp, any qpsolvers solver.  Book mapping: Ch. 7 notes §6.2.

Joints: everything reads ``robot.chain``.  Velocities, Jacobians and limits on the step live in
the tangent space (nv); configurations are integrated on the manifold (``pin.integrate``) and
posture errors are ``pin.difference``, so a continuous joint (q = (cos θ, sin θ), one velocity)
turns the short way and has no position limit; a mimic joint has no q or v of its own
(Pinocchio moves it with its source).  An OpenSim model with nonlinear couplings
(``robot.coupling``) is configured in its independent coordinates (:class:`IKConfiguration`:
Jacobians J·dφ/dq, limits on the coordinates' ranges).

Thread safety: a Robot may be shared by any number of threads calling :func:`step`.
``step(robot, q, ...)`` keeps one IKConfiguration (its own ``pin.Data``), workspace and QP
backends per Robot *and thread* (a ``threading.local`` on the Robot: freed with it).  An
:class:`IKConfiguration`, the tasks (targets, scratch buffers) and stateful limits
(:class:`AccelerationLimit`) belong to one thread at a time: give each thread its own.  The
default limits and the backends of ``step(conf, ...)`` live on that IKConfiguration.  No module
state refers to a Robot.
"""

from . import backends, limits, tasks
from .backends import available_solvers, make_backend
from .configuration import IKConfiguration
from .limits import AccelerationLimit, ConfigurationLimit, Limit, VelocityLimit
from .step import StepResult, default_limits, step
from .tasks import (
    ContactNormalTask,
    DampingTask,
    FrameTask,
    JointCouplingsTask,
    JointCouplingTask,
    MarkerTask,
    MultiFrameTask,
    OrientationTask,
    PositionTask,
    PostureTask,
    RelativeFrameTask,
    SurfaceContactTask,
    SwivelTask,
    Task,
    comfortable_posture,
    swivel_angle,
)

__all__ = [
    "step",
    "StepResult",
    "IKConfiguration",
    "default_limits",
    "available_solvers",
    "make_backend",
    "Task",
    "FrameTask",
    "MarkerTask",
    "PositionTask",
    "OrientationTask",
    "RelativeFrameTask",
    "PostureTask",
    "DampingTask",
    "JointCouplingTask",
    "SwivelTask",
    "ContactNormalTask",
    "SurfaceContactTask",
    "MultiFrameTask",
    "JointCouplingsTask",
    "comfortable_posture",
    "swivel_angle",
    "Limit",
    "ConfigurationLimit",
    "VelocityLimit",
    "AccelerationLimit",
    "backends",
    "limits",
    "tasks",
]
