"""Spatial RRSS four-bar: closed form (book §6-5, Eqs. (6-93)-(6-113)) and Newton-Raphson with
continuation on the constraint equations (002 text §4-3, Eqs. (4-42)-(4-49)).

Mechanism: link R1 turns by theta1 about the fixed unit axis ``u0`` through ``a0``; link R2 is
hinged to R1 at ``a`` about the axis ``u_a`` (``a1``, ``u1`` at theta1 = 0) and turns by theta2
relative to R1; a constant-length S-S bar joins ``b`` on R2 (``b1`` initially) to the fixed
sphere centre ``b0``.  (002 names R1 "link 2", R2 "link 3 / coupler" and the S-S bar "link 4".)
World frame, SI units, angles rad, right-handed about the axes.

Closed form (6-93)-(6-99), subscripts reconstructed (``docs/errata.md``):
a = R(th1,u0)(a1 - a0) + a0, b' = R(th1,u0)(b1 - a0) + a0, u_a = R(th1,u0) u1,
b = R(th2,u_a)(b' - a) + a, |b - b0| = |b1 - b0|  ->  E cos th2 + F sin th2 + G = 0,
E = (a - b0)^T (I - Q_ua)(b' - a), F = (a - b0)^T P_ua (b' - a),
G = (a - b0)^T Q_ua (b' - a) + 1/2 (|b' - a|^2 + |a - b0|^2 - |b1 - b0|^2),
th2 = 2 atan2(-F +/- sqrt(E^2 + F^2 - G^2), G - E).
Velocity (6-102)-(6-105), acceleration (6-109)-(6-111) with the transport, relative and
Coriolis terms of (6-110).

Newton form (002 §4-3): the coupler (R2) pose is (rotation vector rho, reference point p = a),
six unknowns; the six equations are (4-42)-(4-46) — written with the reference values on the
right so that a1 need not be the foot of the common normal (the print's zero right-hand sides are
that special case) — plus the input equation (a - a0) . R(th1,u0)(u0 x (a1 - a0)) = 0.  The 002
text's unknowns (u, phi) make the Jacobian rank-deficient at phi = 0 (u drops out); the rotation
vector with Pinocchio's right Jacobian ``pin.Jexp3`` is regular there, so the march can start at
the reference configuration.  Velocities solve the linear form of (4-48)/(4-49) in (p', omega),
accelerations its time derivative.

A closed-form state whose numbers cannot be represented (lengths near the float range, where
E^2 + F^2 - G^2 grows as their fourth power; rates whose squares overflow) is a ``ValueError``
naming the quantity, never inf or NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ._util import (
    Wdot,
    assembly_status,
    difference,
    finite_array,
    finite_scalar,
    norm,
    out,
    point3,
    pow2_scale,
    representable_fields,
    rot,
    skew,
    unit_axis,
)

DEAD_POINT_TOL = 1e-7

__all__ = [
    "RRSSGeometry",
    "RRSSState",
    "RRSSPoint",
    "rrss",
    "rrss_position",
    "rrss_efg",
    "rrss_branch_through",
    "rrss_point",
    "rrss_newton",
    "rrss_track",
    "rrss_constraints",
]


@dataclass(frozen=True)
class RRSSGeometry:
    """Fixed axis ``u0`` through ``a0``; hinge point ``a1`` with axis ``u1``; sphere centres
    ``b1`` (moving, on R2) and ``b0`` (fixed).  m, world frame, unit axes."""

    a0: np.ndarray
    u0: np.ndarray
    a1: np.ndarray
    u1: np.ndarray
    b0: np.ndarray
    b1: np.ndarray

    def __post_init__(self):
        for n in ("a0", "a1", "b0", "b1"):
            object.__setattr__(self, n, point3(n, getattr(self, n)))
        object.__setattr__(self, "u0", unit_axis("u0", self.u0))
        object.__setattr__(self, "u1", unit_axis("u1", self.u1))
        if self.bar_length == 0.0:
            raise ValueError(f"b1 and b0 coincide ({self.b1.tolist()}): zero-length S-S bar")
        d = difference("b1 - a1", self.b1, self.a1)
        d = d / pow2_scale(d)  # exact; no overflow of the projection
        if np.linalg.norm(d - self.u1 * (self.u1 @ d)) == 0.0:
            raise ValueError(
                f"b1 = {self.b1.tolist()} lies on the hinge axis u1: theta2 cannot move it"
            )

    @property
    def bar_length(self) -> float:
        return float(norm("b1 - b0", difference("b1 - b0", self.b1, self.b0)))

    @property
    def length_scale(self) -> float:
        return float(
            norm("a1 - a0", difference("a1 - a0", self.a1, self.a0))
            + norm("b1 - a1", difference("b1 - a1", self.b1, self.a1))
            + self.bar_length
        )


@dataclass(frozen=True)
class RRSSState:
    """RRSS configuration and rates.  ``theta2`` is R2's rotation relative to R1 about u_a;
    ``R2`` its world rotation relative to the reference pose (3x3 or (..., 3, 3)); points and
    axes (..., 3).  ``status`` "ok" | "dead_point" | "cannot_assemble" | "branch_lost"."""

    theta1: object
    theta2: object
    theta1dot: object
    theta2dot: object
    theta1ddot: object
    theta2ddot: object
    a: np.ndarray
    u_a: np.ndarray
    b: np.ndarray
    adot: np.ndarray
    bdot: np.ndarray
    addot: np.ndarray
    bddot: np.ndarray
    R2: np.ndarray
    omega2: np.ndarray  #: world angular velocity of R2 (rad/s)
    omegadot2: np.ndarray  #: world angular acceleration of R2 (rad/s^2)
    branch: int
    assembled: object
    dead_point: object
    status: object
    reason: str
    residual: object  #: | |b - b0| - |b1 - b0| |, m
    iterations: int = 0

    @property
    def ok(self):
        return out(np.logical_and(self.assembled, np.logical_not(self.dead_point)))


@dataclass(frozen=True)
class RRSSPoint:
    """A point fixed on R2 (initially P1): position, velocity, acceleration (..., 3)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def _vec(M, v):
    return np.einsum("...ij,...j->...i", M, v)


