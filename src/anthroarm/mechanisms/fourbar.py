"""Planar four-bar linkage: position (both assembly branches), velocity, acceleration, coupler
points.

Two independent formulations of the same mechanism, cross-checked against each other, against
finite differences and against Pinocchio (:mod:`anthroarm.mechanisms.closed_loop`):

* **complex polar vectors**, book §5-2, Fig. 5-1, Eqs. (5-12)-(5-22), **corrected**
  (the printed (5-17), (5-19), (5-20), (5-22) and the A, B terms of (5-21)/(5-22) are wrong,
  see ``docs/errata.md``); :func:`fourbar_position`, :func:`fourbar_velocity`,
  :func:`fourbar_acceleration`, all in one call :func:`fourbar`;
* **Cartesian vectors**, book §5-3, Fig. 5-5 (loop r2 + r3 = r1 + r4, general ground vector,
  general crank acceleration); :func:`fourbar_cartesian`.

Conventions (book): the crank pivot O2 is the origin; the ground vector r1 runs from O2 to the
rocker pivot O4 and lies on +x in the complex method; theta2, theta3, theta4 are **absolute**
angles from +x, counter-clockwise positive, rad; lengths in m (any consistent unit works).
r2 = crank O2-A, r3 = coupler A-B, r4 = rocker O4-B.  The loop is
``r2 e^{i th2} + r3 e^{i th3} = r1 + r4 e^{i th4}`` (5-18).

Scale: lengths may have any magnitude the float range holds, but the longest link may be at
most ``MAX_LENGTH_RATIO`` (1e150) times the shortest (``ValueError`` otherwise).  Every formula runs
on lengths divided by the longest link and on rates divided by a rate scale (the largest of |th2'|,
|th3'|, |th4'|, sqrt|th2''|), so angles do not depend on the unit of length (1e-155 m and 1e155 m
give the same angles) and no intermediate square overflows.  A result that is itself beyond the
float range (e.g. th2' = 1e300 rad/s, whose accelerations are ~1e600) is a ``ValueError`` naming the
quantity.

Branches: ``branch=+1`` is the book's (5-16) ``th3 = th_d + arccos(...)``; ``branch=-1`` is the
other assembly mode ``th_d - arccos(...)``.

Bad configurations never raise and never return NaN: a state carries ``assembled`` (False when
the loop cannot close: the returned angles are then the nearest stretched/folded pose and
``residual`` says how far the loop is from closing), ``dead_point`` (coupler and rocker
collinear: transmission angle 0 or pi, the crank-driven branch point where velocities are
unbounded; rates are reported as 0 there) and ``status`` in {"ok", "dead_point",
"cannot_assemble"} with a human-readable ``reason``.  Everything is vectorised over arrays of
theta2 (and omega2, alpha2); scalars in give Python scalars out.

>>> s = fourbar(4.0, 1.5, 3.5, 3.0, 0.7, omega2=2.0)
>>> round(s.theta4, 6), round(s.omega4, 6)
(1.572195, 0.098073)
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ._util import finite_array, finite_scalar, out, positive_length

#: |sin(theta3 - theta4)| below this is a dead point (coupler and rocker collinear); above the
#: ~sqrt(eps) resolution of the toggle angle itself
DEAD_POINT_TOL = 1e-7
#: the cosine of (5-16) may exceed 1 by this much (round-off at a toggle) and still assemble
ASSEMBLY_TOL = 1e-12
#: longest / shortest link above this is a ValueError (squares of the ratio must stay in range)
MAX_LENGTH_RATIO = 1e150

__all__ = [
    "FourBarState",
    "CouplerPoint",
    "FourBarRange",
    "fourbar",
    "fourbar_position",
    "fourbar_velocity",
    "fourbar_acceleration",
    "fourbar_cartesian",
    "coupler_point",
    "fourbar_points",
    "fourbar_input_range",
    "fourbar_grashof",
    "transmission_angle",
]


@dataclass(frozen=True)
class FourBarState:
    """Position (and, once computed, velocity and acceleration) of a planar four-bar.

    Angles are absolute, rad, counter-clockwise from +x of the ground frame (origin at the
    crank pivot O2).  ``ground_angle`` is the direction of r1 (0 for the complex method).
    Scalars for a scalar ``theta2``, arrays of the broadcast shape otherwise."""

    r1: float
    r2: float
    r3: float
    r4: float
    branch: int
    theta2: object
    theta3: object
    theta4: object
    d: object  #: crank-tip to rocker-pivot distance, Eq. (5-13)
    theta_d: object  #: its direction, Eq. (5-14)
    assembled: object  #: the loop closes
    dead_point: object  #: coupler and rocker collinear (sin(th3 - th4) = 0)
    status: object  #: "ok" | "dead_point" | "cannot_assemble"
    reason: str
    residual: object  #: |loop closure error|, same unit as the lengths
    ground_angle: float = 0.0
    omega2: object = 0.0
    omega3: object = 0.0
    omega4: object = 0.0
    alpha2: object = 0.0
    alpha3: object = 0.0
    alpha4: object = 0.0

    @property
    def ok(self):
        """True where the state is assembled and not at a dead point."""
        return out(np.logical_and(self.assembled, np.logical_not(self.dead_point)))

    @property
    def transmission_angle(self):
        """Angle between coupler and rocker in [0, pi] (pi/2 is best; 0 or pi = dead point)."""
        mu = np.abs(
            np.mod(np.asarray(self.theta3) - np.asarray(self.theta4) + np.pi, 2 * np.pi) - np.pi
        )
        return out(np.pi - mu)


@dataclass(frozen=True)
class CouplerPoint:
    """A point fixed on the coupler: position, velocity and acceleration, shape (..., 2), ground
    frame."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class FourBarRange:
    """Crank angles theta2 for which the linkage assembles.

    ``full_turn`` -> the input is a crank; ``intervals`` are closed intervals in [-pi, pi]
    (empty if the linkage never assembles)."""

    full_turn: bool
    intervals: tuple

    def contains(self, theta2) -> np.ndarray | bool:
        t = np.mod(np.asarray(theta2, dtype=float) + np.pi, 2 * np.pi) - np.pi
        if self.full_turn:
            return out(np.ones_like(t, dtype=bool))
        inside = np.zeros_like(t, dtype=bool)
        for lo, hi in self.intervals:
            inside |= (t >= lo - 1e-12) & (t <= hi + 1e-12)
        return out(inside)


