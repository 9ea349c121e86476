r"""Forward simulation of the Lagrange equations with joint damping and energy bookkeeping.

State x = (q, q̇, D, W) with

.. math:: M(q)\ddot q + C(q,\dot q)\dot q + g(q) = \tau(t,q,\dot q) - \xi\dot q,\qquad
          \dot D = \dot q^T\xi\dot q,\qquad \dot W = \tau^T\dot q

(the damping of Eq. (8-108), ξ in N m s/rad, scalar or per joint).  D is the energy dissipated
by damping and W the work of the drive torques, so the **balance** T + V + D − W stays equal to
its initial value up to the integrator's error; :class:`SimResult` reports its drift.

Integrators: fixed-step classical Runge–Kutta (``method="rk4"``) or any
:func:`scipy.integrate.solve_ivp` method (``method="RK45"``, ``"DOP853"``, ...).  The right-hand
side is the generated Lagrange code (:mod:`.lagrange`) or, with ``engine="pin"``, Pinocchio's
``aba`` — :func:`compare_with_pinocchio` runs both and reports the difference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import SingularMassMatrixError
from .lagrange import LagrangeDynamics, load


@dataclass
class SimResult:
    """Trajectory and energies (SI units: s, rad, rad/s, J)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    T: np.ndarray  #: kinetic energy
    V: np.ndarray  #: potential energy (Pinocchio's zero)
    dissipated: np.ndarray  #: ∫ q̇ᵀ ξ q̇ dt
    work: np.ndarray  #: ∫ τᵀ q̇ dt
    method: str
    engine: str
    nfev: int = 0
    status: str = "ok"

    @property
    def balance(self) -> np.ndarray:
        """T + V + dissipated − work (constant for an exact solution)."""
        return self.T + self.V + self.dissipated - self.work

    @property
    def energy_drift(self) -> float:
        """max |balance − balance[0]| (J)."""
        b = self.balance
        return float(np.max(np.abs(b - b[0])))

    def plot_energy(self, ax=None):
        """T, V, dissipated, work and the balance over time."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7, 3.5))
        V0 = self.V[0]
        ax.plot(self.t, self.T, label="T")
        ax.plot(self.t, self.V - V0, label="V − V(0)")
        ax.plot(self.t, self.dissipated, label="dissipated")
        if np.any(self.work):
            ax.plot(self.t, self.work, label="work of τ")
        ax.plot(self.t, self.balance - V0, "k--", label="T + V + D − W − V(0)")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("energy [J]")
        ax.set_title(f"{self.engine} / {self.method}: drift {self.energy_drift:.2e} J")
        ax.legend(fontsize=8)
        return ax


def _as_dyn(system):
    if isinstance(system, LagrangeDynamics):
        return system
    return load(system)


def _tau_fn(tau, n):
    if tau is None:
        z = np.zeros(n)
        return lambda t, q, qd: z
    if callable(tau):
        return tau
    arr = np.asarray(tau, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"tau must be a callable or a finite ({n},) array, got {arr.shape}")
    return lambda t, q, qd: arr


def simulate(
    system,
    q0,
    qd0,
    t_end: float,
    dt: float = 1e-3,
    tau=None,
    damping=0.0,
    method: str = "rk4",
    engine: str = "lagrange",
    rtol: float = 1e-10,
    atol: float = 1e-10,
    pin_model=None,
) -> SimResult:
    """Integrate the equations of motion from (q0, q̇0) over [0, t_end].

    ``system``: Robot, pin.Model or :class:`~.lagrange.LagrangeDynamics`.  ``tau``: None, a
    constant (n,) torque or ``tau(t, q, qd) -> (n,)`` (N m).  ``damping`` ξ: scalar or (n,),
    N m s/rad, >= 0.  ``dt``: RK4 step and output spacing (s).  ``engine``: "lagrange" (the
    generated code) or "pin" (``pin.aba``; the model is the system's pin model or
    ``pin_model``).  NaN/inf initial states raise ``ValueError``; a state or drive torque that
    becomes non-finite during the run ends it with ``status = "diverged: ..."``; a configuration
    where M(q) is singular (:class:`~anthroarm.errors.SingularMassMatrixError` from
    :meth:`~.lagrange.LagrangeDynamics.forward`) ends it with ``status = "singular: ..."`` (the
    trajectory up to the last step before it is kept).  ``engine="pin"`` integrates whatever
    ``pin.aba`` returns there (~1e30 rad/s², then ``"diverged"``).

    q0 and the returned q are in the robot's layout (nq); q̇ has nv entries.  With continuous
    joints (nq > nv: (cos θ, sin θ) pairs) the integrator runs on the joint angles θ, which
    q̇ integrates directly, and maps them back with ``chain.configuration`` (q stays on the
    circle); ``tau(t, q, qd)`` receives q in the robot's layout."""
    dyn = _as_dyn(system) if engine == "lagrange" else None
    if engine == "pin":
        model = pin_model if pin_model is not None else getattr(system, "model", system)
        data = model.createData()
        n = model.nv
    elif engine == "lagrange":
        n = dyn.n
    else:
        raise ValueError(f"engine must be 'lagrange' or 'pin', got {engine!r}")
    chain = dyn.chain if dyn is not None else getattr(system, "chain", None)
    nq = chain.nq if chain is not None else n
    if chain is None and engine == "pin" and model.nq != model.nv:
        raise ValueError(
            f"engine='pin' with nq = {model.nq} != nv = {model.nv} needs a Robot (its chain maps "
            "continuous joints' angles to (cos, sin)), not a bare pin.Model"
        )
    q0 = np.asarray(q0, dtype=float)
    qd0 = np.asarray(qd0, dtype=float)
    for name, a, size in (("q0", q0, nq), ("qd0", qd0, n)):
        if a.shape != (size,):
            raise ValueError(f"{name} must have shape ({size},), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} contains NaN/inf: {a.tolist()}")
    if nq != n:  # continuous joints: integrate the independent joints' angles
        chain.check_unit(q0, "q0")
        to_q = chain.configuration
        x_q0 = chain.angles(q0)[list(chain.independent)]
    else:
        to_q = lambda x: x  # noqa: E731
        x_q0 = q0
    if not (np.isfinite(t_end) and t_end > 0 and np.isfinite(dt) and dt > 0):
        raise ValueError(f"t_end and dt must be finite and > 0, got {t_end}, {dt}")
    xi = np.broadcast_to(np.asarray(damping, dtype=float), (n,)).copy()
    if not np.all(np.isfinite(xi)) or np.any(xi < 0):
        raise ValueError(f"damping must be finite and >= 0, got {xi.tolist()}")
    taufn = _tau_fn(tau, n)
    nfev = [0]

    if engine == "lagrange":

        def accel(q, qd, u):
            return dyn.forward(q, qd, u)

        def energies(q, qd):
            return dyn.kinetic_energy(q, qd), dyn.potential_energy(q)
    else:

        def accel(q, qd, u):
            return pin.aba(model, data, q, qd, u).copy()

        def energies(q, qd):
            return pin.computeKineticEnergy(model, data, q, qd), pin.computePotentialEnergy(
                model, data, q
            )

    def rhs(t, x):
        nfev[0] += 1
        q, qd = to_q(x[:n]), x[n : 2 * n]
        if not np.all(np.isfinite(x)):
            raise FloatingPointError(f"the state became non-finite at t = {t:.6g} s")
        u = np.asarray(taufn(t, q, qd), dtype=float)
        if u.shape != (n,) or not np.all(np.isfinite(u)):
            raise FloatingPointError(
                f"tau(t, q, qd) returned {u.tolist()} at t = {t:.6g} s (need {n} finite values)"
            )
        qdd = accel(q, qd, u - xi * qd)
        return np.concatenate([qd, qdd, [qd @ (xi * qd), u @ qd]])

    x0 = np.concatenate([x_q0, qd0, [0.0, 0.0]])
    nsteps = int(round(t_end / dt))
    t = np.linspace(0.0, nsteps * dt, nsteps + 1)
    status = "ok"
    if method == "rk4":
        X = np.empty((nsteps + 1, x0.size))
        X[0] = x = x0
        try:
            for k in range(nsteps):
                tk = t[k]
                k1 = rhs(tk, x)
                k2 = rhs(tk + dt / 2, x + dt / 2 * k1)
                k3 = rhs(tk + dt / 2, x + dt / 2 * k2)
                k4 = rhs(tk + dt, x + dt * k3)
                x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
                X[k + 1] = x
        except FloatingPointError as exc:
            X = X[: k + 1]
            t = t[: k + 1]
            status = f"diverged: {exc}"
        except SingularMassMatrixError as exc:
            X = X[: k + 1]
            t = t[: k + 1]
            status = f"singular: {exc}"
    else:
        from scipy.integrate import solve_ivp

        try:
            sol = solve_ivp(rhs, (0.0, t[-1]), x0, method=method, t_eval=t, rtol=rtol, atol=atol)
        except (
            FloatingPointError,
            SingularMassMatrixError,
        ) as exc:  # solve_ivp keeps no partial output
            X, t = x0[None], t[:1]
            status = f"{'diverged' if isinstance(exc, FloatingPointError) else 'singular'}: {exc}"
        else:
            if not sol.success:
                status = f"solve_ivp failed: {sol.message}"
            X = sol.y.T
            t = sol.t
    q, qd = to_q(X[:, :n]), X[:, n : 2 * n]
    TV = np.array([energies(a, b) for a, b in zip(q, qd)])
    return SimResult(
        t=t,
        q=q,
        qd=qd,
        T=TV[:, 0],
        V=TV[:, 1],
        dissipated=X[:, 2 * n],
        work=X[:, 2 * n + 1],
        method=method,
        engine=engine,
        nfev=nfev[0],
        status=status,
    )


def compare_with_pinocchio(
    robot, q0, qd0, t_end: float, dt: float = 1e-3, tau=None, damping=0.0, method: str = "rk4"
) -> dict:
    """Integrate with the generated Lagrange code and with ``pin.aba`` (same integrator);
    returns both results and the largest differences in q (rad) and q̇ (rad/s)."""
    a = simulate(robot, q0, qd0, t_end, dt, tau, damping, method, engine="lagrange")
    b = simulate(robot, q0, qd0, t_end, dt, tau, damping, method, engine="pin")
    return dict(
        lagrange=a,
        pin=b,
        max_dq=float(np.max(np.abs(a.q - b.q))),
        max_dqd=float(np.max(np.abs(a.qd - b.qd))),
    )