def _dot(x, y):
    return np.einsum("...i,...i", x, y)


def rrss_efg(geom: RRSSGeometry, theta1):
    """E, F, G of (6-98) and a, b', u_a of (6-93)-(6-95), vectorised over theta1."""
    th1 = finite_array("theta1", theta1)
    R1 = rot(th1, geom.u0)
    a = _vec(R1, geom.a1 - geom.a0) + geom.a0  # (6-93)
    bp = _vec(R1, geom.b1 - geom.a0) + geom.a0  # (6-94)
    ua = _vec(R1, np.broadcast_to(geom.u1, R1.shape[:-1]))  # (6-95)
    c = a - geom.b0
    e = bp - a
    ue = _dot(ua, e)
    E = _dot(c, e - ua * ue[..., None])
    F = _dot(c, np.cross(ua, e))
    G = _dot(c, ua) * ue + 0.5 * (_dot(e, e) + _dot(c, c) - np.float64(geom.bar_length) ** 2)
    return E, F, G, a, bp, ua


def _half_angle(E, F, G, s, root):
    n1, d1 = -F + s * root, G - E
    n2, d2 = G + E, -F - s * root
    half = np.where(np.hypot(n1, d1) >= np.hypot(n2, d2), np.arctan2(n1, d1), np.arctan2(n2, d2))
    return np.mod(2 * half + np.pi, 2 * np.pi) - np.pi


def rrss_position(geom: RRSSGeometry, theta1, branch: int = 1) -> RRSSState:
    """Closed-form position (6-93)-(6-99); rates zero."""
    return rrss(geom, theta1, 0.0, 0.0, branch)


