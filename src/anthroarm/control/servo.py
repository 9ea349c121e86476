"""The book's analog position servo, §9-1 三.3, Eqs. (9-1)–(9-8), and the servo error as a
force sensor (Fig. 9-15, Fig. 9-16).

A DC servo motor (torque–speed line (9-1), ``M_m = k_m V − k ω_m``) turns the output shaft
through gears of ratio ``i`` (θ_m = i θ; (9-2), (9-3)); a potentiometer (``k_p``, V/rad) and a
tachogenerator on the motor shaft (``k_s``, V·s/rad) feed the amplifier (gain ``k_a``):

    V = k_a k_p (θ_i − θ) − k_a k_s dθ_m/dt                              (9-4, corrected)
    J_0 θ̈ + K_v θ̇ + K_s θ = K_s θ_i − M_L                                 (9-5)
    J_0 = η i² J_m + J_L,  K_v = η i² (k + k_m k_a k_s),  K_s = η i k_m k_a k_p
    e(s) = k_p (θ_i − θ) = k_p (J_0 s² + K_v s)/D(s) θ_i(s) + k_p / D(s) M_L(s)   (9-7)
    e_ss = M_L / (η i k_m k_a)                                            (9-8, corrected)

with ``D(s) = J_0 s² + K_v s + K_s`` (9-6).  The book's symbols are kept: ``k_m`` here is the
*stall-torque coefficient* in N·m/V
(the :attr:`~anthroarm.control.motor.DCMotor.stall_torque_coefficient` of
a :class:`~anthroarm.control.motor.DCMotor`, not its torque constant), ``k`` the slope of the
torque–speed line in N·m·s/rad; SI units throughout (the book prints kgf·cm).

Misprints corrected (see ``docs/errata.md``): (9-4) prints the tachometer term as
``k_s k_r dθ_m/dt`` (``k_r`` is never defined; re-deriving (9-5) needs ``k_a k_s``); (9-5) prints
``K_v = i²(k_s + k_m k_a k_r)``, where the derivation from (9-1)–(9-4) gives
``i²(k + k_m k_a k_s)``; (9-8) prints ``e = M_L / (i k_m k_s)``, where the final-value theorem on
(9-7) gives ``M_L / (i k_m k_a)``.

Gear efficiency ``η`` (default 1, the book's lossless gears) is an assumption of this module:
the joint receives ``η i`` times the torque that leaves the motor shaft, ``J_L θ̈ + M_L = η i P r``
in place of (9-3) (Verstraten et al., *Mechatronics* 30 (2015) 198–213); with η = 1 every
formula is the book's.  An amplifier limit ``V_max`` (optional) clips V; the book's model is
linear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.signal

from .. import input_checks as _check
from ..errors import ControlError
from .motor import DCMotor

__all__ = ["KGF_CM", "PositionServo", "ServoResponse"]

#: one kilogram-force centimetre in N·m (the book's torque unit, printed "kg·cm"); also
#: kgf·cm·s² in kg·m² (its inertia unit)
KGF_CM = 9.80665e-2


@dataclass(frozen=True)
class ServoResponse:
    """Samples of a servo simulation (:meth:`PositionServo.simulate`); every array has the
    shape of ``t``.

    Attributes
    ----------
    t : numpy.ndarray
        Times, s.
    theta, omega : numpy.ndarray
        Output angle θ (rad) and speed θ̇ (rad/s).
    theta_i, M_L : numpy.ndarray
        The inputs: set-point θ_i (rad) and load torque M_L (N·m), held over each interval.
    e : numpy.ndarray
        Position error voltage ``k_p (θ_i − θ)``, V (Eq. (9-7)).
    V : numpy.ndarray
        Motor voltage of Eq. (9-4) (clipped to ``±V_max`` if set), V.
    M_m : numpy.ndarray
        Motor torque of Eq. (9-1), N·m (motor side).
    saturated : numpy.ndarray
        True where the amplifier clipped V.
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    theta_i: np.ndarray
    M_L: np.ndarray
    e: np.ndarray
    V: np.ndarray
    M_m: np.ndarray
    saturated: np.ndarray