def _lengths(r1, r2, r3, r4):
    r = (
        positive_length("r1", r1),
        positive_length("r2", r2),
        positive_length("r3", r3),
        positive_length("r4", r4),
    )
    if max(r) > MAX_LENGTH_RATIO * min(r):
        raise ValueError(
            f"link lengths {list(r)} differ by a factor above {MAX_LENGTH_RATIO:.0e}: the squares "
            "of their ratios are not representable; such a linkage cannot be computed in floating "
            "point"
        )
    return r


def _branch(branch) -> int:
    if branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {branch!r}")
    return int(branch)


def _status(assembled, dead):
    st = np.where(~assembled, "cannot_assemble", np.where(dead, "dead_point", "ok"))
    return out(st)


def _reason(assembled, dead, d, r3, r4) -> str:
    assembled = np.asarray(assembled)
    dead = np.asarray(dead)
    if assembled.ndim == 0:
        if not assembled:
            return (
                f"cannot assemble: crank-tip to rocker-pivot distance d = {float(d):.6g} is "
                f"outside [|r3 - r4|, r3 + r4] = [{abs(r3 - r4):.6g}, {r3 + r4:.6g}]"
            )
        if dead:
            return (
                "dead point: coupler and rocker are collinear (transmission angle 0 or pi); "
                "rates are unbounded and reported as 0"
            )
        return "ok"
    n = assembled.size
    na = int(np.sum(~assembled))
    nd = int(np.sum(dead & assembled))
    if na == 0 and nd == 0:
        return "ok"
    return f"{na} of {n} configurations cannot assemble, {nd} at a dead point"