def rrss(geom: RRSSGeometry, theta1, theta1dot=0.0, theta1ddot=0.0, branch: int = 1) -> RRSSState:
    """Closed-form RRSS: position (6-93)-(6-99), velocity (6-102)-(6-105), acceleration
    (6-109)-(6-111).

    th2' = -th1' (b - b0)^T [P_u0 (b - a0)] / ((b - b0)^T [P_ua (b - a)])              (6-105)
    th2'' = -{(b - b0)^T [b''_e + th2'^2 P_ua^2 (b - a) + b''_c] + |b'|^2} / ((b - b0)^T [P_ua (b -
    a)])   (6-111) b''_e = Wdot(th1', th1'', u0)(b - a0) (transport), b''_c = 2 W(th1', u0) W(th2',
    u_a)(b - a) (Coriolis). ``branch`` +1 takes the "+" root of (6-99)."""
    if branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {branch!r}")
    th1, w1, al1 = np.broadcast_arrays(
        finite_array("theta1", theta1),
        finite_array("theta1dot", theta1dot),
        finite_array("theta1ddot", theta1ddot),
    )
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        E, F, G, a, bp, ua = rrss_efg(geom, th1)
        disc = E * E + F * F - G * G
        L = np.float64(
            geom.length_scale
        )  # numpy: overflow is inf (checked below), not OverflowError
        assembled = disc >= -1e-12 * L**4
        th2 = _half_angle(E, F, G, branch, np.sqrt(np.clip(disc, 0.0, None)))  # (6-99)
        R2rel = _rot_batch(th2, ua)
        b = _vec(R2rel, bp - a) + a  # (6-96)
        R1 = rot(th1, geom.u0)
        u0 = geom.u0
        rb0, rba, rba0 = b - geom.b0, b - a, b - geom.a0
        den = _dot(rb0, np.cross(ua, rba))
        dead = assembled & (
            np.abs(den) < DEAD_POINT_TOL * geom.bar_length * np.linalg.norm(geom.b1 - geom.a1)
        )
        good = assembled & ~dead
        dens = np.where(good, den, 1.0)
        w2 = np.where(good, -w1 * _dot(rb0, np.cross(u0, rba0)) / dens, 0.0)  # (6-105)
        om1 = w1[..., None] * u0
        adot = np.cross(om1, a - geom.a0)  # (6-106)
        bdot = np.cross(om1, rba0) + w2[..., None] * np.cross(ua, rba)  # (6-103)/(6-104)
        b_e = _vec(Wdot(w1, al1, u0), rba0)  # transport
        b_c = 2 * np.cross(om1, w2[..., None] * np.cross(ua, rba))  # Coriolis
        cen = (w2**2)[..., None] * np.cross(ua, np.cross(ua, rba))
        al2 = np.where(
            good, -(_dot(rb0, b_e + cen + b_c) + _dot(bdot, bdot)) / dens, 0.0
        )  # (6-111)
        addot = _vec(Wdot(w1, al1, u0), a - geom.a0)  # (6-112)
        bddot = b_e + al2[..., None] * np.cross(ua, rba) + cen + b_c  # (6-110)
        om2 = om1 + w2[..., None] * ua
        uadot = np.cross(om1, ua)
        omd2 = al1[..., None] * u0 + al2[..., None] * ua + w2[..., None] * uadot
        st, reason = assembly_status(
            assembled,
            dead,
            th1,
            disc,
            "theta1",
            "branch point: E^2 + F^2 - G^2 = 0 (S-S bar in the plane of b's motion about u_a); "
            "rates reported as 0",
        )
        if not np.all(good):
            z = ~good[..., None]
            bdot, bddot = np.where(z, 0.0, bdot), np.where(z, 0.0, bddot)
            om2, omd2 = np.where(z, 0.0, om2), np.where(z, 0.0, omd2)
        res = np.abs(np.linalg.norm(rb0, axis=-1) - geom.bar_length)
    st_ = RRSSState(
        theta1=out(th1),
        theta2=out(th2),
        theta1dot=out(w1),
        theta2dot=out(w2),
        theta1ddot=out(al1),
        theta2ddot=out(al2),
        a=a,
        u_a=ua,
        b=b,
        adot=adot,
        bdot=bdot,
        addot=addot,
        bddot=bddot,
        R2=R2rel @ R1,
        omega2=om2,
        omegadot2=omd2,
        branch=int(branch),
        assembled=out(assembled),
        dead_point=out(dead),
        status=out(st),
        reason=reason,
        residual=out(res),
    )
    return representable_fields(
        st_,
        f"length scale {geom.length_scale:.3g} m, theta1dot up to "
        f"{np.max(np.abs(w1)):.3g} rad/s, theta1ddot up to {np.max(np.abs(al1)):.3g} rad/s^2",
    )


