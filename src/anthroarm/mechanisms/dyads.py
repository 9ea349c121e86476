"""Planar building blocks of the finger mechanisms, book §6-5: the rigid-body subroutine
(刚体机构子程序, Fig. 6-12, Eqs. (6-66)-(6-69)) and the dyad / two-link subroutine
(二连杆机构子程序, Fig. 6-13, Eqs. (6-70)-(6-87)).

Points are planar (x, y) in one fixed frame (m), angles absolute from +x, counter-clockwise,
rad.  Every function is vectorised over leading axes: points (..., 2), angles (...).

Corrections to the print (``docs/errata.md``, Chapter 6): (6-73)/(6-77) use arctan of a ratio,
which loses the quadrant -> atan2; the acceleration formulas (6-86)/(6-87) are printed as
*velocities* (single dot) but give the angular *accelerations*; the tag of (6-75) is printed
"(6-25)".

Any length scale: the dyad works on lengths divided by a power of two near the largest one (an
exact scaling), so points and lengths up to the float range give finite angles; a result that
cannot be represented (points too far apart for their difference, rates whose squares overflow)
is a ``ValueError`` naming the quantity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._util import difference, finite_array, out, positive_length, pow2_scale, representable

#: |D| / (r1 r2) below this: the two links are collinear, the dyad is at a dead point
DEAD_POINT_TOL = 1e-7
ASSEMBLY_TOL = 1e-12

__all__ = ["RigidBodyPoint", "DyadState", "rigid_body_point", "dyad"]


@dataclass(frozen=True)
class RigidBodyPoint:
    """A point of a planar rigid body: position, velocity, acceleration (..., 2)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class DyadState:
    """Result of the dyad subroutine.

    ``P3`` and its rates (..., 2); ``theta1`` = direction P1->P3, ``theta2`` = direction P2->P3
    with rates; ``assembled`` (6-71)/(6-72); ``dead_point`` (links collinear, D = 0: the rates
    are unbounded and reported as 0); ``status`` "ok" | "dead_point" | "cannot_assemble"."""

    P3: np.ndarray
    P3dot: np.ndarray
    P3ddot: np.ndarray
    theta1: object
    theta2: object
    omega1: object
    omega2: object
    alpha1: object
    alpha2: object
    d: object
    assembled: object
    dead_point: object
    status: object
    reason: str

    @property
    def ok(self):
        return out(np.logical_and(self.assembled, np.logical_not(self.dead_point)))


def _pt(name, x):
    return (
        finite_array(name, x, (None,) * (np.ndim(x) - 1) + (2,))
        if np.ndim(x) >= 1
        else finite_array(name, x, (2,))
    )


def _cross_k(w, r):
    """k w x r for planar r (..., 2): (-w r_y, w r_x)."""
    return np.stack([-w * r[..., 1], w * r[..., 0]], -1)


def rigid_body_point(
    P1, P1dot, P1ddot, length, theta, thetadot=0.0, thetaddot=0.0, phi=0.0
) -> RigidBodyPoint:
    """A point at ``length`` from P1 on a rigid body turning with angle theta, offset by the
    fixed included angle ``phi`` (Eqs. (6-66)/(6-67): P = P1 + L (cos(theta + phi), sin(theta +
    phi))).

    Velocity (6-68): P' = P1' + theta' k x (P - P1); acceleration (6-69):
    P'' = P1'' + theta'' k x (P - P1) + theta' k x (theta' k x (P - P1)).
    With phi = 0 this is P2 of (6-66); with (S, phi) it is P3 of (6-67)."""
    P1, P1dot, P1ddot = _pt("P1", P1), _pt("P1dot", P1dot), _pt("P1ddot", P1ddot)
    L = positive_length("length", length)
    th = finite_array("theta", theta)
    w = finite_array("thetadot", thetadot)
    al = finite_array("thetaddot", thetaddot)
    ph = finite_array("phi", phi)
    ang = th + ph
    r = L * np.stack([np.cos(ang), np.sin(ang)], -1)
    with np.errstate(over="ignore", invalid="ignore"):
        P = P1 + r  # (6-66)/(6-67)
        V = P1dot + _cross_k(w, r)  # (6-68)
        A = P1ddot + _cross_k(al, r) - (w**2)[..., None] * r  # (6-69)
    why = f"length {L:.3g} m, thetadot up to {np.max(np.abs(w)):.3g} rad/s"
    return RigidBodyPoint(
        representable("position", P, why),
        representable("velocity", V, why),
        representable("acceleration", A, why),
    )