@dataclass(frozen=True)
class PositionServo:
    """The analog position servo of Eqs. (9-1)–(9-8) (book symbols, SI units).

    Parameters
    ----------
    k_m : float
        Stall-torque coefficient of the motor, N·m/V (book: 制动力矩系数) (> 0).
    k : float
        Torque-reduction coefficient, slope of the torque–speed line, N·m·s/rad (≥ 0).
    J_m : float
        Motor-side inertia, kg·m² (≥ 0).
    J_L : float
        Load inertia at the output shaft, kg·m² (≥ 0; J_0 must be > 0).
    i : float
        Gear ratio, θ_m = i θ (> 0).
    k_a : float
        Amplifier gain, V/V (> 0).
    k_p : float
        Potentiometer constant, V/rad (> 0).
    k_s : float
        Tachogenerator constant (on the motor shaft), V·s/rad (≥ 0).
    eta : float
        Gear efficiency, 0 < η ≤ 1 (an assumption; 1 is the book's model).
    V_max : float or None
        Amplifier output limit, V (> 0), or None for the book's linear servo.

    Raises
    ------
    anthroarm.errors.ControlError
        A parameter that is not finite or out of its range.
    """

    k_m: float
    k: float
    J_m: float
    J_L: float
    i: float
    k_a: float
    k_p: float
    k_s: float = 0.0
    eta: float = 1.0
    V_max: float | None = None

    def __post_init__(self):
        s = object.__setattr__
        s(self, "k_m", _check.positive(self.k_m, "k_m (stall-torque coefficient, N m/V)"))
        s(self, "k", _check.nonnegative(self.k, "k (torque-speed slope, N m s/rad)"))
        s(self, "J_m", _check.nonnegative(self.J_m, "J_m (motor inertia, kg m^2)"))
        s(self, "J_L", _check.nonnegative(self.J_L, "J_L (load inertia, kg m^2)"))
        s(self, "i", _check.positive(self.i, "i (gear ratio)"))
        s(self, "k_a", _check.positive(self.k_a, "k_a (amplifier gain)"))
        s(self, "k_p", _check.positive(self.k_p, "k_p (potentiometer constant, V/rad)"))
        s(self, "k_s", _check.nonnegative(self.k_s, "k_s (tachogenerator constant, V s/rad)"))
        eta = _check.positive(self.eta, "eta (gear efficiency)")
        if eta > 1.0:
            raise ControlError(f"eta (gear efficiency) must be in (0, 1], got {eta}")
        s(self, "eta", eta)
        if self.V_max is not None:
            s(self, "V_max", _check.positive(self.V_max, "V_max (amplifier limit, V)"))
        with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
            J0, Kv, Ks = self.J0, self.Kv, self.Ks
            derived = (J0, Kv, Ks, Ks / J0 if J0 > 0 else 1.0, Kv / J0 if J0 > 0 else 1.0)
        if not all(math.isfinite(v) for v in derived):
            raise ControlError(
                f"the servo's coefficients of Eq. (9-5) are beyond the floating-point range: "
                f"J_0 = {J0:.3g}, K_v = {Kv:.3g}, K_s = {Ks:.3g} (and K_s/J_0, K_v/J_0) from "
                f"k_m={self.k_m:g}, k={self.k:g}, J_m={self.J_m:g}, J_L={self.J_L:g}, "
                f"i={self.i:g}, k_a={self.k_a:g}, k_p={self.k_p:g}, k_s={self.k_s:g}; "
                "give parameters of a physical scale"
            )
        if J0 <= 0.0:
            raise ControlError(
                "J_0 = eta i^2 J_m + J_L must be > 0 (give a motor or a load inertia)"
            )
        if Ks <= 0.0 or Ks / J0 <= 0.0:
            raise ControlError(
                f"the servo's stiffness K_s = eta i k_m k_a k_p = {Ks:.3g} (K_s/J_0 = "
                f"{Ks / J0:.3g}) underflows the floating-point range: give parameters of a "
                "physical scale"
            )

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_motor(
        cls,
        motor: DCMotor,
        J_L: float,
        k_a: float,
        k_p: float,
        k_s: float = 0.0,
        V_max: float | None = None,
    ) -> PositionServo:
        """The servo of a :class:`~anthroarm.control.motor.DCMotor`: ``k_m = k_m^motor / R``,
        ``k = k_m^motor² / R + b_m`` (Eq. (9-1)), and the motor's ``J_m``, ``i``, ``η``.

        Parameters
        ----------
        motor : DCMotor
            The motor and gearbox.
        J_L : float
            Load inertia at the joint, kg·m².
        k_a, k_p, k_s : float
            Amplifier gain (V/V), potentiometer (V/rad) and tachogenerator (V·s/rad) constants.
        V_max : float, optional
            Amplifier limit, V (e.g. ``motor.V_nom``); None for the linear servo.

        Returns
        -------
        PositionServo
        """
        if not isinstance(motor, DCMotor):
            raise ControlError(f"motor must be a DCMotor, got {type(motor).__name__}")
        return cls(
            k_m=motor.stall_torque_coefficient,
            k=motor.torque_speed_slope,
            J_m=motor.J_m,
            J_L=J_L,
            i=motor.i,
            k_a=k_a,
            k_p=k_p,
            k_s=k_s,
            eta=motor.eta,
            V_max=V_max,
        )

    @classmethod
    def from_book_units(
        cls,
        k_m: float,
        k: float,
        J_m: float,
        J_L: float,
        i: float,
        k_a: float,
        k_p: float,
        k_s: float = 0.0,
        eta: float = 1.0,
        V_max: float | None = None,
    ) -> PositionServo:
        """The servo from parameters in the book's gravitational units (§9-1 三.3, l. 7119–7133):
        ``k_m`` in kgf·cm/V, ``k`` in kgf·cm·s/rad, ``J_m`` and ``J_L`` in kgf·cm·s²; ``i``,
        ``k_a``, ``k_p`` (V/rad), ``k_s`` (V·s/rad) as they are.  1 kgf·cm = 0.0980665 N·m and
        1 kgf·cm·s² = 0.0980665 kg·m² (standard gravity 9.80665 m/s², ISO 80000-4)."""
        c = KGF_CM
        return cls(
            k_m=_check.scalar(k_m, "k_m") * c,
            k=_check.scalar(k, "k") * c,
            J_m=_check.scalar(J_m, "J_m") * c,
            J_L=_check.scalar(J_L, "J_L") * c,
            i=i,
            k_a=k_a,
            k_p=k_p,
            k_s=k_s,
            eta=eta,
            V_max=V_max,
        )

    @classmethod
    def tuned(
        cls,
        motor: DCMotor,
        J_L: float,
        omega_n: float,
        zeta: float,
        k_p: float = 1.0,
        V_max: float | None = None,
    ) -> PositionServo:
        """A servo whose (9-5) has natural frequency ``omega_n`` (rad/s) and damping ratio
        ``zeta``: ``k_a = J_0 ω_n² / (η i k_m k_p)`` from ``K_s = J_0 ω_n²`` and
        ``k_s = (2 ζ ω_n J_0 / (η i²) − k) / (k_m k_a)`` from ``K_v = 2 ζ ω_n J_0``.

        Raises
        ------
        anthroarm.errors.ControlError
            When the motor alone damps more than asked (k_s would be negative).
        """
        omega_n = _check.positive(omega_n, "omega_n (natural frequency, rad/s)")
        zeta = _check.positive(zeta, "zeta (damping ratio)")
        base = cls.from_motor(motor, J_L, k_a=1.0, k_p=k_p)
        J0 = base.J0
        with np.errstate(over="ignore", under="ignore"):
            k_a = J0 * omega_n * omega_n / (base.eta * base.i * base.k_m * k_p)
        if not (math.isfinite(k_a) and k_a > 0.0):
            raise ControlError(
                f"omega_n = {omega_n:g} rad/s needs an amplifier gain k_a = J_0 omega_n^2 / "
                f"(eta i k_m k_p) = {k_a:.3g}, outside the floating-point range"
            )
        k_s = (2.0 * zeta * omega_n * J0 / (base.eta * base.i * base.i) - base.k) / (base.k_m * k_a)
        if k_s < 0.0:
            zmin = base.eta * base.i * base.i * base.k / (2.0 * omega_n * J0)
            raise ControlError(
                f"the motor's own damping gives zeta >= {zmin:.6g} at omega_n = {omega_n:g} rad/s; "
                f"asked for zeta = {zeta:g} (no tachogenerator gain can lower it)"
            )
        return cls.from_motor(motor, J_L, k_a=k_a, k_p=k_p, k_s=k_s, V_max=V_max)

    # ------------------------------------------------------------------ coefficients of (9-5)
    @property
    def J0(self) -> float:
        """``J_0 = η i² J_m + J_L`` (kg·m²), Eq. (9-5)."""
        return self.eta * (self.i * self.i) * self.J_m + self.J_L

    @property
    def Kv(self) -> float:
        """``K_v = η i² (k + k_m k_a k_s)`` (N·m·s/rad), Eq. (9-5) as corrected."""
        return self.eta * (self.i * self.i) * (self.k + self.k_m * self.k_a * self.k_s)

    @property
    def Ks(self) -> float:
        """``K_s = η i k_m k_a k_p`` (N·m/rad), Eq. (9-5): the servo's stiffness."""
        return self.eta * self.i * self.k_m * self.k_a * self.k_p

    @property
    def natural_frequency(self) -> float:
        """``ω_n = sqrt(K_s / J_0)``, rad/s."""
        return math.sqrt(self.Ks / self.J0)

    @property
    def damping_ratio(self) -> float:
        """``ζ = K_v / (2 sqrt(K_s J_0))``."""
        return self.Kv / (2.0 * math.sqrt(self.Ks * self.J0))

    # ------------------------------------------------------------------ the servo error as a force
    # sensor
    @_check.finite_result
    def steady_error(self, M_L):
        """Steady position-error voltage under a constant load torque, Eq. (9-8) as corrected:
        ``e_ss = M_L / (η i k_m k_a)`` (V), whatever the (constant) set-point.

        Parameters
        ----------
        M_L : array_like
            Load torque at the output shaft, N·m.

        Returns
        -------
        numpy.ndarray
            Error voltage ``k_p (θ_i − θ)`` at rest, V.
        """
        return _check.array(M_L, "M_L (load torque, N m)") / (
            self.eta * self.i * self.k_m * self.k_a
        )

    @_check.finite_result
    def estimate_load_torque(self, e):
        """The load torque the steady servo error reveals, ``M̂_L = η i k_m k_a e`` (N·m), the
        inverse of Eq. (9-8): the servo error as a force sensor (§9-1 三.3).

        Parameters
        ----------
        e : array_like
            Steady error voltage ``k_p (θ_i − θ)``, V.

        Returns
        -------
        numpy.ndarray
            Load torque, N·m.
        """
        return _check.array(e, "e (error voltage, V)") * (self.eta * self.i * self.k_m * self.k_a)

    # ------------------------------------------------------------------ linear system
    def state_space(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C, D) of Eq. (9-5) with state ``x = (θ, θ̇)``, inputs ``u = (θ_i, M_L)`` and
        outputs ``y = (θ, e)`` with ``e = k_p (θ_i − θ)`` (rad, rad/s, N·m, V)."""
        J0, Kv, Ks = self.J0, self.Kv, self.Ks
        A = np.array([[0.0, 1.0], [-Ks / J0, -Kv / J0]])
        B = np.array([[0.0, 0.0], [Ks / J0, -1.0 / J0]])
        C = np.array([[1.0, 0.0], [-self.k_p, 0.0]])
        D = np.array([[0.0, 0.0], [self.k_p, 0.0]])
        return A, B, C, D

    def transfer_functions(self) -> dict[str, scipy.signal.TransferFunction]:
        """The transfer functions of Eqs. (9-6) and (9-7), keyed ``"theta/theta_i"``,
        ``"theta/M_L"``, ``"e/theta_i"``, ``"e/M_L"`` (numerator and denominator in descending
        powers of s; ``.num``, ``.den``)."""
        den = np.array([self.J0, self.Kv, self.Ks])
        tf = scipy.signal.TransferFunction
        return {
            "theta/theta_i": tf([self.Ks], den),
            "theta/M_L": tf([-1.0], den),
            "e/theta_i": tf(self.k_p * np.array([self.J0, self.Kv, 0.0]), den),
            "e/M_L": tf([self.k_p], den),
        }

    def poles(self) -> np.ndarray:
        """Roots of ``J_0 s² + K_v s + K_s`` (1/s), Eq. (9-6)."""
        return np.roots([self.J0, self.Kv, self.Ks])

    # ------------------------------------------------------------------ the ODE
    def voltage(self, theta, omega, theta_i):
        """Motor voltage of Eq. (9-4), ``k_a k_p (θ_i − θ) − k_a k_s i θ̇`` (V), clipped to
        ``±V_max`` when set."""
        theta = _check.array(theta, "theta (rad)")
        omega = _check.array(omega, "omega (rad/s)")
        theta_i = _check.array(theta_i, "theta_i (rad)")
        theta, omega, theta_i = _check.broadcast(
            (theta, "theta"), (omega, "omega"), (theta_i, "theta_i")
        )
        V = self.k_a * self.k_p * (theta_i - theta) - self.k_a * self.k_s * self.i * omega
        return V if self.V_max is None else np.clip(V, -self.V_max, self.V_max)

    def rhs(self, x, theta_i, M_L) -> np.ndarray:
        """Time derivative of the state ``x = (θ, θ̇)`` from Eqs. (9-1)–(9-4) (with the
        amplifier limit if set): ``J_0 θ̈ = η i (k_m V − k i θ̇) − M_L``.

        Parameters
        ----------
        x : array_like, shape (2,) or (2, N)
            Angle (rad) and speed (rad/s).
        theta_i, M_L : float or array_like
            Set-point (rad) and load torque (N·m).

        Returns
        -------
        numpy.ndarray
            ``(θ̇, θ̈)``, same shape as ``x``.
        """
        x = _check.array(x, "x (state)")
        if x.ndim == 0 or x.shape[0] != 2:
            raise ControlError(f"x must be (theta, omega), shape (2,) or (2, N), got {x.shape}")
        M_L = _check.array(M_L, "M_L (N m)")
        theta, omega = x[0], x[1]
        V = self.voltage(theta, omega, theta_i)
        M_m = self.k_m * V - self.k * self.i * omega
        return np.array([omega, (self.eta * self.i * M_m - M_L) / self.J0])

    def _zoh(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        A, B, _, _ = self.state_space()
        decay = float(-np.max(self.poles().real))  # the slowest mode's decay rate, 1/s
        if decay > 0.0 and dt * decay > 800.0:
            # every mode has decayed by more than e^-800 (below the smallest float): the state
            # is the steady state of the held inputs, x = -A^-1 B u, exactly as far as floats go
            return np.zeros((2, 2)), -np.linalg.solve(A, B)
        M = np.zeros((4, 4))
        M[:2, :2], M[:2, 2:] = A * dt, B * dt
        with np.errstate(over="ignore", invalid="ignore"):
            E = scipy.linalg.expm(M)
        _check.finite(
            E,
            f"the servo's transition over dt = {dt:g} s",
            "an undamped servo (K_v = 0) cannot be stepped over so long a time; give a shorter dt",
        )
        return E[:2, :2], E[:2, 2:]

    def advance(self, x, dt: float, theta_i: float, M_L: float = 0.0) -> np.ndarray:
        """The state after ``dt`` seconds with the inputs held constant (zero-order hold).
        Exact (matrix exponential) for the linear servo; with ``V_max``, classical Runge–Kutta
        on sub-steps no longer than 1/50 of the servo's fastest time constant.

        Parameters
        ----------
        x : array_like, shape (2,)
            ``(θ, θ̇)`` now, rad and rad/s.
        dt : float
            Step, s (> 0).
        theta_i, M_L : float
            Set-point (rad) and load torque (N·m) over the step.

        Returns
        -------
        numpy.ndarray, shape (2,)
        """
        dt = _check.positive(dt, "dt (s)")
        x = _check.array(x, "x (state)")
        if x.shape != (2,):
            raise ControlError(f"x must be (theta, omega), shape (2,), got {x.shape}")
        theta_i = _check.scalar(theta_i, "theta_i (rad)")
        M_L = _check.scalar(M_L, "M_L (N m)")
        if self.V_max is not None:
            _check.steps(
                self._substeps_float(dt),
                f"advance(dt={dt:g} s) with the amplifier limit V_max (RK4 steps of 1/50 of "
                "the fastest time constant)",
                "give a shorter dt",
            )
        out = self._advance(x, dt, theta_i, M_L, None)
        return _check.finite(out, "the servo's state", "the inputs are too large")

    def _substeps_float(self, dt) -> float:
        fastest = float(np.max(np.abs(self.poles())))
        with np.errstate(over="ignore"):
            n = np.ceil(np.asarray(dt, dtype=float) * fastest * 50.0)
        return float(np.sum(np.maximum(n, 1.0)))

    def _substeps(self, dt: float) -> int:
        return int(self._substeps_float(dt))

    def _advance(self, x, dt, theta_i, M_L, zoh=None):
        """One step; ``zoh`` = (Ad, Bd) of this ``dt`` when the caller has them."""
        if self.V_max is None:
            Ad, Bd = self._zoh(dt) if zoh is None else zoh
            return Ad @ x + Bd @ np.array([theta_i, M_L])
        n = self._substeps(dt)
        h = dt / n
        for _ in range(n):
            k1 = self.rhs(x, theta_i, M_L)
            k2 = self.rhs(x + 0.5 * h * k1, theta_i, M_L)
            k3 = self.rhs(x + 0.5 * h * k2, theta_i, M_L)
            k4 = self.rhs(x + h * k3, theta_i, M_L)
            x = x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        return x

    def simulate(self, t, theta_i=0.0, M_L=0.0, x0=(0.0, 0.0)) -> ServoResponse:
        """Simulate Eqs. (9-1)–(9-5) on the time grid ``t`` with the inputs held constant over
        each interval (zero-order hold; the value at ``t[k]`` acts on ``[t[k], t[k+1])``).

        Parameters
        ----------
        t : array_like, shape (N,)
            Strictly increasing times, s.
        theta_i : float or array_like, shape (N,)
            Set-point, rad.
        M_L : float or array_like, shape (N,)
            Load torque at the output shaft, N·m.
        x0 : array_like, shape (2,)
            Initial angle (rad) and speed (rad/s).

        Returns
        -------
        ServoResponse
        """
        t = _check.time_grid(t)
        ti = _check.on_grid(theta_i, t, "theta_i (rad)")
        ml = _check.on_grid(M_L, t, "M_L (N m)")
        x = _check.array(x0, "x0")
        if x.shape != (2,):
            raise ControlError(f"x0 must be (theta, omega), shape (2,), got {x.shape}")
        dts = np.diff(t)
        if self.V_max is not None:
            _check.steps(
                self._substeps_float(dts),
                f"simulate over {t[-1] - t[0]:g} s with the amplifier limit V_max (RK4 steps "
                "of 1/50 of the fastest time constant)",
                "simulate a shorter time",
            )
        X = np.empty((t.size, 2))
        X[0] = x
        uniform = np.allclose(dts, dts[0], rtol=1e-9, atol=0.0)
        zoh = self._zoh(float(dts[0])) if self.V_max is None and uniform else None
        for k, dt in enumerate(dts):
            dt = float(dts[0]) if uniform else float(dt)
            X[k + 1] = self._advance(X[k], dt, ti[k], ml[k], zoh)
        with np.errstate(over="ignore", invalid="ignore"):
            theta, omega = X[:, 0], X[:, 1]
            V_raw = self.k_a * self.k_p * (ti - theta) - self.k_a * self.k_s * self.i * omega
            V = self.voltage(theta, omega, ti)
            M_m = self.k_m * V - self.k * self.i * omega
            e = self.k_p * (ti - theta)
        if not all(np.all(np.isfinite(a)) for a in (X, V_raw, V, M_m, e)):
            raise ControlError(
                "the servo's state, voltage or torque left the floating-point range (inputs too "
                "large)"
            )
        return ServoResponse(
            t=t,
            theta=theta,
            omega=omega,
            theta_i=ti,
            M_L=ml,
            e=e,
            V=V,
            M_m=M_m,
            saturated=np.abs(V_raw) > np.abs(V),
        )

    def step_response(
        self, duration: float, theta_step: float = 1.0, M_L_step: float = 0.0, n: int = 1001
    ) -> ServoResponse:
        """Response from rest to a step of the set-point and/or the load torque at t = 0 (the
        two cases of Fig. 9-16: (a) ``M_L = 0, θ_i = 1/s``; (b) ``θ_i = 0, M_L = 1/s``).

        Parameters
        ----------
        duration : float
            Length of the simulation, s.
        theta_step : float
            Size of the set-point step, rad.
        M_L_step : float
            Size of the load-torque step, N·m.
        n : int
            Number of samples (≥ 2).

        Returns
        -------
        ServoResponse
        """
        duration = _check.positive(duration, "duration (s)")
        n = _check.count(n, "n", 2)
        _check.samples(n, 9, f"step_response(n={n})", "give a smaller n")
        t = np.linspace(0.0, duration, n)
        return self.simulate(t, theta_step, M_L_step)