def _rot_batch(theta, u):
    """R(theta, u) with u batched (..., 3) (Rodrigues, Eq. (6-88))."""
    P = skew(u)
    c = np.cos(theta)[..., None, None]
    s = np.sin(theta)[..., None, None]
    return np.eye(3) + s * P + (1 - c) * (P @ P)


def rrss_branch_through(geom: RRSSGeometry, theta1: float = 0.0, theta2: float = 0.0) -> int:
    """The branch sign whose solution passes through (theta1, theta2) — by default the reference
    configuration (b = b1 at theta1 = 0), "the sign comes from the initial state" (6-99)."""
    err = [
        abs(np.angle(np.exp(1j * (rrss_position(geom, theta1, s).theta2 - theta2))))
        for s in (1, -1)
    ]
    return 1 if err[0] <= err[1] else -1


def rrss_point(geom: RRSSGeometry, state: RRSSState, P1) -> RRSSPoint:
    """A point fixed on R2 (initial position P1): P = R(th2,u_a)(P' - a) + a with
    P' = R(th1,u0)(P1 - a0) + a0 (6-100)/(6-101); P' = th1' P_u0 (P - a0) + th2' P_ua (P - a)
    (6-107)/(6-108); P'' = transport + relative + Coriolis (6-113)."""
    P1 = point3("P1", P1)
    P = _vec(np.asarray(state.R2), P1 - geom.a1) + state.a
    u0, ua = geom.u0, state.u_a
    w1 = np.asarray(state.theta1dot, float)
    w2 = np.asarray(state.theta2dot, float)
    al1 = np.asarray(state.theta1ddot, float)
    al2 = np.asarray(state.theta2ddot, float)
    om1 = w1[..., None] * u0
    rP0, rPa = P - geom.a0, P - state.a
    V = np.cross(om1, rP0) + w2[..., None] * np.cross(ua, rPa)
    A = (
        _vec(Wdot(w1, al1, u0), rP0)
        + al2[..., None] * np.cross(ua, rPa)
        + (w2**2)[..., None] * np.cross(ua, np.cross(ua, rPa))
        + 2 * np.cross(om1, w2[..., None] * np.cross(ua, rPa))
    )
    return RRSSPoint(P, V, A)


# ---------------------------------------------------------------------------------------------
# 002 §4-3: constraint equations and Newton-Raphson with continuation
# ---------------------------------------------------------------------------------------------
def _pose(geom, x):
    """Coupler pose from x = (p, rho): R = exp3(rho); a = p; b = R (b1 - a1) + p; u_a = R u1."""
    p, rho = x[:3], x[3:]
    R = pin.exp3(rho)
    return R, p, R @ (geom.b1 - geom.a1) + p, R @ geom.u1


def rrss_constraints(geom: RRSSGeometry, x, theta1: float) -> np.ndarray:
    """The six residuals of 002 §4-3 at coupler pose x = (p, rotation vector rho):
    (4-42) u0.(a - a0) = u0.(a1 - a0); (4-43) u_a.(a - a0) = u1.(a1 - a0); (4-44) u0.u_a = u0.u1;
    (4-45) ((a - a0) x u_a).u0 = ((a1 - a0) x u1).u0; (4-46) |b - b0|^2 = |b1 - b0|^2;
    input: (a - a0).R(th1,u0)(u0 x (a1 - a0)) = 0.  All in m (or m^2 for (4-46), m for the rest
    after dividing by the length scale where needed)."""
    R, a, b, ua = _pose(geom, np.asarray(x, float))
    u0, d1 = geom.u0, geom.a1 - geom.a0
    d = a - geom.a0
    n = rot(theta1, u0) @ np.cross(u0, d1)
    return np.array(
        [
            u0 @ d - u0 @ d1,
            ua @ d - geom.u1 @ d1,
            u0 @ ua - u0 @ geom.u1,
            np.cross(d, ua) @ u0 - np.cross(d1, geom.u1) @ u0,
            ((b - geom.b0) @ (b - geom.b0) - geom.bar_length**2) / (2 * geom.bar_length),
            d @ n / max(np.linalg.norm(d1), 1e-300),
        ]
    )