def _finish(r1, r2, r3, r4, branch, th2, th3, th4, d, thd, k, ground_angle, gx, gy):
    """Shared tail of both formulations: assembly, dead point, residual, status."""
    assembled = np.abs(k) <= 1.0 + ASSEMBLY_TOL
    s34 = np.sin(th3 - th4)
    dead = assembled & (np.abs(s34) < DEAD_POINT_TOL)
    # loop residual r2 + r3 - r1 - r4 (vector), Eq. (5-18)
    L = max(r1, r2, r3, r4)
    rx = (r2 / L) * np.cos(th2) + (r3 / L) * np.cos(th3) - gx / L - (r4 / L) * np.cos(th4)
    ry = (r2 / L) * np.sin(th2) + (r3 / L) * np.sin(th3) - gy / L - (r4 / L) * np.sin(th4)
    res = L * np.hypot(rx, ry)
    return FourBarState(
        r1=r1,
        r2=r2,
        r3=r3,
        r4=r4,
        branch=branch,
        theta2=out(th2),
        theta3=out(th3),
        theta4=out(th4),
        d=out(d),
        theta_d=out(thd),
        assembled=out(assembled),
        dead_point=out(dead),
        status=_status(assembled, dead),
        reason=_reason(assembled, dead, d, r3, r4),
        residual=out(res),
        ground_angle=float(ground_angle),
        omega2=out(np.zeros_like(th2)),
        omega3=out(np.zeros_like(th2)),
        omega4=out(np.zeros_like(th2)),
        alpha2=out(np.zeros_like(th2)),
        alpha3=out(np.zeros_like(th2)),
        alpha4=out(np.zeros_like(th2)),
    )


def _representable(name: str, x, why: str):
    """``x`` (computed with overflow warnings off) or ``ValueError`` when it holds inf/NaN."""
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ValueError(
            f"{name} is beyond the float range ({why}); use smaller rates or other units"
        )
    return x


def _rate_scale(*rates):
    """Elementwise max(|w2|, |w3|, |w4|, sqrt|a2|) (1 where all are 0): rates / scale are <= 1."""
    om = np.maximum.reduce(
        [np.abs(np.asarray(r, dtype=float)) for r in rates[:-1]] + [np.sqrt(np.abs(rates[-1]))]
    )
    return np.where(om > 0, om, 1.0)


def _cosine(r3, r4, d, scale):
    """(r3^2 + d^2 - r4^2) / (2 r3 d), Eq. (5-16); d = 0 handled without dividing by zero."""
    tiny = 1e-14 * scale
    safe = np.where(d > tiny, d, 1.0)
    k = (r3 * r3 + d * d - r4 * r4) / (2.0 * r3 * safe)
    # d = 0: the crank tip sits on the rocker pivot; closes (indeterminately) only if r3 == r4
    return np.where(d > tiny, k, np.where(abs(r3 - r4) <= tiny, 1.0, 2.0))


