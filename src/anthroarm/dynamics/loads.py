r"""External loads as generalised forces (Eq. (8-5)) and inverse dynamics along a trajectory.

**Generalised forces.**  A force :math:`F_i` acting at a point :math:`r_i(q)` does the virtual work
:math:`F_i\cdot\delta r_i = \sum_j F_i\cdot\frac{\partial r_i}{\partial q_j}\delta q_j`, so its
generalised force is Eq. (8-5) of the book,

.. math::  Q_j = \sum_i\Big(F_{ix}\frac{\partial x_i}{\partial q_j}
                 +F_{iy}\frac{\partial y_i}{\partial q_j}
                 +F_{iz}\frac{\partial z_i}{\partial q_j}\Big) = \big(J_v^T F\big)_j .

A moment :math:`m` on the same body adds :math:`J_\omega^T m`, so a wrench
:math:`w = (f, m)` (Pinocchio order: linear, angular) at a frame gives :math:`Q = J^T w` with
the frame's 6 × nv Jacobian in the same axes as the wrench: LOCAL_WORLD_ALIGNED (force and moment
at the frame origin in world axes, the Jacobian of the origin's velocity and of the angular
velocity in world axes) or LOCAL (everything in the frame's own axes).  Units: N, N m; Q in N m
for a revolute joint, N for a prismatic one.

**Sign convention.**  The Lagrange equations (8-8) with the loads' generalised forces on the
right-hand side, :math:`\frac{d}{dt}\frac{\partial T}{\partial\dot q}-\frac{\partial T}{\partial q}
+\frac{\partial V}{\partial q} = \tau + Q_{ext}`, give the joint torques the motors must supply:

.. math::  \tau = M(q)\ddot q + C(q,\dot q)\dot q + g(q) - \sum_k J_k(q)^T w_k .

``w`` is the wrench **applied to the arm** (a cup pulls the hand down: its wrench is the
negative of what it takes to carry it).  This equals Pinocchio's ``pin.rnea(model, data, q, v,
a, fext)`` where ``fext[i]`` is the same wrench moved to joint ``i``'s frame and expressed in its
axes (tested, ``tests/dynamics/test_loads.py``).

**A held object** (mass m, centre of mass c and rotational inertia :math:`I_c` about it, in the
holding frame's axes) moves rigidly with its frame F.  With the frame's spatial velocity
:math:`(v, \omega)` and spatial acceleration :math:`(\dot v, \dot\omega)` in LOCAL axes (as
``pin.getFrameVelocity``/``getFrameAcceleration`` give them) and gravity :math:`g_F = R^T g`, the
Newton–Euler equations of the object give the wrench it needs at the frame origin,

.. math::  a_c = \dot v + \omega\times v + \dot\omega\times c + \omega\times(\omega\times c),\quad
           f = m\,(a_c - g_F),\quad
           n = I_c\dot\omega + \omega\times I_c\omega + c\times f,

and it applies :math:`w = -(f, n)` (LOCAL) to the arm.  Carrying the object is therefore the same
as adding its inertia to the body of the holding frame (the second oracle of the tests).

Inverse dynamics without the loads comes from the generated Lagrange code
(:mod:`anthroarm.dynamics.lagrange`, ``engine="lagrange"``, the default) or Pinocchio's ``rnea``
(``engine="pinocchio"``); the loads' term :math:`J^T w` is added to either.  Inputs are in the
robot's layout (q ``(N, nq)``, q̇ and q̈ ``(N, nv)``); SI units throughout.  Bad input: a
held object's mass or inertia raises :class:`~anthroarm.errors.InertiaError`; a wrench, rate or
option that is not finite, not numbers, of the wrong shape or unknown raises
:class:`~anthroarm.errors.ParameterError` (a ``ValueError``); q is checked by the robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import InertiaError, ParameterError
from .lagrange import load as load_dynamics

_REFERENCES = {"LOCAL": pin.LOCAL, "LOCAL_WORLD_ALIGNED": pin.LOCAL_WORLD_ALIGNED}
#: a held object above this mass (kg) or force/moment above this magnitude is refused
LOAD_BOUND = 1e6


def _vector3(x, what: str, n: int | None = None) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{what} must be numbers, got {x!r}") from None
    if a.shape not in ((3,),) and not (a.ndim == 2 and a.shape[1] == 3):
        raise ParameterError(f"{what} must have shape (3,) or (N, 3), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"{what} must be finite, got {a[~np.isfinite(a)][0]}")
    if a.size and np.max(np.abs(a)) > LOAD_BOUND:
        raise ParameterError(
            f"{what} has an entry beyond +-{LOAD_BOUND:.0e} (N, N m or m): {np.max(np.abs(a)):.3g}"
        )
    if n is not None and a.ndim == 2 and a.shape[0] != n:
        raise ParameterError(f"{what} has {a.shape[0]} rows but the trajectory has {n} samples")
    return a


@dataclass(frozen=True)
class Wrench:
    """A wrench applied **to the arm** at a frame: ``force`` (N) and ``moment`` (N m) at the
    frame's origin, constant ``(3,)`` or one row per trajectory sample ``(N, 3)``.

    ``reference`` = "LOCAL_WORLD_ALIGNED" (default: world axes) or "LOCAL" (the frame's own axes).
    ``frame`` = a frame name of the robot; ``None`` is the tool."""

    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    frame: str | None = None
    reference: str = "LOCAL_WORLD_ALIGNED"

    def __post_init__(self):
        if self.reference not in _REFERENCES:
            raise ParameterError(
                f"Wrench reference must be one of {sorted(_REFERENCES)}, got {self.reference!r}"
            )
        object.__setattr__(self, "force", _vector3(self.force, "Wrench force (N)"))
        object.__setattr__(self, "moment", _vector3(self.moment, "Wrench moment (N m)"))

    def values(self, robot, q, qd=None, qdd=None):
        """(w (N, 6), J (N, 6, nv)): the wrench (linear, angular) and the frame Jacobian in
        ``self.reference`` axes at the configurations ``q`` (N, nq)."""
        q = np.atleast_2d(q)
        n = len(q)
        f = np.broadcast_to(_vector3(self.force, "Wrench force (N)", n), (n, 3))
        m = np.broadcast_to(_vector3(self.moment, "Wrench moment (N m)", n), (n, 3))
        J = _frame_jacobians(robot, q, self.frame, self.reference)
        return np.concatenate([f, m], axis=1), J


@dataclass(frozen=True)
class HeldObject:
    """A rigid object held at a frame (a cup in the hand).

    ``mass`` kg (> 0); ``com`` (3,) m, its centre of mass in the frame's axes from the frame
    origin; ``inertia`` (3, 3) kg m², its rotational inertia about the centre of mass in the
    frame's axes (default zero: a point mass); ``frame`` a frame name, ``None`` the tool.  Bad
    mass or inertia: :class:`~anthroarm.errors.InertiaError`."""

    mass: float
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    frame: str | None = None

    def __post_init__(self):
        try:
            m = float(self.mass)
        except (TypeError, ValueError):
            raise InertiaError(
                f"held object: mass must be a number (kg), got {self.mass!r}"
            ) from None
        if not (np.isfinite(m) and 0.0 < m <= LOAD_BOUND):
            raise InertiaError(
                f"held object: mass must be finite and in (0, {LOAD_BOUND:.0e}] kg, got {self.mass}"
            )
        c = np.asarray(self.com, dtype=float)
        if c.shape != (3,) or not np.all(np.isfinite(c)) or np.max(np.abs(c)) > 1e3:
            raise InertiaError(
                f"held object: com must be a finite (3,) vector in m (|c| <= 1e3), got {self.com!r}"
            )
        Ic = np.asarray(self.inertia, dtype=float)
        if Ic.shape != (3, 3) or not np.all(np.isfinite(Ic)):
            raise InertiaError(
                "held object: inertia must be a finite (3, 3) matrix in kg m^2, got "
                f"{self.inertia!r}"
            )
        if not np.allclose(Ic, Ic.T, rtol=0.0, atol=1e-12 * max(1.0, np.max(np.abs(Ic)))):
            raise InertiaError("held object: inertia must be symmetric")
        ev = np.linalg.eigvalsh(Ic)
        tol = 1e-12 * max(1.0, float(np.max(np.abs(ev))))
        if ev[0] < -tol or ev[0] + ev[1] < ev[2] - tol:
            raise InertiaError(
                f"held object: inertia is not physical (principal moments {ev} kg m^2 must be >= 0 "
                "and satisfy the triangle inequality)"
            )
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", c)
        object.__setattr__(self, "inertia", 0.5 * (Ic + Ic.T))

    @classmethod
    def cylinder(
        cls,
        mass: float,
        radius: float,
        height: float,
        com=(0.0, 0.0, 0.0),
        frame: str | None = None,
    ):
        """A solid cylinder (a full cup) whose axis is the frame's z axis: I = diag(m(3r²+h²)/12,
        m(3r²+h²)/12, m r²/2) about its centre of mass."""
        mass = cls(mass).mass  # the mass checks of a point mass
        try:
            r, h = float(radius), float(height)
        except (TypeError, ValueError):
            r = h = float("nan")
        if not (r >= 0 and h >= 0 and np.isfinite(r) and np.isfinite(h)):
            raise InertiaError(
                f"held object: radius and height must be finite and >= 0 m, got {radius!r}, "
                f"{height!r}"
            )
        radius, height = r, h
        a = mass * (3 * radius**2 + height**2) / 12.0
        return cls(mass, np.asarray(com, float), np.diag([a, a, mass * radius**2 / 2.0]), frame)

    def values(self, robot, q, qd, qdd):
        """(w (N, 6), J (N, 6, nv)): the wrench the object applies to the arm at its frame and the
        frame Jacobian, both LOCAL (the frame's axes), along the trajectory (q, q̇, q̈)."""
        q, qd, qdd = np.atleast_2d(q), np.atleast_2d(qd), np.atleast_2d(qdd)
        model, data = robot.model, robot.data
        fid = robot.frame_id(self.frame)
        n = len(q)
        V = np.empty((n, 6))
        A = np.empty((n, 6))
        R = np.empty((n, 3, 3))
        J = np.empty((n, 6, robot.nv))
        for k in range(n):
            pin.forwardKinematics(model, data, q[k], qd[k], qdd[k])
            pin.updateFramePlacement(model, data, fid)
            V[k] = pin.getFrameVelocity(model, data, fid, pin.LOCAL).vector
            A[k] = pin.getFrameAcceleration(model, data, fid, pin.LOCAL).vector
            R[k] = data.oMf[fid].rotation
            J[k] = pin.computeFrameJacobian(model, data, q[k], fid, pin.LOCAL)
        return -self.required_wrench(V, A, R, robot.chain.gravity), J

    def required_wrench(self, V, A, R, gravity) -> np.ndarray:
        """The wrench (N, 6) (force; moment about the frame origin), LOCAL, that moves the object
        with the frame's spatial velocity ``V`` (N, 6) and spatial acceleration ``A`` (N, 6)
        (LOCAL, linear first) against ``gravity`` (3,) m/s² in world axes, the frame's rotation
        being ``R`` (N, 3, 3): the Newton–Euler equations of the module docstring."""
        v, w = V[:, :3], V[:, 3:]
        a, al = A[:, :3], A[:, 3:]
        c, Ic, m = self.com, self.inertia, self.mass
        gF = np.einsum("nji,j->ni", R, np.asarray(gravity, float))  # Rᵀ g
        wc = np.cross(w, np.broadcast_to(c, w.shape))
        ac = a + np.cross(w, v) + np.cross(al, np.broadcast_to(c, al.shape)) + np.cross(w, wc)
        f = m * (ac - gF)
        n = al @ Ic.T + np.cross(w, w @ Ic.T) + np.cross(np.broadcast_to(c, f.shape), f)
        return np.concatenate([f, n], axis=1)


def _frame_jacobians(robot, q, frame, reference: str) -> np.ndarray:
    J = robot.jacobian(q, frame=frame, reference=reference)
    return J[None] if J.ndim == 2 else J


def _check_rates(robot, q, qd, qdd):
    q = robot.check_q(q, "q")
    single = q.ndim == 1
    q = np.atleast_2d(q)
    out = [q]
    for x, name in ((qd, "qd"), (qdd, "qdd")):
        try:
            a = np.atleast_2d(np.asarray(x, dtype=float))
        except (TypeError, ValueError):
            raise ParameterError(
                f"{robot.name}: {name} must be numbers (rad/s, rad/s^2), got {x!r}"
            ) from None
        if a.shape != (len(q), robot.nv):
            raise ParameterError(
                f"{robot.name}: {name} must have shape ({len(q)}, {robot.nv}) like q, got "
                f"{np.shape(x)}"
            )
        if not np.all(np.isfinite(a)):
            j = int(np.argwhere(~np.isfinite(a))[0][-1])
            raise ParameterError(
                f"{robot.name}: {name} for joint {robot.joint_names[j]!r} is not finite"
            )
        out.append(a)
    return single, out


def generalized_forces(robot, q, loads, qd=None, qdd=None) -> np.ndarray:
    """Generalised forces Q = Σ Jᵀ w of the loads, Eq. (8-5) (N m for revolute joints).

    ``loads``: a :class:`Wrench`, a :class:`HeldObject` or a sequence of them.  ``q`` (nq,) or
    (N, nq); a held object also needs ``qd`` and ``qdd`` (nv,) or (N, nv) (it is a static weight
    when they are omitted: zero velocity and acceleration).  Returns (nv,) or (N, nv)."""
    q_in = robot.check_q(q, "q")
    zeros = np.zeros(q_in.shape[:-1] + (robot.nv,))
    single, (Q2, V2, A2) = _check_rates(
        robot, q_in, zeros if qd is None else qd, zeros if qdd is None else qdd
    )
    out = _loads_q(robot, Q2, V2, A2, loads)
    return out[0] if single else out


def _as_loads(loads) -> tuple:
    if loads is None:
        return ()
    if isinstance(loads, (Wrench, HeldObject)):
        return (loads,)
    loads = tuple(loads)
    for x in loads:
        if not isinstance(x, (Wrench, HeldObject)):
            raise ParameterError(f"a load is a Wrench or a HeldObject, got {type(x).__name__}")
    return loads


def _loads_q(robot, q, qd, qdd, loads) -> np.ndarray:
    Q = np.zeros((len(q), robot.nv))
    for load in _as_loads(loads):
        w, J = load.values(robot, q, qd, qdd)
        Q += np.einsum("nki,nk->ni", J, w)  # Jᵀ w, Eq. (8-5)
    return Q


@dataclass
class InverseDynamicsResult:
    """Joint torques along a trajectory (SI units; rows are samples, columns joints in nv order).

    ``tau`` the torques the joints must supply, ``tau_free`` = M q̈ + C q̇ + g without loads,
    ``q_ext`` = Σ Jᵀ w the loads' generalised forces (8-5) (so ``tau = tau_free - q_ext``),
    ``qd`` the joint velocities (rad/s), ``power`` = τ q̇ per joint (W; > 0 when the joint
    drives, < 0 when it brakes)."""

    tau: np.ndarray
    tau_free: np.ndarray
    q_ext: np.ndarray
    qd: np.ndarray
    power: np.ndarray
    joint_names: list
    engine: str


def inverse_dynamics(
    robot, q, qd, qdd, loads=None, *, engine: str = "lagrange", dynamics=None
) -> InverseDynamicsResult:
    """τ = M(q) q̈ + C(q, q̇) q̇ + g(q) − Σ Jᵀ w along a trajectory (module docstring).

    Parameters
    ----------
    robot : Robot
    q, qd, qdd : array
        (N, nq), (N, nv), (N, nv) (or one sample each), rad, rad/s, rad/s².
    loads : Wrench, HeldObject or sequence of them, optional
        Applied to the arm (Eq. (8-5)).
    engine : {"lagrange", "pinocchio"}
        Source of the load-free torques: the generated Lagrange code or ``pin.rnea``.
    dynamics : LagrangeDynamics, optional
        Reuse an already loaded :func:`anthroarm.dynamics.lagrange.load` of ``robot``.
    """
    single, (Q, V, A) = _check_rates(robot, q, qd, qdd)
    if engine == "lagrange":
        if dynamics is None:
            dynamics = load_dynamics(robot)
        free = dynamics.tau(Q, V, A)
    elif engine == "pinocchio":
        model, data = robot.model, robot.data
        free = np.array([pin.rnea(model, data, Q[k], V[k], A[k]) for k in range(len(Q))])
    else:
        raise ParameterError(f"engine must be 'lagrange' or 'pinocchio', got {engine!r}")
    qext = _loads_q(robot, Q, V, A, loads)
    tau = free - qext
    res = InverseDynamicsResult(
        tau=tau,
        tau_free=free,
        q_ext=qext,
        qd=V,
        power=tau * V,
        joint_names=list(robot.joint_names),
        engine=engine,
    )
    if single:
        for k in ("tau", "tau_free", "q_ext", "qd", "power"):
            setattr(res, k, getattr(res, k)[0])
    return res