def dyad(P1, P1dot, P1ddot, P2, P2dot, P2ddot, r1, r2, branch: int = 1) -> DyadState:
    """Two links r1 (P1-P3) and r2 (P2-P3) jointed at P3, with P1, P2 and their rates known.

    Position: d^2 = |P2 - P1|^2 (6-70); exists iff |r1 - r2| <= d <= r1 + r2 (6-71)/(6-72);
    phi = atan2(P2y - P1y, P2x - P1x) (6-73, atan2 for the printed arctan);
    alpha = arccos((r1^2 + d^2 - r2^2)/(2 r1 d)) (6-74); theta1 = phi + branch*alpha (6-75);
    P3 = P1 + r1 (cos theta1, sin theta1) (6-76); theta2 = atan2(P3 - P2) (6-77).
    Rates with a = P3x - P1x, b = P3y - P1y, c = P3x - P2x, d = P3y - P2y, D = bc - ad:
    theta1' = -((P2x' - P1x') c + (P2y' - P1y') d)/D (6-83), theta2' = -((P2x' - P1x') a + (P2y' -
    P1y') b)/D (6-84), theta1'' = -(E c + F d)/D (6-86), theta2'' = -(E a + F b)/D (6-87), with
    E = (P2x'' - P1x'') + theta1'^2 a - theta2'^2 c, F = (P2y'' - P1y'') + theta1'^2 b - theta2'^2
    d. P3', P3'' from (6-78)/(6-85)."""
    P1, P1dot, P1ddot = _pt("P1", P1), _pt("P1dot", P1dot), _pt("P1ddot", P1ddot)
    P2, P2dot, P2ddot = _pt("P2", P2), _pt("P2dot", P2dot), _pt("P2ddot", P2ddot)
    r1 = positive_length("r1", r1)
    r2 = positive_length("r2", r2)
    if branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {branch!r}")
    P1, P2, P1dot, P2dot, P1ddot, P2ddot = np.broadcast_arrays(P1, P2, P1dot, P2dot, P1ddot, P2ddot)
    dv = difference("P2 - P1", P2, P1)
    # every length / L (a power of two: exact), so no square overflows or underflows
    L = pow2_scale(r1, r2, dv)
    n1, n2, dvn = r1 / L, r2 / L, dv / L
    distn = np.hypot(dvn[..., 0], dvn[..., 1])  # (6-70), d / L
    dist = distn * L
    phi = np.arctan2(dv[..., 1], dv[..., 0])  # (6-73)
    tiny = 1e-14 * (n1 + n2)
    safe = np.where(distn > tiny, distn, 1.0)
    k = np.where(
        distn > tiny,
        (n1 * n1 + distn * distn - n2 * n2) / (2 * n1 * safe),
        np.where(abs(n1 - n2) <= tiny, 1.0, 2.0),
    )
    assembled = np.abs(k) <= 1 + ASSEMBLY_TOL  # (6-71)/(6-72)
    th1 = phi + branch * np.arccos(np.clip(k, -1.0, 1.0))  # (6-74)/(6-75)
    r = r1 * np.stack([np.cos(th1), np.sin(th1)], -1)
    P3 = representable("P3", P1 + r, "the points are too far apart")  # (6-76)
    rn = n1 * np.stack([np.cos(th1), np.sin(th1)], -1)  # (P3 - P1) / L
    qn = rn - dvn  # (P3 - P2) / L
    th2 = np.arctan2(qn[..., 1], qn[..., 0])  # (6-77)
    a, b = rn[..., 0], rn[..., 1]  # a, b, c, d of (6-83) / L
    c, dd = qn[..., 0], qn[..., 1]
    D = b * c - a * dd  # D / L^2
    dead = assembled & (np.abs(D) < DEAD_POINT_TOL * n1 * n2)
    good = assembled & ~dead
    Ds = np.where(good, D, 1.0) * L
    with np.errstate(over="ignore", invalid="ignore"):
        X, Y = P2dot[..., 0] - P1dot[..., 0], P2dot[..., 1] - P1dot[..., 1]
        w1 = np.where(good, -(X * c + Y * dd) / Ds, 0.0)  # (6-83)
        w2 = np.where(good, -(X * a + Y * b) / Ds, 0.0)  # (6-84)
        E = (P2ddot[..., 0] - P1ddot[..., 0]) + L * (w1**2 * a - w2**2 * c)
        F = (P2ddot[..., 1] - P1ddot[..., 1]) + L * (w1**2 * b - w2**2 * dd)
        a1 = np.where(good, -(E * c + F * dd) / Ds, 0.0)  # (6-86), corrected to theta''
        a2 = np.where(good, -(E * a + F * b) / Ds, 0.0)  # (6-87), corrected to theta''
        V = P1dot + _cross_k(w1, r)  # (6-78)
        A = P1ddot + _cross_k(a1, r) - (w1**2)[..., None] * r  # (6-85)
    why = "rates of the points too large for these lengths"
    w1, w2 = representable("omega1", w1, why), representable("omega2", w2, why)
    a1, a2 = representable("alpha1", a1, why), representable("alpha2", a2, why)
    V, A = representable("P3dot", V, why), representable("P3ddot", A, why)
    st = np.where(~assembled, "cannot_assemble", np.where(dead, "dead_point", "ok"))
    if np.ndim(dist) == 0:
        if not assembled:
            reason = (
                f"dyad does not exist: d = {float(dist):.6g} outside [|r1 - r2|, r1 + r2] = "
                f"[{abs(r1 - r2):.6g}, {r1 + r2:.6g}] (6-71)/(6-72)"
            )
        elif dead:
            reason = (
                "dead point: the two links are collinear (D = 0); rates unbounded, reported as 0"
            )
        else:
            reason = "ok"
    else:
        na, nd = int(np.sum(~assembled)), int(np.sum(dead))
        reason = (
            "ok" if na == nd == 0 else f"{na} of {dist.size} cannot assemble, {nd} at a dead point"
        )
    return DyadState(
        P3=P3,
        P3dot=V,
        P3ddot=A,
        theta1=out(th1),
        theta2=out(th2),
        omega1=out(w1),
        omega2=out(w2),
        alpha1=out(a1),
        alpha2=out(a2),
        d=out(dist),
        assembled=out(assembled),
        dead_point=out(dead),
        status=out(st),
        reason=reason,
    )