def fourbar_position(r1, r2, r3, r4, theta2, branch: int = 1) -> FourBarState:
    """Position of the four-bar by complex polar vectors, Eqs. (5-12)-(5-17), corrected.

    d = |r1 - r2 e^{i th2}| (5-13), th_d = atan2(-r2 sin th2, r1 - r2 cos th2) (5-14),
    th3 = th_d + branch * arccos((r3^2 + d^2 - r4^2)/(2 r3 d)) (5-16),
    th4 = atan2(r3 sin th3 - d sin th_d, r3 cos th3 - d cos th_d) (5-17, corrected: the print
    has d sin th2 and an arcsin that loses the quadrant).

    Parameters: lengths > 0 (ground r1 along +x, crank r2, coupler r3, rocker r4); ``theta2``
    scalar or array, rad; ``branch`` +1 / -1.  Returns a :class:`FourBarState` (rates zero)."""
    r1, r2, r3, r4 = _lengths(r1, r2, r3, r4)
    branch = _branch(branch)
    th2 = finite_array("theta2", theta2)
    L = max(r1, r2, r3, r4)  # lengths / L: no square overflows
    n1, n2, n3, n4 = r1 / L, r2 / L, r3 / L, r4 / L
    zd = n1 - n2 * np.exp(1j * th2)  # d e^{i th_d} = r1 - r2 e^{i th2}  (5-12)
    dn = np.abs(zd)  # (5-13), d / L
    thd = np.angle(zd)  # (5-14) with atan2
    k = _cosine(n3, n4, dn, n1 + n2 + n3 + n4)
    th3 = thd + branch * np.arccos(np.clip(k, -1.0, 1.0))  # (5-16), both branches
    th4 = np.arctan2(
        n3 * np.sin(th3) - dn * np.sin(thd), n3 * np.cos(th3) - dn * np.cos(thd)
    )  # (5-17) corr.
    return _finish(r1, r2, r3, r4, branch, th2, th3, th4, dn * L, thd, k, 0.0, r1, 0.0)


def _rates_mask(state):
    return np.asarray(state.assembled) & ~np.asarray(state.dead_point)


