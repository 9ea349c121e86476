"""Bilateral master–slave servos of Fig. 9-17 (§9-1 三.1): what the operator feels.

One joint on each side.  Master (inertia ``J1``, viscous ``B1``) and slave (``J2``, ``B2``):

    J1 θ̈1 + B1 θ̇1 = τ_h + τ_1,        J2 θ̈2 + B2 θ̇2 = τ_2 − τ_e

where ``τ_h`` is the operator's torque on the master handle (**what the operator feels**, the
reaction of the handle), ``τ_1``/``τ_2`` the actuator torques and ``τ_e`` the environment's
torque on the slave: a constant load ``M_L`` and/or a wall at ``θ_w`` of stiffness ``K_e``
(N·m/rad) and damping ``B_e`` that pushes back only while ``θ2 > θ_w``.  The operator's hand is
an impedance that tracks an intended motion ``θ_h(t)``:
``τ_h = K_h (θ_h − θ1) + B_h (θ̇_h − θ̇1)`` (an assumption, the usual model of a stiff grip,
e.g. Hashtrudi-Zaad & Salcudean, *IJRR* 20(6) 2001).

The three types of Fig. 9-17 (the book describes their signal paths in words; the control laws
below are their standard forms, Hashtrudi-Zaad & Salcudean 2001, with PD position regulators):

* **symmetric** (对称型, (a)): the position error drives both sides,
  ``τ_2 = K_s e + D_s ė``, ``τ_1 = −K_m e − D_m ė`` with ``e = θ1 − θ2``; no torque sensor.
  At rest against a load the operator feels ``(K_m / K_s) τ_e``; in free motion he also feels
  the slave's inertia and friction through the error (bad for heavy arms, as the book says).
* **force-reflecting** (力回送型, (b)): the slave is an ordinary position servo and the
  measured slave drive torque is sent back, ``τ_1 = −k_f τ_2``: the operator feels
  ``k_f τ_e`` at rest, but also ``k_f`` times the slave's inertia and friction torque in
  motion ("heavy to operate even without load").
* **force-feedback** (力反馈型, (c)): torque sensors on both sides; the master's torque
  regulator acts on their difference, ``τ_1 = G (τ_h − k_f τ_e)``: the operator feels
  ``G/(1+G) k_f τ_e`` at rest and only ``1/(1+G)`` of the master's own inertia and friction in
  free motion ("no inertial reaction when unloaded").

Units: rad, rad/s, N·m, kg·m², s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .. import input_checks as _check
from ..errors import ControlError

__all__ = ["KINDS", "Bilateral", "BilateralResult", "Wall"]

KINDS = ("symmetric", "force_reflecting", "force_feedback")


@dataclass(frozen=True)
class Wall:
    """A stiff environment at ``theta`` (rad): torque ``K (θ2 − θ) + B θ̇2`` on the slave while
    ``θ2 > theta`` (never pulling), zero otherwise."""

    theta: float
    K: float
    B: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "theta", _check.scalar(self.theta, "wall theta (rad)"))
        object.__setattr__(self, "K", _check.positive(self.K, "wall K (N m/rad)"))
        object.__setattr__(self, "B", _check.nonnegative(self.B, "wall B (N m s/rad)"))

    def torque(self, theta2, omega2):
        """Environment torque on the slave, N·m (≥ 0)."""
        pen = theta2 - self.theta
        return np.where(pen > 0.0, np.maximum(self.K * pen + self.B * omega2, 0.0), 0.0)


@dataclass(frozen=True)
class BilateralResult:
    """Samples of :meth:`Bilateral.simulate`; arrays of the shape of ``t``.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    t : numpy.ndarray
        Times, s.
    theta_h : numpy.ndarray
        The operator's intended motion, rad.
    theta_m, theta_s : numpy.ndarray
        Master and slave angles, rad.
    omega_m, omega_s : numpy.ndarray
        Their speeds, rad/s.
    felt : numpy.ndarray
        ``τ_h``, the torque the operator exerts on (and feels from) the master, N·m.
    tau_env : numpy.ndarray
        ``τ_e``, the environment's torque on the slave, N·m.
    tau_master, tau_slave : numpy.ndarray
        Actuator torques ``τ_1`` and ``τ_2``, N·m.
    """

    kind: str
    t: np.ndarray
    theta_h: np.ndarray
    theta_m: np.ndarray
    theta_s: np.ndarray
    omega_m: np.ndarray
    omega_s: np.ndarray
    felt: np.ndarray
    tau_env: np.ndarray
    tau_master: np.ndarray
    tau_slave: np.ndarray


@dataclass(frozen=True)
class Bilateral:
    """A one-joint master–slave pair (module docstring for the equations).

    Parameters
    ----------
    J1, B1 : float
        Master inertia (kg·m², > 0) and viscous friction (N·m·s/rad, ≥ 0).
    J2, B2 : float
        Slave inertia and viscous friction.
    K, D : float
        Slave position regulator: stiffness (N·m/rad, > 0) and damping (N·m·s/rad, ≥ 0).
    K_master, D_master : float, optional
        Master position regulator of the symmetric type (default ``K``, ``D``).
    k_f : float
        Torque scale from slave to master (force-reflecting and force-feedback), > 0.
    G : float
        Gain of the force-feedback type's torque regulator (≥ 0).
    K_h, B_h : float
        The operator's hand impedance (N·m/rad > 0, N·m·s/rad ≥ 0).
    """

    J1: float = 0.01
    B1: float = 0.02
    J2: float = 0.05
    B2: float = 0.2
    K: float = 40.0
    D: float = 1.0
    K_master: float | None = None
    D_master: float | None = None
    k_f: float = 1.0
    G: float = 20.0
    K_h: float = 200.0
    B_h: float = 4.0

    def __post_init__(self):
        s = object.__setattr__
        for name in ("J1", "J2", "K", "k_f", "K_h"):
            s(self, name, _check.positive(getattr(self, name), name))
        for name in ("B1", "B2", "D", "G", "B_h"):
            s(self, name, _check.nonnegative(getattr(self, name), name))
        s(
            self,
            "K_master",
            self.K if self.K_master is None else _check.positive(self.K_master, "K_master"),
        )
        s(
            self,
            "D_master",
            self.D if self.D_master is None else _check.nonnegative(self.D_master, "D_master"),
        )

    def _torques(self, kind, th, wh, x, load, wall, contact=None):
        """(τ_h, τ_e, τ_1, τ_2); ``contact`` True/False forces the wall's linear law on/off."""
        t1, w1, t2, w2 = x
        tau_h = self.K_h * (th - t1) + self.B_h * (wh - w1)
        if wall is None or contact is False:
            tau_e = load + 0.0 * t2
        elif contact is None:
            tau_e = load + wall.torque(t2, w2)
        else:
            tau_e = load + wall.K * (t2 - wall.theta) + wall.B * w2
        e, de = t1 - t2, w1 - w2
        tau_2 = self.K * e + self.D * de
        if kind == "symmetric":
            tau_1 = -self.K_master * e - self.D_master * de
        elif kind == "force_reflecting":
            tau_1 = -self.k_f * tau_2
        else:
            tau_1 = self.G * (tau_h - self.k_f * tau_e)
        return tau_h, tau_e, tau_1, tau_2

    def _affine(self, kind, load, wall, contact):
        """(A, B, c) with ``ẋ = A x + B (θ_h, θ̇_h) + c`` for one contact state: the equations
        are affine in the state and the operator's input while the wall is on or off."""

        def f(x, u):
            tau_h, tau_e, tau_1, tau_2 = self._torques(kind, u[0], u[1], x, load, wall, contact)
            return np.array(
                [
                    x[1],
                    (tau_h + tau_1 - self.B1 * x[1]) / self.J1,
                    x[3],
                    (tau_2 - tau_e - self.B2 * x[3]) / self.J2,
                ]
            )

        z4, z2 = np.zeros(4), np.zeros(2)
        c = f(z4, z2)
        A = np.column_stack([f(e, z2) - c for e in np.eye(4)])
        B = np.column_stack([f(z4, e) - c for e in np.eye(2)])
        return A, B, c

    def simulate(
        self,
        kind: str,
        t,
        theta_h,
        load: float = 0.0,
        wall: Wall | None = None,
        max_step: float = 1e-3,
    ) -> BilateralResult:
        """Simulate one type of Fig. 9-17 from rest at the operator's first position.

        The equations are linear while the wall is in contact or not, so each step is exact
        (matrix exponential) for the operator's input interpolated linearly over the step
        (first-order hold); the contact state is decided at the start of each step (steps of at
        most ``max_step``).

        Parameters
        ----------
        kind : str
            ``"symmetric"``, ``"force_reflecting"`` or ``"force_feedback"``.
        t : array_like, shape (N,)
            Strictly increasing output times, s.
        theta_h : callable or array_like, shape (N,)
            The operator's intended motion: ``theta_h(t) -> (θ, θ̇)`` (rad, rad/s), or samples
            on ``t`` (linear interpolation, speed by finite differences).
        load : float
            Constant load torque on the slave, N·m.
        wall : Wall, optional
            A stiff environment.
        max_step : float
            Longest integration step, s.

        Returns
        -------
        BilateralResult
        """
        if kind not in KINDS:
            raise ControlError(f"kind must be one of {KINDS}, got {kind!r}")
        t = _check.time_grid(t)
        load = _check.scalar(load, "load (N m)")
        max_step = _check.positive(max_step, "max_step (s)")
        if wall is not None and not isinstance(wall, Wall):
            raise ControlError(f"wall must be a Wall, got {type(wall).__name__}")
        if callable(theta_h):

            def path(tt):
                try:
                    out = theta_h(tt)
                    th, wh = out
                    th = np.asarray(th, dtype=float)
                    wh = np.asarray(wh, dtype=float)
                except (TypeError, ValueError, OverflowError):
                    raise ControlError(
                        "theta_h(t) must return (theta, theta_dot), two numbers or arrays of the "
                        f"shape of t (rad, rad/s); got {_check.short(locals().get('out'))}"
                    ) from None
                try:
                    return tuple(np.broadcast_arrays(th, wh, np.asarray(tt, dtype=float))[:2])
                except ValueError:
                    raise ControlError(
                        f"theta_h(t) returned shapes {th.shape} and {wh.shape} for t of shape "
                        f"{np.shape(tt)}"
                    ) from None
        else:
            samples = _check.on_grid(theta_h, t, "theta_h (rad)")
            rate = np.gradient(samples, t)

            def path(tt):
                return np.interp(tt, t, samples), np.interp(tt, t, rate)

        with np.errstate(over="ignore"):
            n_sub = float(np.sum(np.maximum(1.0, np.ceil(np.diff(t) / max_step))))
        _check.steps(
            n_sub,
            f"simulate over {t[-1] - t[0]:g} s with max_step = {max_step:g} s",
            "give a larger max_step or a shorter time",
        )
        th_t, wh_t = (np.broadcast_to(np.asarray(v, dtype=float), t.shape) for v in path(t))
        if not (np.all(np.isfinite(th_t)) and np.all(np.isfinite(wh_t))):
            raise ControlError("theta_h must be finite")
        modes = {
            c: self._affine(kind, load, wall, c)
            for c in ((False, True) if wall is not None else (False,))
        }
        cache: dict = {}

        def discrete(c, h):
            """First-order hold: ẋ = A x + B u + k with u linear over the step (z = (x, u, u̇))."""
            key = (c, h)
            if key not in cache:
                A, B, k = modes[c]
                M = np.zeros((9, 9))
                M[:4, :4], M[:4, 4:6], M[:4, 6] = A * h, B * h, k * h
                M[4:6, 7:9] = np.eye(2) * h
                E = scipy.linalg.expm(M)
                cache[key] = (E[:4, :4], E[:4, 4:6], E[:4, 6], E[:4, 7:9])
            return cache[key]

        X = np.empty((t.size, 4))
        x = np.array([th_t[0], 0.0, th_t[0], 0.0])
        X[0] = x
        for k in range(t.size - 1):
            n = max(1, int(np.ceil((t[k + 1] - t[k]) / max_step - 1e-9)))
            h = (t[k + 1] - t[k]) / n
            hk = float(np.round(h, 15))
            u0 = np.array([th_t[k], wh_t[k]])
            for j in range(n):
                u1 = (
                    np.asarray(path(t[k] + (j + 1) * h), dtype=float)
                    if j < n - 1
                    else np.array([th_t[k + 1], wh_t[k + 1]])
                )
                contact = wall is not None and bool(wall.torque(x[2], x[3]) > 0.0)
                Ad, Bd, cd, Dd = discrete(contact, hk)
                x = Ad @ x + Bd @ u0 + cd + Dd @ ((u1 - u0) / h)
                u0 = u1
            if not np.all(np.isfinite(x)):
                raise ControlError(f"the {kind} simulation diverged at t = {t[k + 1]:g} s")
            X[k + 1] = x
        X = X.T
        tau_h, tau_e, tau_1, tau_2 = self._torques(kind, th_t, wh_t, X, load, wall)
        bc = np.broadcast_to
        return BilateralResult(
            kind=kind,
            t=t,
            theta_h=th_t.copy(),
            theta_m=X[0],
            theta_s=X[2],
            omega_m=X[1],
            omega_s=X[3],
            felt=np.asarray(tau_h, dtype=float),
            tau_env=bc(np.asarray(tau_e, float), t.shape).copy(),
            tau_master=bc(np.asarray(tau_1, float), t.shape).copy(),
            tau_slave=np.asarray(tau_2, dtype=float),
        )

    @_check.finite_result
    def static_feel(self, kind: str, tau_env) -> np.ndarray:
        """What the operator feels at rest against an environment torque ``tau_env`` (N·m), from
        the equilibrium of the module docstring's equations: ``(K_m/K_s) τ_e`` (symmetric),
        ``k_f τ_e`` (force-reflecting), ``G/(1+G) k_f τ_e`` (force-feedback)."""
        if kind not in KINDS:
            raise ControlError(f"kind must be one of {KINDS}, got {kind!r}")
        te = _check.array(tau_env, "tau_env (N m)")
        if kind == "symmetric":
            return self.K_master / self.K * te
        if kind == "force_reflecting":
            return self.k_f * te
        return self.G / (1.0 + self.G) * self.k_f * te
