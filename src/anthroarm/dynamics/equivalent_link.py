r"""Equivalent-link method for one-DOF mechanisms, book §8-2, Eqs. (8-14)–(8-29).

A mechanism with one degree of freedom φ (the angle of the *equivalent link*, rad) moves like
a single body with a position-dependent moment of inertia J*(φ), driven by the equivalent
moment M*(φ, ω, t):

* equal power (8-19)/(8-20): M* = Σ_i (F_i · v_i + M_i · ω_i) / ω;
* equal kinetic energy (8-23), (8-28): J* = Σ_i [m_i (v_si/ω)² + (ω_i/ω)ᵀ J_i (ω_i/ω)];
  the velocity ratios depend only on the position, so the book evaluates them at ω = 1 rad/s;
* energy form (8-15): ½J*(φ)ω² − ½J*(φ₀)ω₀² = ∫_{φ₀}^{φ} M* dφ  (M* a function of φ only);
* moment form (8-16): M* = J* dω/dt + ½ ω² dJ*/dφ, an ODE for any M*(φ, ω, t).

:func:`equivalent_inertia` and :func:`equivalent_moment` implement (8-28) and (8-20) for any
list of links (spatial, with full inertia tensors, (8-24)–(8-26)).  :class:`FourBarFinger`
applies them to a planar finger four-bar (crank = proximal phalanx driven at O2, coupler,
rocker), using the four-bar position/velocity/acceleration analysis of
:mod:`anthroarm.mechanisms.fourbar` (book Ch. 5); :meth:`FourBarFinger.pin_tree` is the same
linkage as a Pinocchio tree cut at the coupler–rocker joint, the oracle of the tests
(J* = Gᵀ M(q) G, ½ dJ*/dφ = Gᵀ(rnea(q, G, G′) − g(q)), M*_gravity = −Gᵀ g(q), with
G = dq/dφ from the loop-closure velocity analysis).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import InertiaError
from ..mechanisms.fourbar import fourbar
from ..spatial.rotations import as_scalar


def equivalent_inertia(links) -> float:
    """J* of Eq. (8-28) (or m* of (8-29) with v in place of ω).

    ``links``: iterable of ``(m, v_s, omega, J)`` with the CoM velocity v_s (m/s) and angular
    velocity ω (rad/s, in the same axes as the inertia tensor J about the CoM, (8-25)) of each
    link **for a unit speed of the equivalent link** (ω = 1 rad/s or v = 1 m/s).  kg m²."""
    total = 0.0
    for m, v, w, J in links:
        v = np.atleast_1d(np.asarray(v, float))
        w = np.atleast_1d(np.asarray(w, float))
        J = np.asarray(J, float)
        total += m * float(v @ v) + float(w @ (J @ w if J.ndim == 2 else J * w))  # (8-26)
    if not np.isfinite(total):
        raise ValueError(
            f"equivalent_inertia: a mass, velocity or inertia is NaN/inf (J* = {total})"
        )
    return total


def equivalent_moment(loads) -> float:
    """M* of Eqs. (8-19)/(8-20): Σ (F_i · v_i + M_i · ω_i) for a unit speed of the equivalent
    link.  ``loads``: iterable of ``(F, v, M, omega)`` in fixed-frame components (use
    (8-22), F⁰ = C₀ᵢ F⁽ⁱ⁾, for forces given in a link frame).  N m (or N for m*)."""
    total = 0.0
    for F, v, M, w in loads:
        total += float(np.dot(F, v)) + float(np.dot(M, w))
    if not np.isfinite(total):
        raise ValueError(
            f"equivalent_moment: a force, moment or velocity is NaN/inf (M* = {total})"
        )
    return total


@dataclass
class FourBarFinger:
    """A planar finger four-bar in the vertical xy plane (y up unless ``gravity`` says
    otherwise).  Lengths in m: ground r1 (O2 → O4 along +x), crank r2 (O2–A, the driven
    equivalent link), coupler r3 (A–B), rocker r4 (O4–B).  ``com[k]`` is the CoM of link k
    (crank, coupler, rocker) as a fraction along the link; ``mass[k]`` kg; ``inertia[k]``
    kg m² about the CoM (planar).  ``branch`` as in :func:`mechanisms.fourbar.fourbar`."""

    r1: float = 0.040
    r2: float = 0.012
    r3: float = 0.042
    r4: float = 0.025
    mass: tuple = (0.008, 0.015, 0.010)
    com: tuple = (0.5, 0.5, 0.5)
    inertia: tuple = (1.0e-7, 2.2e-6, 5.2e-7)
    gravity: tuple = (0.0, -9.81)
    branch: int = 1

    def __post_init__(self):
        for name in ("r1", "r2", "r3", "r4"):
            if not as_scalar(getattr(self, name), f"FourBarFinger: {name}") > 0:
                raise ValueError(
                    f"FourBarFinger: {name} must be a positive length (m), got "
                    f"{getattr(self, name)}"
                )
        g = np.asarray(self.gravity, float)
        if g.shape != (2,) or not np.all(np.isfinite(g)):
            raise ValueError(
                f"FourBarFinger: gravity must be 2 finite numbers (m/s²), got {self.gravity}"
            )
        for name in ("mass", "com", "inertia"):
            v = np.asarray(getattr(self, name), float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ValueError(
                    f"FourBarFinger: {name} must be 3 finite numbers, got {getattr(self, name)}"
                )
        if (
            np.any(np.asarray(self.mass) < 0)
            or np.any(np.asarray(self.inertia) < 0)
            or sum(self.mass) == 0
        ):
            raise InertiaError("FourBarFinger: masses and inertias must be >= 0 and not all zero")

    # ------------------------------------------------------------------ kinematics (ω = 1)
    def _state(self, phi):
        phi = float(phi)
        if not np.isfinite(phi):
            raise ValueError(f"phi must be finite, got {phi}")
        s = fourbar(
            self.r1, self.r2, self.r3, self.r4, phi, omega2=1.0, alpha2=0.0, branch=self.branch
        )
        if s.status != "ok":
            raise ValueError(f"four-bar at phi = {phi:.4f} rad: {s.status} ({s.reason})")
        return s

    def link_motion(self, phi):
        """For ω = φ̇ = 1, φ̈ = 0: per link (crank, coupler, rocker) the CoM position, CoM
        velocity, CoM acceleration, angular velocity and angular acceleration (planar, SI)."""
        s = self._state(phi)
        e = lambda a: np.array([np.cos(a), np.sin(a)])  # noqa: E731
        perp = lambda v: np.array([-v[1], v[0]])  # noqa: E731  ω × r in the plane, ω = 1
        th = (s.theta2, s.theta3, s.theta4)
        w = (1.0, s.omega3, s.omega4)
        al = (0.0, s.alpha3, s.alpha4)
        c = [self.com[0] * self.r2 * e(th[0]), None, None]
        A = self.r2 * e(th[0])
        c[1] = A + self.com[1] * self.r3 * e(th[1])
        O4 = np.array([self.r1, 0.0])
        c[2] = O4 + self.com[2] * self.r4 * e(th[2])
        rel = [c[0], c[1] - A, c[2] - O4]
        vA = perp(A)
        aA = -A  # ω2 = 1, α2 = 0
        v = [perp(rel[0]), vA + w[1] * perp(rel[1]), w[2] * perp(rel[2])]
        a = [
            -rel[0],
            aA + al[1] * perp(rel[1]) - w[1] ** 2 * rel[1],
            al[2] * perp(rel[2]) - w[2] ** 2 * rel[2],
        ]
        return dict(state=s, com=c, v=v, a=a, omega=w, alpha=al)

    def J_star(self, phi) -> float:
        """Equivalent moment of inertia J*(φ) about the crank pivot, Eq. (8-28), kg m²."""
        lm = self.link_motion(phi)
        return equivalent_inertia(
            (self.mass[k], lm["v"][k], lm["omega"][k], self.inertia[k]) for k in range(3)
        )

    def dJ_star(self, phi) -> float:
        """dJ*/dφ = 2 Σ (m v_s · a_s + J ω α) at ω = 1, φ̈ = 0 (kg m²/rad)."""
        lm = self.link_motion(phi)
        return 2.0 * sum(
            self.mass[k] * lm["v"][k] @ lm["a"][k]
            + self.inertia[k] * lm["omega"][k] * lm["alpha"][k]
            for k in range(3)
        )

    def M_star(self, phi, drive: float = 0.0, rocker_moment: float = 0.0) -> float:
        """Equivalent moment M*(φ), Eq. (8-20): the link weights, a drive moment on the crank
        and a moment on the rocker (e.g. a grip reaction, negative = resisting), N m."""
        drive, rocker_moment = as_scalar(drive, "drive"), as_scalar(rocker_moment, "rocker_moment")
        lm = self.link_motion(phi)
        g = np.asarray(self.gravity, float)
        loads = [(self.mass[k] * g, lm["v"][k], 0.0, 0.0) for k in range(3)]
        loads += [
            (np.zeros(2), np.zeros(2), drive, 1.0),
            (np.zeros(2), np.zeros(2), rocker_moment, lm["omega"][2]),
        ]
        return equivalent_moment(loads)

    # ------------------------------------------------------------------ equations of motion
    def integrate_energy_form(
        self,
        phi0: float,
        omega0: float,
        phi1: float,
        drive: float = 0.0,
        rocker_moment: float = 0.0,
        samples: int = 201,
    ):
        """Energy form (8-15): ω(φ) = sqrt((J*(φ₀)ω₀² + 2∫M*dφ)/J*(φ)) on a grid from φ₀ to φ₁,
        and t(φ) = ∫dφ/ω (trapezoid).  Returns (φ, ω, t); ω must stay > 0 (else ValueError:
        the mechanism stops before φ₁)."""
        from scipy.integrate import cumulative_trapezoid

        phi0, omega0, phi1 = (
            as_scalar(phi0, "phi0"),
            as_scalar(omega0, "omega0"),
            as_scalar(phi1, "phi1"),
        )
        if omega0 <= 0:
            raise ValueError(
                "the energy form needs omega0 > 0 (the mechanism must move toward phi1)"
            )
        phi = np.linspace(phi0, phi1, samples)
        Ms = np.array([self.M_star(p, drive, rocker_moment) for p in phi])
        Js = np.array([self.J_star(p) for p in phi])
        work = cumulative_trapezoid(Ms, phi, initial=0.0)
        e2 = (Js[0] * omega0**2 + 2 * work) / Js
        if np.any(e2 <= 0):
            k = int(np.argmax(e2 <= 0))
            raise ValueError(
                f"the mechanism stops before phi = {phi[k]:.4f} rad (kinetic energy exhausted)"
            )
        om = np.sqrt(e2)
        t = cumulative_trapezoid(1.0 / om, phi, initial=0.0)
        return phi, om, t

    def integrate_moment_form(
        self,
        phi0: float,
        omega0: float,
        t_end: float,
        drive: float = 0.0,
        rocker_moment: float = 0.0,
        damping: float = 0.0,
        rtol: float = 1e-10,
    ):
        """Moment form (8-16) as an ODE: φ̇ = ω, ω̇ = (M* − ½ω² dJ*/dφ)/J*, with an optional
        viscous moment −damping·ω on the crank.  Returns the ``solve_ivp`` solution."""
        from scipy.integrate import solve_ivp

        phi0, omega0, t_end = (
            as_scalar(phi0, "phi0"),
            as_scalar(omega0, "omega0"),
            as_scalar(t_end, "t_end"),
        )
        damping = as_scalar(damping, "damping")
        if t_end <= 0 or damping < 0:
            raise ValueError(
                f"need t_end > 0 and damping >= 0, got t_end={t_end}, damping={damping}"
            )

        def rhs(t, x):
            phi, om = x
            Ms = self.M_star(phi, drive, rocker_moment) - damping * om
            return [om, (Ms - 0.5 * om * om * self.dJ_star(phi)) / self.J_star(phi)]

        return solve_ivp(
            rhs,
            (0.0, t_end),
            [phi0, omega0],
            method="DOP853",
            rtol=rtol,
            atol=1e-12,
            dense_output=True,
        )

    # ------------------------------------------------------------------ Pinocchio oracle
    def pin_tree(self):
        """The linkage as a Pinocchio tree (cut at the coupler–rocker joint B): crank RZ at O2,
        coupler RZ at A (child of the crank), rocker RZ at O4; q = (θ2, θ3 − θ2, θ4); planar
        inertias about z; gravity in the plane."""
        model = pin.Model()
        model.gravity.linear = np.array([self.gravity[0], self.gravity[1], 0.0])

        def body(jid, L, k):
            I = np.diag([self.inertia[k], self.inertia[k], self.inertia[k]])
            model.appendBodyToJoint(
                jid,
                pin.Inertia(float(self.mass[k]), np.array([self.com[k] * L, 0, 0]), I),
                pin.SE3.Identity(),
            )

        j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "crank")
        body(j1, self.r2, 0)
        j2 = model.addJoint(
            j1, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([self.r2, 0, 0])), "coupler"
        )
        body(j2, self.r3, 1)
        j3 = model.addJoint(
            0, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([self.r1, 0, 0])), "rocker"
        )
        body(j3, self.r4, 2)
        return model

    def tree_coordinates(self, phi):
        """(q, G = dq/dφ, G′ = d²q/dφ²) of :meth:`pin_tree` from the loop-closure analysis."""
        s = self._state(phi)
        q = np.array([s.theta2, s.theta3 - s.theta2, s.theta4])
        G = np.array([1.0, s.omega3 - 1.0, s.omega4])
        Gp = np.array([0.0, s.alpha3, s.alpha4])
        return q, G, Gp
