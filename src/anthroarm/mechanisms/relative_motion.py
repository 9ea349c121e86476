"""Point motion under relative motion, with the Coriolis term (002 text §4-1, Eq. (4-1)–(4-17)).

Configuration (002 lines 18–159): link 2 turns θ about the fixed axis u₀ through p₀; link 3
is joined to link 2 by a cylindrical pair, turning φ about and sliding s along the axis u
(initially u₁ through p₁).  q₁ is the initial position of a point of link 3
(θ = φ = s = 0).  All vectors in the fixed frame (link 1), m and rad.

Position (4-1)–(4-6)::

    q₁′ = [R_{θ,u₀}](q₁ − p₀) + p₀,  p₁′ = [R_{θ,u₀}](p₁ − p₀) + p₀,  u = [R_{θ,u₀}] u₁,
    p = p₁′ + s u,  q = [R_{φ,u}](q₁′ − p₁′) + p₁′ + s u   (screw matrix [S_{φ,s,u,p₁′}]).

Velocity (4-7)–(4-11) (transport + relative)::

    q̇ = ṗ₀ + [W_{θ̇,u₀}](q − p₀)  +  [W_{φ̇,u}](q − p) + ṡ u.

Acceleration (4-12)–(4-17) (transport + relative + Coriolis)::

    q̈ = p̈₀ + [E_{θ̇,θ̈,u₀}](q − p₀) + [E_{φ̇,φ̈,u}](q − p) + s̈ u + 2[W_{θ̇,u₀}]([W_{φ̇,u}](q − p) + ṡ u),

where [E_{φ̇,φ̈,u}] has no [Ṗ_u] term (the relative motion is taken in link 2, where u is
fixed).  The printed (4-9) has u₀ for u and s for ṡ, (4-14) ṡ for s̈, and (4-16) a misplaced
bracket; (4-17) is printed correctly (docs/errata.md, "002 text").

Everything is vectorised over a batch of N configurations (θ, φ, s and rates of shape (N,)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..spatial.rotations import as_angle, as_vector3, check_unit_axis, rot_axis, skew
from ..spatial.screw import rotation_matrix


@dataclass(frozen=True)
class RelativeMotionGeometry:
    """u₀, p₀: fixed revolute axis of link 2; u₁, p₁: initial cylinder axis of link 3 (unit
    axes, ``ValueError`` otherwise); q₁: initial position of the point on link 3 (m)."""

    u0: np.ndarray
    p0: np.ndarray
    u1: np.ndarray
    p1: np.ndarray
    q1: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "u0", check_unit_axis(self.u0, "u0"))
        object.__setattr__(self, "u1", check_unit_axis(self.u1, "u1"))
        for n in ("p0", "p1", "q1"):
            object.__setattr__(self, n, as_vector3(getattr(self, n), n))
            if getattr(self, n).shape != (3,):
                raise ValueError(f"{n} must have shape (3,), got {getattr(self, n).shape}")


@dataclass
class RelativePosition:
    """q (point), p (point of the moving axis), u (moving axis direction), q_transported = q₁′,
    p_transported = p₁′, each (..., 3)."""

    q: np.ndarray
    p: np.ndarray
    u: np.ndarray
    q_transported: np.ndarray
    p_transported: np.ndarray


@dataclass
class RelativeVelocity:
    """q̇ = transport + relative, Eq. (4-10)/(4-11) (m/s)."""

    total: np.ndarray
    transport: np.ndarray
    relative: np.ndarray


@dataclass
class RelativeAcceleration:
    """q̈ = transport + relative + coriolis, Eq. (4-12)–(4-17) (m/s²)."""

    total: np.ndarray
    transport: np.ndarray
    relative: np.ndarray
    coriolis: np.ndarray


def _mv(M, v):
    return np.einsum("...ij,...j->...i", M, v)


def relative_position(g: RelativeMotionGeometry, theta, phi, s) -> RelativePosition:
    """Position of the point, Eq. (4-1)–(4-6) (screw-matrix form reconstructed)."""
    th, ph, s = as_angle(theta, "theta"), as_angle(phi, "phi"), as_angle(s, "s")
    R0 = rotation_matrix(th, g.u0)
    q1p = _mv(R0, g.q1 - g.p0) + g.p0
    p1p = _mv(R0, g.p1 - g.p0) + g.p0
    u = _mv(R0, g.u1)
    Ru = rot_axis(u, ph)  # [R_{φ,u}] for the (batch of) moved axes u, Rodrigues (5-84)
    p = p1p + s[..., None] * u
    q = _mv(Ru, q1p - p1p) + p
    return RelativePosition(q, p, u, q1p, p1p)


def relative_velocity(
    g: RelativeMotionGeometry,
    theta,
    theta_dot,
    phi,
    phi_dot,
    s,
    s_dot,
    p0_dot=(0.0, 0.0, 0.0),
    position: RelativePosition | None = None,
) -> RelativeVelocity:
    """q̇ = ṗ₀ + [W_{θ̇,u₀}](q − p₀) + [W_{φ̇,u}](q − p) + ṡ u, Eq. (4-7)–(4-11)."""
    pos = position or relative_position(g, theta, phi, s)
    thd, phd, sd = (
        as_angle(theta_dot, "theta_dot"),
        as_angle(phi_dot, "phi_dot"),
        as_angle(s_dot, "s_dot"),
    )
    p0d = as_vector3(p0_dot, "p0_dot")
    W0 = thd[..., None, None] * skew(g.u0)
    Wu = phd[..., None, None] * skew(pos.u)
    transport = p0d + _mv(W0, pos.q - g.p0)
    relative = _mv(Wu, pos.q - pos.p) + sd[..., None] * pos.u
    return RelativeVelocity(transport + relative, transport, relative)


def relative_acceleration(
    g: RelativeMotionGeometry,
    theta,
    theta_dot,
    theta_ddot,
    phi,
    phi_dot,
    phi_ddot,
    s,
    s_dot,
    s_ddot,
    p0_ddot=(0.0, 0.0, 0.0),
    position: RelativePosition | None = None,
) -> RelativeAcceleration:
    """q̈ = transport (4-13) + relative (4-14) + Coriolis (4-15)/(4-16), total (4-17)."""
    pos = position or relative_position(g, theta, phi, s)
    thd, thdd = as_angle(theta_dot, "theta_dot"), as_angle(theta_ddot, "theta_ddot")
    phd, phdd = as_angle(phi_dot, "phi_dot"), as_angle(phi_ddot, "phi_ddot")
    sd, sdd = as_angle(s_dot, "s_dot"), as_angle(s_ddot, "s_ddot")
    p0dd = as_vector3(p0_ddot, "p0_ddot")
    P0, Pu = skew(g.u0), skew(pos.u)
    E0 = thdd[..., None, None] * P0 + (thd**2)[..., None, None] * (P0 @ P0)
    Eu = phdd[..., None, None] * Pu + (phd**2)[..., None, None] * (Pu @ Pu)
    W0 = thd[..., None, None] * P0
    Wu = phd[..., None, None] * Pu
    transport = p0dd + _mv(E0, pos.q - g.p0)
    relative = _mv(Eu, pos.q - pos.p) + sdd[..., None] * pos.u
    qr_dot = _mv(Wu, pos.q - pos.p) + sd[..., None] * pos.u
    coriolis = 2.0 * _mv(W0, qr_dot)
    return RelativeAcceleration(transport + relative + coriolis, transport, relative, coriolis)


def pinocchio_model(g: RelativeMotionGeometry) -> tuple[pin.Model, int]:
    """The two-link chain as a Pinocchio model: RevoluteUnaligned(u₀) at p₀, then
    PrismaticUnaligned(u₁) and RevoluteUnaligned(u₁) at p₁, and a frame at q₁.  Configuration
    (θ, s, φ).  Returns (model, frame id of the point)."""
    model = pin.Model()
    I = pin.Inertia.FromSphere(1.0, 0.05)
    j1 = model.addJoint(0, pin.JointModelRevoluteUnaligned(g.u0), pin.SE3(np.eye(3), g.p0), "theta")
    model.appendBodyToJoint(j1, I, pin.SE3.Identity())
    j2 = model.addJoint(
        j1, pin.JointModelPrismaticUnaligned(g.u1), pin.SE3(np.eye(3), g.p1 - g.p0), "s"
    )
    model.appendBodyToJoint(j2, I, pin.SE3.Identity())
    j3 = model.addJoint(j2, pin.JointModelRevoluteUnaligned(g.u1), pin.SE3.Identity(), "phi")
    model.appendBodyToJoint(j3, I, pin.SE3.Identity())
    fid = model.addFrame(
        pin.Frame("q", j3, 0, pin.SE3(np.eye(3), g.q1 - g.p1), pin.FrameType.OP_FRAME)
    )
    return model, fid