def fourbar_velocity(state: FourBarState, omega2) -> FourBarState:
    """Coupler and rocker angular velocities, Eqs. (5-19)/(5-20), corrected.

    th3' = th2' r2 sin(th4 - th2) / (r3 sin(th3 - th4))     (5-19; print: sin(th4 - th3))
    th4' = th2' r2 sin(th3 - th2) / (r4 sin(th3 - th4))     (5-20; print: -r2 sin(th3 + th4))

    rad/s.  Zero where the state is not assembled or at a dead point (see ``state.status``)."""
    w2 = np.broadcast_to(finite_array("omega2", omega2), np.shape(state.theta2)).astype(float)
    th2, th3, th4 = (np.asarray(x, dtype=float) for x in (state.theta2, state.theta3, state.theta4))
    good = _rates_mask(state)
    den = np.where(good, np.sin(th3 - th4), 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        w3 = np.where(good, w2 * ((state.r2 / state.r3) * np.sin(th4 - th2) / den), 0.0)
        w4 = np.where(good, w2 * ((state.r2 / state.r4) * np.sin(th3 - th2) / den), 0.0)
    w3 = _representable("omega3", w3, f"omega2 = {np.max(np.abs(w2)):.3g} rad/s near a dead point")
    w4 = _representable("omega4", w4, f"omega2 = {np.max(np.abs(w2)):.3g} rad/s near a dead point")
    return replace(state, omega2=out(w2), omega3=out(w3), omega4=out(w4))


def fourbar_acceleration(state: FourBarState, alpha2=0.0) -> FourBarState:
    """Coupler and rocker angular accelerations, Eqs. (5-21)/(5-22), corrected and generalised.

    With A = r2 th2'' s2 + r2 th2'^2 c2 + r3 th3'^2 c3 - r4 th4'^2 c4 and
    B = -r2 th2'' c2 + r2 th2'^2 s2 + r3 th3'^2 s3 - r4 th4'^2 s4 (the print has squared
    *accelerations* and assumes th2'' = 0):
    th3'' = -(A c4 + B s4) / (r3 sin(th3 - th4))    (5-21)
    th4'' = -(A c3 + B s3) / (r4 sin(th3 - th4))    (5-22; print: -(A c3 - B s3))

    Call :func:`fourbar_velocity` first (uses ``state.omega*``).  rad/s^2."""
    a2 = np.broadcast_to(finite_array("alpha2", alpha2), np.shape(state.theta2)).astype(float)
    th2, th3, th4 = (np.asarray(x, dtype=float) for x in (state.theta2, state.theta3, state.theta4))
    w2, w3, w4 = (np.asarray(x, dtype=float) for x in (state.omega2, state.omega3, state.omega4))
    L = max(state.r1, state.r2, state.r3, state.r4)
    r2, r3, r4 = state.r2 / L, state.r3 / L, state.r4 / L  # lengths / L and rates / om (<= 1)
    om = _rate_scale(w2, w3, w4, a2)
    w2, w3, w4, a2n = w2 / om, w3 / om, w4 / om, (a2 / om) / om
    # the complex method works in the ground frame (r1 on +x): rotate absolute angles back
    g = state.ground_angle
    t2, t3, t4 = th2 - g, th3 - g, th4 - g
    A = (
        r2 * a2n * np.sin(t2)
        + r2 * w2**2 * np.cos(t2)
        + r3 * w3**2 * np.cos(t3)
        - r4 * w4**2 * np.cos(t4)
    )
    B = (
        -r2 * a2n * np.cos(t2)
        + r2 * w2**2 * np.sin(t2)
        + r3 * w3**2 * np.sin(t3)
        - r4 * w4**2 * np.sin(t4)
    )
    good = _rates_mask(state)
    den = np.where(good, np.sin(th3 - th4), 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        a3 = np.where(good, om * (om * (-(A * np.cos(t4) + B * np.sin(t4)) / (r3 * den))), 0.0)
        a4 = np.where(good, om * (om * (-(A * np.cos(t3) + B * np.sin(t3)) / (r4 * den))), 0.0)
    why = f"rates up to {np.max(om):.3g} rad/s give accelerations of order their square"
    a3, a4 = _representable("alpha3", a3, why), _representable("alpha4", a4, why)
    return replace(state, alpha2=out(a2), alpha3=out(a3), alpha4=out(a4))


def fourbar(r1, r2, r3, r4, theta2, omega2=0.0, alpha2=0.0, branch: int = 1) -> FourBarState:
    """Position, velocity and acceleration in one call (complex method, Eqs. (5-12)-(5-22)
    corrected).

    ``theta2``, ``omega2``, ``alpha2`` broadcast against each other (rad, rad/s, rad/s^2)."""
    th2, w2, a2 = np.broadcast_arrays(
        finite_array("theta2", theta2),
        finite_array("omega2", omega2),
        finite_array("alpha2", alpha2),
    )
    s = fourbar_position(r1, r2, r3, r4, th2, branch)
    s = fourbar_velocity(s, w2)
    return fourbar_acceleration(s, a2)


def fourbar_cartesian(
    ground, r2, r3, r4, theta2, omega2=0.0, alpha2=0.0, branch: int = 1
) -> FourBarState:
    """The same four-bar by Cartesian vectors, book §5-3 (Fig. 5-5), with a general ground vector.

    ``ground`` = r1 = (r1x, r1y), the vector from the crank pivot O2 to the rocker pivot O4.
    Position: d = r1 - r2 (5-60, reconstructed), d.d = d^2, tg th_d = (r1y - r2y)/(r1x - r2x)
    (print: tg th2), cos(alpha) = (r3^2 + d^2 - r4^2)/(2 r3 d), th3 = th_d +/- alpha, r4 = r3 - d.
    Velocity (Cramer, as printed in §5-3):
    th3' = th2' (r2x r4y - r2y r4x)/(r4x r3y - r3x r4y), th4' = th2' (r2x r3y - r3x r2y)/(r4x r3y -
    r3x r4y). Acceleration with a general th2'' (§5-3):
    A = r2y th2'' + r2x th2'^2 + r3x th3'^2 - r4x th4'^2, B = -r2x th2'' + r2y th2'^2 + r3y th3'^2 -
    r4y th4'^2, th3'' = -(A r4x + B r4y)/(r3y r4x - r3x r4y), th4'' = -(A r3x + B r3y)/(r3y r4x -
    r3x r4y).

    Angles absolute from +x; the ``branch`` sign means the same as in :func:`fourbar_position`."""
    g = finite_array("ground", ground, (2,))
    r1 = float(np.hypot(g[0], g[1]))
    if r1 == 0.0:
        raise ValueError(f"ground vector must be non-zero, got {g.tolist()}")
    _, r2, r3, r4 = _lengths(r1, r2, r3, r4)
    branch = _branch(branch)
    th2, w2, a2 = np.broadcast_arrays(
        finite_array("theta2", theta2),
        finite_array("omega2", omega2),
        finite_array("alpha2", alpha2),
    )
    L = max(r1, r2, r3, r4)  # every vector / L: no product overflows
    gn, n2, n3, n4 = g / L, r2 / L, r3 / L, r4 / L
    r2x, r2y = n2 * np.cos(th2), n2 * np.sin(th2)
    dx, dy = gn[0] - r2x, gn[1] - r2y
    dn = np.hypot(dx, dy)
    thd = np.arctan2(dy, dx)
    k = _cosine(n3, n4, dn, n2 + n3 + n4 + r1 / L)
    th3 = thd + branch * np.arccos(np.clip(k, -1.0, 1.0))
    r3x, r3y = n3 * np.cos(th3), n3 * np.sin(th3)
    r4x, r4y = r3x - dx, r3y - dy
    th4 = np.arctan2(r4y, r4x)
    s = _finish(
        r1, r2, r3, r4, branch, th2, th3, th4, dn * L, thd, k, np.arctan2(g[1], g[0]), g[0], g[1]
    )
    # r4 from the closed form has length r4 only when assembled; use the unit direction times r4
    r4x, r4y = n4 * np.cos(th4), n4 * np.sin(th4)
    good = _rates_mask(s)
    den = np.where(good, r4x * r3y - r3x * r4y, 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        w3 = np.where(good, w2 * ((r2x * r4y - r2y * r4x) / den), 0.0)
        w4 = np.where(good, w2 * ((r2x * r3y - r3x * r2y) / den), 0.0)
    why = f"omega2 = {np.max(np.abs(w2)):.3g} rad/s near a dead point"
    w3, w4 = _representable("omega3", w3, why), _representable("omega4", w4, why)
    om = _rate_scale(w2, w3, w4, a2)  # rates / om <= 1: no square overflows
    v2, v3, v4, a2n = w2 / om, w3 / om, w4 / om, (a2 / om) / om
    A = r2y * a2n + r2x * v2**2 + r3x * v3**2 - r4x * v4**2
    B = -r2x * a2n + r2y * v2**2 + r3y * v3**2 - r4y * v4**2
    with np.errstate(over="ignore", invalid="ignore"):
        a3 = np.where(good, om * (om * (-(A * r4x + B * r4y) / den)), 0.0)
        a4 = np.where(good, om * (om * (-(A * r3x + B * r3y) / den)), 0.0)
    why = f"rates up to {np.max(om):.3g} rad/s give accelerations of order their square"
    a3, a4 = _representable("alpha3", a3, why), _representable("alpha4", a4, why)
    return replace(
        s,
        omega2=out(w2),
        omega3=out(w3),
        omega4=out(w4),
        alpha2=out(a2),
        alpha3=out(a3),
        alpha4=out(a4),
    )


def coupler_point(state: FourBarState, p, gamma=0.0) -> CouplerPoint:
    """A point P fixed on the coupler, at distance ``p`` from the crank-coupler joint A and angle
    ``gamma`` (rad, counter-clockwise) from the coupler line A->B.

    P = r2 e^{i th2} + p e^{i(th3 + gamma)}; velocity P' = th2' x r2 + th3' x (P - A) (§5-3,
    "coupler point velocity"); acceleration by (5-11) / (5-59) with r' = 0.  Shape (..., 2),
    ground frame with origin at O2, uses the state's rates (compute them first)."""
    p = finite_scalar("p", p)
    gamma = finite_scalar("gamma", gamma)
    th2, th3 = np.asarray(state.theta2, float), np.asarray(state.theta3, float)
    w2, w3 = np.asarray(state.omega2, float), np.asarray(state.omega3, float)
    a2, a3 = np.asarray(state.alpha2, float), np.asarray(state.alpha3, float)
    e2, e3 = np.exp(1j * th2), np.exp(1j * (th3 + gamma))
    with np.errstate(over="ignore", invalid="ignore"):
        z = state.r2 * e2 + p * e3
        zd = 1j * state.r2 * w2 * e2 + 1j * p * w3 * e3
        zdd = state.r2 * (1j * a2 - w2**2) * e2 + p * (1j * a3 - w3**2) * e3

    def xy(name, c):
        return _representable(name, np.stack([c.real, c.imag], -1), "lengths times rates squared")

    return CouplerPoint(
        xy("coupler point", z),
        xy("coupler point velocity", zd),
        xy("coupler point acceleration", zdd),
    )


def fourbar_points(state: FourBarState) -> dict:
    """Joint positions O2, A, B, O4 (each (..., 2)) in the ground frame, for plotting."""
    th2, th3 = np.asarray(state.theta2, float), np.asarray(state.theta3, float)
    O2 = np.zeros(th2.shape + (2,))
    A = np.stack([state.r2 * np.cos(th2), state.r2 * np.sin(th2)], -1)
    B = A + np.stack([state.r3 * np.cos(th3), state.r3 * np.sin(th3)], -1)
    O4 = O2 + state.r1 * np.array([np.cos(state.ground_angle), np.sin(state.ground_angle)])
    return {"O2": O2, "A": A, "B": B, "O4": O4}


def transmission_angle(state: FourBarState):
    """Angle between coupler and rocker in [0, pi]; see :attr:`FourBarState.transmission_angle`."""
    return state.transmission_angle


def fourbar_input_range(r1, r2, r3, r4) -> FourBarRange:
    """Crank angles for which the linkage assembles (either branch).

    Assembly needs |r3 - r4| <= d <= r3 + r4 with d^2 = r1^2 + r2^2 - 2 r1 r2 cos th2 (5-13), i.e.
    cos th2 in [(r1^2 + r2^2 - (r3 + r4)^2)/(2 r1 r2), (r1^2 + r2^2 - (r3 - r4)^2)/(2 r1 r2)].
    The input is a crank (``full_turn``) when that interval contains [-1, 1]."""
    r1, r2, r3, r4 = _lengths(r1, r2, r3, r4)
    L = max(r1, r2, r3, r4)  # scale-free: lengths / L
    r1, r2, r3, r4 = r1 / L, r2 / L, r3 / L, r4 / L
    cmin = (r1 * r1 + r2 * r2 - (r3 + r4) ** 2) / (2 * r1 * r2)
    cmax = (r1 * r1 + r2 * r2 - (r3 - r4) ** 2) / (2 * r1 * r2)
    if cmin <= -1.0 and cmax >= 1.0:
        return FourBarRange(True, ((-np.pi, np.pi),))
    if cmin > 1.0 or cmax < -1.0:
        return FourBarRange(False, ())
    a = float(np.arccos(min(cmax, 1.0)))  # smallest |th2|
    b = float(np.arccos(max(cmin, -1.0)))  # largest |th2|
    if a == 0.0:
        return FourBarRange(False, ((-b, b),))
    if b == np.pi:
        return FourBarRange(False, ((a, np.pi), (-np.pi, -a)))
    return FourBarRange(False, ((-b, -a), (a, b)))


def fourbar_grashof(r1, r2, r3, r4) -> str:
    """Grashof class: "crank-rocker", "double-crank", "double-rocker", "rocker-crank",
    "change-point" (s + l = p + q) or "triple-rocker" (non-Grashof)."""
    r = _lengths(r1, r2, r3, r4)
    r = tuple(x / max(r) for x in r)  # scale-free (no overflow of the sums)
    s, l_ = min(r), max(r)
    pq = sum(r) - s - l_
    tol = 1e-12 * sum(r)
    if abs(s + l_ - pq) <= tol:
        return "change-point"
    if s + l_ > pq:
        return "triple-rocker"
    i = int(np.argmin(r))
    return {0: "double-crank", 1: "crank-rocker", 2: "double-rocker", 3: "rocker-crank"}[i]