def _G(geom, x, theta1):
    """Rows of the linearised constraints in (dp, dphi_world) (the matrix of (4-48)/(4-49)) and
    the input column dc/dtheta1."""
    R, a, b, ua = _pose(geom, x)
    u0, d1 = geom.u0, geom.a1 - geom.a0
    d = a - geom.a0
    n = rot(theta1, u0) @ np.cross(u0, d1)
    nd1 = max(np.linalg.norm(d1), 1e-300)
    L = geom.bar_length
    z = np.zeros(3)
    G = np.array(
        [
            np.r_[u0, z],
            np.r_[ua, np.cross(ua, d)],
            np.r_[z, np.cross(ua, u0)],
            np.r_[np.cross(ua, u0), np.cross(ua, np.cross(u0, d))],
            np.r_[(b - geom.b0) / L, np.cross(b - a, b - geom.b0) / L],
            np.r_[n / nd1, z],
        ]
    )
    g_th = np.zeros(6)
    g_th[5] = d @ np.cross(u0, n) / nd1
    return G, g_th, (R, a, b, ua, d, n, nd1)


def _newton(geom, x, theta1, tol, max_iter=30):
    r = rrss_constraints(geom, x, theta1)
    for it in range(max_iter):
        if np.linalg.norm(r) <= tol:
            return x, r, it, True
        G, _, (R, *_rest) = _G(geom, x, theta1)
        J = G @ np.block([[np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), R @ pin.Jexp3(x[3:])]])
        try:
            dx = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            return x, r, it, False
        if not np.all(np.isfinite(dx)):
            return x, r, it, False
        x = x + dx
        r = rrss_constraints(geom, x, theta1)
    return x, r, max_iter, bool(np.linalg.norm(r) <= tol)


def _rates(geom, x, theta1, w1, al1):
    """(p', omega) and (p'', omegadot) from the linearised constraints; cond = conditioning."""
    G, g_th, (R, a, b, ua, d, n, nd1) = _G(geom, x, theta1)
    u0 = geom.u0
    L = geom.bar_length
    s = np.linalg.svd(G, compute_uv=False)
    if s[-1] < DEAD_POINT_TOL * s[0]:
        return None
    v = np.linalg.solve(G, -g_th * w1)
    pd, om = v[:3], v[3:]
    bd = pd + np.cross(om, b - a)
    uad = np.cross(om, ua)
    b0dd = np.cross(om, np.cross(om, b - a))
    ua0dd = np.cross(om, np.cross(om, ua))
    ndot = w1 * np.cross(u0, n)
    quad = np.array(
        [
            0.0,
            ua0dd @ d + 2 * uad @ pd,
            u0 @ ua0dd,
            np.cross(ua0dd, u0) @ d + 2 * np.cross(uad, u0) @ pd,
            ((b - geom.b0) @ b0dd + bd @ bd) / L,
            (2 * pd @ ndot + w1**2 * d @ np.cross(u0, np.cross(u0, n))) / nd1,
        ]
    )
    acc = np.linalg.solve(G, -quad - g_th * al1)
    return pd, om, acc[:3], acc[3:]


def _state_from_x(geom, x, th1, w1, al1, iters, status, reason, rates):
    R, a, b, ua = _pose(geom, x)
    R1 = rot(th1, geom.u0)
    Rrel = R @ R1.T
    th2 = float(pin.log3(Rrel) @ ua)
    if rates is None:
        z = np.zeros(3)
        pd = om = pdd = omd = z
        w2 = al2 = 0.0
    else:
        pd, om, pdd, omd = rates
        w2 = float(ua @ (om - w1 * geom.u0))
        al2 = float(ua @ (omd - al1 * geom.u0))
    bdot = pd + np.cross(om, b - a)
    bddot = pdd + np.cross(omd, b - a) + np.cross(om, np.cross(om, b - a))
    res = abs(np.linalg.norm(b - geom.b0) - geom.bar_length)
    assembled = status in ("ok", "dead_point")
    return RRSSState(
        theta1=float(th1),
        theta2=th2,
        theta1dot=float(w1),
        theta2dot=w2,
        theta1ddot=float(al1),
        theta2ddot=al2,
        a=a,
        u_a=ua,
        b=b,
        adot=pd,
        bdot=bdot,
        addot=pdd,
        bddot=bddot,
        R2=R,
        omega2=om,
        omegadot2=omd,
        branch=0,
        assembled=assembled,
        dead_point=status == "dead_point",
        status=status,
        reason=reason,
        residual=float(res),
        iterations=iters,
    )


