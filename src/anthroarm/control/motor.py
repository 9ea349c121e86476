"""A permanent-magnet DC motor with a gearbox: the actuator of the book's servo (§9-1, Eq. (9-1)).

The motor (armature resistance ``R``, inductance ``L``, torque constant ``k_m``, rotor inertia
``J_m``, viscous friction ``b_m``) drives a joint through a gearbox of ratio ``i`` (motor angle
θ_m = i θ, the book's convention under Eq. (9-1)) and efficiency ``η``.  Units are SI: Ω, H,
N·m/A (= V·s/rad), kg·m², N·m·s/rad, V, rad/s, N·m.  *Motor side* quantities carry the suffix
``_m`` or say so; everything else is on the *joint side* (after the gearbox).

Steady state (the armature current has settled, ``L di/dt = 0``), the motor torque is linear in
voltage and speed,

    τ_m = (k_m / R) V − (k_m² / R + b_m) ω_m,

which is the book's torque–speed line **Eq. (9-1)**, ``M_m = k_m V − k ω_m``, with the book's
*stall-torque coefficient* (制动力矩系数) ``k_m^book = k_m / R`` (N·m/V;
:attr:`DCMotor.stall_torque_coefficient`) and *torque-reduction coefficient* (力矩减少系数)
``k^book = k_m² / R + b_m`` (N·m·s/rad; :attr:`DCMotor.torque_speed_slope`).  Beware the clash
of symbols: the book's ``k_m`` is a torque per **volt**, this class's ``k_m`` the usual torque
constant per **ampere**.

Gearbox losses (an assumption; the book's (9-2)/(9-3) are lossless): a constant efficiency η
on the torque that passes the gears, in the direction of the power flow, as in Verstraten et al.,
"Modeling and design of geared DC motors for energy efficiency", *Mechatronics* 30 (2015)
198–213.  Motoring (joint torque and speed of the same sign, or zero speed) the joint receives
``η i`` times the motor's shaft torque; back-driven, it needs only ``η / i`` of it on the motor.
The rotor inertia and the motor's viscous friction act on the motor side, before the gears.

The thermal limit is the usual one for a motor duty cycle: the RMS of the motor's
electromagnetic torque (∝ the RMS current, so ∝ the copper loss) over the cycle must not exceed
the motor's rated continuous torque ``tau_cont`` (e.g. maxon's "max. continuous torque"); see
e.g. Pons, *Wearable Robots* (Wiley, 2008), §7, and the maxon "Key information" of its catalogue.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError, ParameterError

__all__ = ["DCMotor", "ThermalCheck", "rms"]


@dataclass(frozen=True)
class ThermalCheck:
    """Result of :meth:`DCMotor.thermal_check` (motor side, N·m).

    Attributes
    ----------
    rms_torque : float
        RMS of the motor's electromagnetic torque over the cycle, N·m.
    peak_torque : float
        Largest magnitude of that torque, N·m.
    continuous_torque : float
        The motor's rated continuous torque ``tau_cont``, N·m.
    ratio : float
        ``rms_torque / continuous_torque``; the cycle is thermally admissible when ≤ 1.
    ok : bool
        ``ratio <= 1``.
    """

    rms_torque: float
    peak_torque: float
    continuous_torque: float
    ratio: float
    ok: bool


def rms(t, x) -> float:
    """Root mean square of a sampled signal over its time span, ``sqrt(∫ x² dt / T)``, with the
    trapezoidal rule.

    Parameters
    ----------
    t : array_like, shape (N,)
        Strictly increasing times, s (N ≥ 2).
    x : array_like, shape (N,)
        Samples.

    Returns
    -------
    float
        The RMS value, in the unit of ``x``.
    """
    t = _check.time_grid(t)
    x = _check.on_grid(x, t, "x")
    # in units of the largest |x| and |t|, so neither x² nor the time span overflows (the RMS
    # does not depend on the time unit); the scale of x is put back at the end
    xs, ts = float(np.max(np.abs(x))), float(np.max(np.abs(t)))
    if xs == 0.0:
        return 0.0
    u, tau = x / xs, t / ts
    return xs * float(np.sqrt(np.trapezoid(u * u, tau) / (tau[-1] - tau[0])))


@dataclass(frozen=True)
class DCMotor:
    """A DC motor and gearbox (see the module docstring for the model and the units).

    Parameters
    ----------
    R : float
        Armature resistance, Ω (> 0).
    k_m : float
        Torque constant, N·m/A; equal to the back-EMF constant in V·s/rad (SI) (> 0).
    J_m : float
        Rotor inertia (plus anything on the motor shaft), kg·m² (≥ 0).
    L : float
        Armature inductance, H (≥ 0; 0 neglects the electrical time constant, as the book does).
    b_m : float
        Viscous friction on the motor shaft, N·m·s/rad (≥ 0).
    i : float
        Gear ratio, motor angle over joint angle, θ_m = i θ (> 0; 1 = direct drive).
    eta : float
        Gearbox efficiency, 0 < η ≤ 1.
    V_nom : float or None
        Nominal supply voltage, V (> 0); the default of the ``V`` arguments.
    tau_cont : float or None
        Rated continuous (thermal) torque of the motor, N·m, motor side (> 0); needed by
        :meth:`thermal_check`.
    name : str
        A label for reports.

    Raises
    ------
    anthroarm.errors.ControlError
        A parameter that is not finite or out of its range.
    """

    R: float
    k_m: float
    J_m: float
    L: float = 0.0
    b_m: float = 0.0
    i: float = 1.0
    eta: float = 1.0
    V_nom: float | None = None
    tau_cont: float | None = None
    name: str = ""

    def __post_init__(self):
        s = object.__setattr__
        s(self, "R", _check.positive(self.R, "R (armature resistance, ohm)"))
        s(self, "k_m", _check.positive(self.k_m, "k_m (torque constant, N m/A)"))
        s(self, "J_m", _check.nonnegative(self.J_m, "J_m (rotor inertia, kg m^2)"))
        s(self, "L", _check.nonnegative(self.L, "L (armature inductance, H)"))
        s(self, "b_m", _check.nonnegative(self.b_m, "b_m (viscous friction, N m s/rad)"))
        s(self, "i", _check.positive(self.i, "i (gear ratio)"))
        eta = _check.positive(self.eta, "eta (gear efficiency)")
        if eta > 1.0:
            raise ControlError(f"eta (gear efficiency) must be in (0, 1], got {eta}")
        s(self, "eta", eta)
        if self.V_nom is not None:
            s(self, "V_nom", _check.positive(self.V_nom, "V_nom (supply voltage, V)"))
        if self.tau_cont is not None:
            s(self, "tau_cont", _check.positive(self.tau_cont, "tau_cont (continuous torque, N m)"))
        if not isinstance(self.name, str):
            raise ControlError(f"name must be a string, got {type(self.name).__name__}")
        with np.errstate(over="ignore", under="ignore"):
            derived = {
                "k_m / R (the book's stall-torque coefficient)": self.stall_torque_coefficient,
                "k_m^2 / R + b_m (the torque-speed slope)": self.torque_speed_slope,
                "i^2 J_m (the reflected inertia)": self.reflected_inertia,
            }
        for what, v in derived.items():
            if not math.isfinite(v) or (v <= 0.0 and "inertia" not in what):
                raise ControlError(
                    f"{what} = {v:.3g} is outside the floating-point range for R={self.R:g}, "
                    f"k_m={self.k_m:g}, b_m={self.b_m:g}, i={self.i:g}, J_m={self.J_m:g}: give "
                    "parameters of a physical scale"
                )

    def replace(self, **changes) -> DCMotor:
        """A copy with some parameters changed (validated again), e.g. ``motor.replace(i=100)``."""
        fields = {f.name for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - fields)
        if unknown:
            raise ParameterError(
                f"DCMotor has no parameter {', '.join(map(repr, unknown))}; parameters: "
                f"{sorted(fields)}"
            )
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ book symbols of (9-1)
    @property
    def stall_torque_coefficient(self) -> float:
        """The book's ``k_m`` of Eq. (9-1), stall torque per volt on the motor shaft, ``k_m / R``
        (N·m/V)."""
        return self.k_m / self.R

    @property
    def torque_speed_slope(self) -> float:
        """The book's ``k`` of Eq. (9-1), the drop of motor torque per unit motor speed,
        ``k_m² / R + b_m`` (N·m·s/rad)."""
        return self.k_m * self.k_m / self.R + self.b_m

    @property
    def reflected_inertia(self) -> float:
        """Rotor inertia seen at the joint through an ideal gearbox, ``i² J_m`` (kg·m²); the
        ``i² J_m`` of the book's ``J_0 = i² J_m + J_L`` (Eq. (9-5))."""
        return self.i * self.i * self.J_m

    @property
    def electrical_time_constant(self) -> float:
        """``L / R``, s."""
        return self.L / self.R

    @property
    def mechanical_time_constant(self) -> float:
        """``J_m / k^book = J_m R / (k_m² + b_m R)``, s: the time constant of the unloaded motor's
        speed after a voltage step (motor inertia only)."""
        return self.J_m / self.torque_speed_slope

    @property
    def continuous_torque(self) -> float:
        """The rated continuous torque at the joint, ``η i tau_cont`` (N·m, motoring)."""
        if self.tau_cont is None:
            raise ControlError(
                f"motor {self.name!r} has no tau_cont (rated continuous torque, N m)"
            )
        return self.eta * self.i * self.tau_cont

    def _voltage(self, V):
        if V is None:
            if self.V_nom is None:
                raise ControlError("give a voltage V or set V_nom on the motor")
            return np.asarray(self.V_nom)
        return _check.array(V, "V (voltage, V)")

    # ------------------------------------------------------------------ steady torque-speed line
    @_check.finite_result
    def motor_torque(self, V, omega_m):
        """Steady motor shaft torque at voltage ``V`` and motor speed ``omega_m``, Eq. (9-1):
        ``τ_m = (k_m/R) V − (k_m²/R + b_m) ω_m`` (N·m, motor side; after the viscous friction).

        Parameters
        ----------
        V : array_like
            Armature voltage, V.
        omega_m : array_like
            Motor speed, rad/s (broadcast against ``V``).

        Returns
        -------
        numpy.ndarray
            Torque, N·m.
        """
        V = _check.array(V, "V (voltage, V)")
        w = _check.array(omega_m, "omega_m (motor speed, rad/s)")
        V, w = _check.broadcast((V, "V"), (w, "omega_m"))
        return self.stall_torque_coefficient * V - self.torque_speed_slope * w

    @_check.finite_result
    def joint_torque(self, omega, V=None):
        """Steady joint torque available at joint speed ``omega``: the torque–speed line seen
        through the gearbox, ``τ = η i [(k_m/R) V − (k_m²/R + b_m) i ω]`` where the motor drives
        (τ ω ≥ 0) and ``τ = (i/η) [...]`` where it is back-driven (the joint turns against it).

        Parameters
        ----------
        omega : array_like
            Joint speed, rad/s.
        V : array_like, optional
            Voltage, V (default ``V_nom``).

        Returns
        -------
        numpy.ndarray
            Joint torque, N·m (broadcast shape of ``omega`` and ``V``).
        """
        w = _check.array(omega, "omega (joint speed, rad/s)")
        V, w = _check.broadcast((self._voltage(V), "V"), (w, "omega"))
        tm = self.motor_torque(V, self.i * w)
        motoring = tm * w >= 0.0
        return np.where(motoring, self.eta * self.i * tm, self.i / self.eta * tm)

    @_check.finite_result
    def stall_torque(self, V=None):
        """Joint torque at zero speed, ``η i k_m V / R`` (N·m)."""
        return self.eta * self.i * self.stall_torque_coefficient * self._voltage(V)

    @_check.finite_result
    def no_load_speed(self, V=None):
        """Joint speed at zero torque, ``k_m V / ((k_m² + b_m R) i)`` (rad/s)."""
        return self.stall_torque_coefficient * self._voltage(V) / (self.torque_speed_slope * self.i)

    @_check.finite_result
    def speed_at_torque(self, tau, V=None):
        """Steady joint speed at which the motor delivers the joint torque ``tau`` at voltage
        ``V`` (the inverse of :meth:`joint_torque` in the motoring quadrant, τ ≥ 0 for V > 0).

        Parameters
        ----------
        tau : array_like
            Joint torque, N·m.
        V : array_like, optional
            Voltage, V (default ``V_nom``).

        Returns
        -------
        numpy.ndarray
            Joint speed, rad/s.
        """
        tau = _check.array(tau, "tau (joint torque, N m)")
        tau, V = _check.broadcast((tau, "tau"), (self._voltage(V), "V"))
        tm = tau / (self.eta * self.i)
        return (self.stall_torque_coefficient * V - tm) / (self.torque_speed_slope * self.i)

    # ------------------------------------------------------------------ what a joint motion needs
    @_check.finite_result
    def required_motor_torque(self, tau, omega=0.0, alpha=0.0):
        """Electromagnetic motor torque (``k_m`` × current) that makes the joint deliver torque
        ``tau`` at speed ``omega`` and acceleration ``alpha``:
        ``τ_em = J_m i α + b_m i ω + τ_gear`` with ``τ_gear = τ/(η i)`` when the motor drives
        (τ ω ≥ 0) and ``η τ / i`` when it is back-driven.

        Parameters
        ----------
        tau : array_like
            Joint torque the load needs, N·m.
        omega, alpha : array_like
            Joint speed (rad/s) and acceleration (rad/s²), broadcast against ``tau``.

        Returns
        -------
        numpy.ndarray
            Motor torque, N·m (motor side).
        """
        tau = _check.array(tau, "tau (joint torque, N m)")
        w = _check.array(omega, "omega (joint speed, rad/s)")
        a = _check.array(alpha, "alpha (joint acceleration, rad/s^2)")
        tau, w, a = _check.broadcast((tau, "tau"), (w, "omega"), (a, "alpha"))
        gear = np.where(tau * w >= 0.0, tau / (self.eta * self.i), self.eta * tau / self.i)
        return self.J_m * self.i * a + self.b_m * self.i * w + gear

    @_check.finite_result
    def current(self, tau, omega=0.0, alpha=0.0):
        """Armature current, ``τ_em / k_m`` (A), for :meth:`required_motor_torque`."""
        return self.required_motor_torque(tau, omega, alpha) / self.k_m

    @_check.finite_result
    def voltage(self, tau, omega=0.0, alpha=0.0):
        """Steady armature voltage that the motion needs, ``R I + k_m i ω`` (V; the inductive
        term ``L dI/dt`` is left out)."""
        w = _check.array(omega, "omega (joint speed, rad/s)")
        return self.R * self.current(tau, w, alpha) + self.k_m * self.i * w

    def within_torque_speed(self, tau, omega, V=None):
        """True where the steady point (joint torque ``tau``, speed ``omega``) lies inside the
        motor's envelope at voltage ``V``: the voltage it needs has a magnitude ≤ ``|V|``."""
        need = self.voltage(tau, omega)
        return np.abs(need) <= np.abs(self._voltage(V)) * (1.0 + 1e-12)

    @_check.finite_result
    def copper_loss(self, tau, omega=0.0, alpha=0.0):
        """Heat in the winding, ``R I²`` (W)."""
        I = self.current(tau, omega, alpha)
        return self.R * I * I

    def thermal_check(self, t, tau, omega=0.0, alpha=0.0) -> ThermalCheck:
        """The thermal limit over a duty cycle: RMS of the electromagnetic motor torque of
        :meth:`required_motor_torque` against the rated continuous torque ``tau_cont``.

        Parameters
        ----------
        t : array_like, shape (N,)
            Strictly increasing times of the cycle, s.
        tau, omega, alpha : array_like, shape (N,) or scalars
            Joint torque (N·m), speed (rad/s) and acceleration (rad/s²) at those times.

        Returns
        -------
        ThermalCheck
            RMS and peak motor torque, the limit, their ratio, and whether it holds.

        Raises
        ------
        anthroarm.errors.ControlError
            No ``tau_cont`` on the motor, or bad samples.
        """
        if self.tau_cont is None:
            raise ControlError(
                "thermal_check needs the motor's rated continuous torque tau_cont (N m)"
            )
        t = _check.time_grid(t)
        tau = _check.on_grid(tau, t, "tau")
        omega = _check.on_grid(omega, t, "omega")
        alpha = _check.on_grid(alpha, t, "alpha")
        tm = self.required_motor_torque(tau, omega, alpha)
        r = rms(t, tm)
        ratio = r / self.tau_cont
        return ThermalCheck(
            r, float(np.max(np.abs(tm))), self.tau_cont, float(ratio), bool(ratio <= 1.0)
        )