def rrss_track(
    geom: RRSSGeometry,
    theta1_path,
    theta1dot=0.0,
    theta1ddot=0.0,
    x0=None,
    tol: float = 1e-14,
    max_halvings: int = 12,
) -> list:
    """Newton-Raphson with continuation along ``theta1_path`` (002 §4-3: "use the previous
    position's solution as the initial estimate").

    Starts at ``x0`` = (p, rho) for the first path value (default: the reference pose p = a1,
    rho = 0, which closes at theta1 = 0 — so the path should start at 0 unless x0 is given).
    Each step uses a tangent predictor from the velocity solution and halves the step when Newton
    fails; when even tiny steps fail the branch is lost (a dead point / assembly limit) and this
    and every later entry get ``status="branch_lost"``.  Returns a list of :class:`RRSSState`."""
    path = np.atleast_1d(finite_array("theta1_path", theta1_path))
    w1 = finite_scalar("theta1dot", theta1dot)
    al1 = finite_scalar("theta1ddot", theta1ddot)
    tol_abs = tol * geom.length_scale
    x = np.r_[geom.a1, 0.0, 0.0, 0.0] if x0 is None else finite_array("x0", x0, (6,)).copy()
    th_prev = 0.0 if x0 is None else float(path[0])
    states = []
    lost = None
    for th in path:
        th = float(th)
        if lost is None:
            x, ok, iters = _march(geom, x, th_prev, th, tol_abs, max_halvings)
            if not ok:
                lost = (
                    f"branch lost between theta1 = {th_prev:.6g} and {th:.6g}: Newton fails even "
                    "for tiny steps (dead point or assembly limit)"
                )
            else:
                th_prev = th
        if lost is not None:
            states.append(_state_from_x(geom, x, th_prev, 0.0, 0.0, 0, "branch_lost", lost, None))
            continue
        r = _rates(geom, x, th, w1, al1)
        if r is None:
            states.append(
                _state_from_x(
                    geom,
                    x,
                    th,
                    w1,
                    al1,
                    iters,
                    "dead_point",
                    "dead point: the constraint Jacobian is singular; rates reported as 0",
                    None,
                )
            )
        else:
            states.append(_state_from_x(geom, x, th, w1, al1, iters, "ok", "ok", r))
    return states


def _march(geom, x, th_from, th_to, tol, max_halvings):
    """Continuation from a solution x at th_from to th_to; returns (x, converged, iterations)."""
    total = 0
    t = th_from
    h = th_to - th_from
    halvings = 0
    while abs(th_to - t) > 0.0:
        step = h if abs(h) <= abs(th_to - t) else th_to - t
        # tangent predictor
        r = _rates(geom, x, t, 1.0, 0.0)
        xp = x.copy()
        if r is not None:
            pd, om = r[0], r[1]
            R = pin.exp3(x[3:])
            xp[:3] += pd * step
            xp[3:] += np.linalg.solve(R @ pin.Jexp3(x[3:]), om) * step
        xn, _, it, ok = _newton(geom, xp, t + step, tol)
        total += it
        if ok and np.linalg.norm(xn[3:] - x[3:]) < 0.5 + 2 * abs(
            step
        ):  # guard against branch jumps
            x, t = xn, t + step
            if halvings:
                h, halvings = h * 2, halvings - 1
        else:
            halvings += 1
            if halvings > max_halvings:
                return x, False, total
            h = step / 2
    return x, True, total


def rrss_newton(
    geom: RRSSGeometry, theta1, theta1dot=0.0, theta1ddot=0.0, steps: int = 8, tol: float = 1e-14
) -> RRSSState:
    """One configuration by continuation from the reference pose (theta1 = 0) in ``steps``
    equal steps, then velocity and acceleration (002 (4-48)/(4-49) and their derivative)."""
    th = finite_scalar("theta1", theta1)
    if steps < 1:
        raise ValueError(f"steps must be >= 1, got {steps!r}")
    path = np.linspace(0.0, th, int(steps) + 1)[1:]
    states = rrss_track(geom, path, theta1dot, theta1ddot, tol=tol)
    return states[-1]
