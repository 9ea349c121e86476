"""The anthropomorphic thumb of book Fig. 2-9: a lower spatial RRSS four-bar plus an upper planar
four-bar, analysed as in §6-5 (Fig. 6-17, Eqs. (6-93)-(6-116)) with the Chapter 4 geometry.

Pipeline (Fig. 6-17): the RRSS subroutine (:func:`~anthroarm.mechanisms.rrss.rrss`) gives the
driver R1's hinge a, the MP axis u_a and theta2 (R2 relative to R1) with rates; the planar
four-bar relative to R1 (Fig. 6-16) is solved with the rigid-body and dyad subroutines
(:mod:`~anthroarm.mechanisms.dyads`): R2 (crank A-P) -> dyad (R4 = P-F on R3, R5 = F-C on the
rocker) -> rigid body (R3 = P-S at the fixed angle beta from P-F) -> fingertip S_r; the
coordinate transformation (6-114)/(6-115) and the absolute motion (6-116) give S, S', S''.

Geometry (:meth:`ThumbGeometry.book`), Chapter 4 §4-5 (lines 2037-2133), converted mm -> m:

* RRSS: a0 = 0, a1 = (0, 30, 0) mm, u1 = (sqrt3/2, sqrt3/4, -1/4) (Ch. 4's u2, the MP hinge),
  optimum b0 = (-2.229, -4.316, -48.326) mm, b1 = (15.913, 15.462, -40.15) mm.  The printed
  u0 = (0, 0, 1); theta1 is taken as a rotation about **-z** (``u0 = (0, 0, -1)``) because only
  in that sense does the mechanism follow the Chapter 3 curve theta2 = f2(theta1) (within
  0.6 deg for theta1 in [0, 30 deg], tested) — with +z it cannot even assemble at 10 deg.
* Upper planar four-bar (R2 = A-P = 45 mm, optimum X = (angle PAC, x_f, y_f, x_c, alpha,
  beta) = (157.098 deg, -42.132, 17.918, 14.758 mm, 159.913 deg, 49.365 deg), R3 = 35 mm), read
  literally: planar frame with origin A, x along A->C, P = 45 (cos PAC, sin PAC), F = (x_f, y_f),
  C = (x_c, 0); so R4 = |PF| = 0.791 mm and R5 = |FC| = 59.645 mm.  Fig. 2-9 is lost, so the
  embedding is our choice: the planar plane is normal to u_a through a, its y axis is u_a x x,
  and its x axis (A->C) is the projection of a1 -> a0 (along R1, toward the palm) turned by
  alpha - PAC about u_a, so that R2's initial angle from R1 is the printed alpha.  S is at
  angle +beta (counter-clockwise) from P->F.  Under this literal reading the transmission angle
  PFC is 13.4 deg (the printed constraint asks > 35 deg) and theta3(theta2) does *not* follow
  f3: the printed row cannot be the optimum of the printed problem as we read it (see
  ch3-4.md E9).  The kinematics below are exact for whatever geometry is given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._util import W, Wdot, finite_array, finite_scalar, out, point3, positive_length, rot
from .closed_loop import Closure, LoopSpec, TreeJoint, origin
from .dyads import dyad, rigid_body_point
from .pin_models import frame_with_z
from .rrss import RRSSGeometry, RRSSState, rrss, rrss_branch_through

MM = 1e-3

__all__ = ["ThumbGeometry", "ThumbState", "thumb", "thumb_f2", "thumb_f3"]


def thumb_f2(theta1_deg):
    """Chapter 3 measured thumb coupling theta2 = f2(theta1), degrees (line 1089)."""
    x = np.asarray(theta1_deg, float)
    return -37.030e-3 + 366.517e-3 * x - 8.373e-3 * x**2 + 0.1297e-3 * x**3


def thumb_f3(theta2_deg):
    """Chapter 3 measured thumb coupling theta3 = f3(theta2), degrees (line 1089)."""
    x = np.asarray(theta2_deg, float)
    return 27.533e-2 + 92.657e-2 * x + 10.027e-2 * x**2 - 0.232e-2 * x**3


@dataclass(frozen=True)
class ThumbGeometry:
    """RRSS part (:class:`RRSSGeometry`) + planar four-bar in R1's plane normal to u1 through a1.

    Planar points (m) in the frame (origin a1, x = ``ex``, y = u1 x ex): ``P0`` (IP joint, end
    of R2), ``F0`` (coupler-rocker joint, on R3), ``C`` (rocker pivot on R1); ``R3`` = |PS|,
    ``beta`` = angle from P->F to P->S (rad, counter-clockwise about u1)."""

    rrss: RRSSGeometry
    ex: np.ndarray
    P0: np.ndarray
    F0: np.ndarray
    C: np.ndarray
    R3: float
    beta: float

    def __post_init__(self):
        ex = point3("ex", self.ex)
        u1 = self.rrss.u1
        if abs(ex @ u1) > 1e-9 or abs(np.linalg.norm(ex) - 1) > 1e-9:
            raise ValueError(f"ex must be a unit vector normal to u1, got {ex.tolist()}")
        object.__setattr__(self, "ex", ex)
        for n in ("P0", "F0", "C"):
            object.__setattr__(self, n, finite_array(n, getattr(self, n), (2,)))
        object.__setattr__(self, "R3", positive_length("R3", self.R3))
        object.__setattr__(self, "beta", finite_scalar("beta", self.beta))
        for n, v in (
            ("R2 = |P0|", self.R2),
            ("R4 = |F0 - P0|", self.R4),
            ("R5 = |F0 - C|", self.R5),
        ):
            if v == 0.0:
                raise ValueError(f"{n} is zero")

    @property
    def ey(self) -> np.ndarray:
        return np.cross(self.rrss.u1, self.ex)

    @property
    def R2(self) -> float:
        return float(np.linalg.norm(self.P0))

    @property
    def R4(self) -> float:
        return float(np.linalg.norm(self.F0 - self.P0))

    @property
    def R5(self) -> float:
        return float(np.linalg.norm(self.F0 - self.C))

    @property
    def length_scale(self) -> float:
        return self.rrss.length_scale + self.R2 + self.R3

    def to_world(self, xy) -> np.ndarray:
        """Initial (theta1 = 0) world position of planar point(s) xy (..., 2)."""
        xy = np.asarray(xy, float)
        return self.rrss.a1 + xy[..., :1] * self.ex + xy[..., 1:2] * self.ey

    @property
    def S0(self) -> np.ndarray:
        """Initial fingertip, planar."""
        ang = np.arctan2(*(self.F0 - self.P0)[::-1]) + self.beta
        return self.P0 + self.R3 * np.array([np.cos(ang), np.sin(ang)])

    @property
    def transmission_angle0(self) -> float:
        """Initial angle PFC (rad), Ch. 4 constraint g11 asks > 35 deg."""
        u, v = self.P0 - self.F0, self.C - self.F0
        return float(np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1)))

    @classmethod
    def book(cls) -> "ThumbGeometry":
        """The Chapter 4 §4-5 thumb (see the module docstring for every reading we had to make)."""
        u1 = np.array([np.sqrt(3) / 2, np.sqrt(3) / 4, -0.25])
        g = RRSSGeometry(
            a0=[0, 0, 0],
            u0=[0, 0, -1],
            a1=np.array([0, 30.0, 0]) * MM,
            u1=u1,
            b0=np.array([-2.229, -4.316, -48.326]) * MM,
            b1=np.array([15.913, 15.462, -40.15]) * MM,
        )
        pac, xf, yf, xc, alpha, beta = (
            np.deg2rad(157.098),
            -42.132 * MM,
            17.918 * MM,
            14.758 * MM,
            np.deg2rad(159.913),
            np.deg2rad(49.365),
        )
        back = g.a0 - g.a1
        back = back - u1 * (u1 @ back)
        back /= np.linalg.norm(back)
        ex = rot(alpha - pac, u1) @ back  # A->C: R1's line turned by alpha - PAC about u1
        return cls(
            rrss=g,
            ex=ex,
            P0=45 * MM * np.array([np.cos(pac), np.sin(pac)]),
            F0=np.array([xf, yf]),
            C=np.array([xc, 0.0]),
            R3=35 * MM,
            beta=beta,
        )


@dataclass(frozen=True)
class ThumbState:
    """Thumb configuration and rates.  theta2 (R2 rel. R1 about u_a), theta3 (R3 rel. R2), rad;
    points in the world frame (m): ``a`` (MP hinge), ``P`` (IP joint), ``S`` (fingertip) with
    velocities and accelerations; ``S_r`` the fingertip in R1's planar frame."""

    theta1: object
    theta2: object
    theta3: object
    theta1dot: object
    theta2dot: object
    theta3dot: object
    theta1ddot: object
    theta2ddot: object
    theta3ddot: object
    a: np.ndarray
    P: np.ndarray
    Pdot: np.ndarray
    Pddot: np.ndarray
    S: np.ndarray
    Sdot: np.ndarray
    Sddot: np.ndarray
    S_r: np.ndarray
    F: np.ndarray
    rrss: RRSSState
    status: object
    reason: str
    residual: object  #: largest closure error of the two loops (m)


def _dyad_branch(geom: ThumbGeometry) -> int:
    z = np.zeros(2)
    d = [
        np.linalg.norm(dyad(geom.P0, z, z, geom.C, z, z, geom.R4, geom.R5, s).P3 - geom.F0)
        for s in (1, -1)
    ]
    return 1 if d[0] <= d[1] else -1


def thumb(
    geom: ThumbGeometry,
    theta1,
    theta1dot=0.0,
    theta1ddot=0.0,
    rrss_branch: int | None = None,
    dyad_branch: int | None = None,
) -> ThumbState:
    """Thumb kinematics for driver angle(s) theta1 (rad, scalar or array) and rates, Fig. 6-17
    pipeline.

    Branches default to the ones through the initial pose (theta1 = 0: theta2 = theta3 = 0).
    (6-114) S = T S_r + a, S'_r = T S'_r(planar), S''_r = T S''_r(planar) with
    T = R(theta1, u0) [ex ey u1] ((6-115); the book's x'y'z' frame differs by a constant in-plane
    rotation); (6-116) S' = T S_r' + W(theta1', u0)(S - a0),
    S'' = T S_r'' + Wdot(theta1', theta1'', u0)(S - a0) + 2 W(theta1', u0) T S_r'."""
    th1, w1, al1 = np.broadcast_arrays(
        finite_array("theta1", theta1),
        finite_array("theta1dot", theta1dot),
        finite_array("theta1ddot", theta1ddot),
    )
    g = geom.rrss
    rb = rrss_branch_through(g) if rrss_branch is None else rrss_branch
    db = _dyad_branch(geom) if dyad_branch is None else dyad_branch
    r = rrss(g, th1, w1, al1, rb)
    z = np.zeros(th1.shape + (2,))
    C = np.broadcast_to(geom.C, z.shape)
    th2, w2, al2 = (np.asarray(x, float) for x in (r.theta2, r.theta2dot, r.theta2ddot))
    # planar four-bar relative to R1 (Fig. 6-16): crank R2 about A (origin), a' = c' = 0
    ang0 = float(np.arctan2(geom.P0[1], geom.P0[0]))
    P = rigid_body_point(z, z, z, geom.R2, ang0 + th2, w2, al2)  # (6-66)-(6-69)
    dy = dyad(
        P.position, P.velocity, P.acceleration, C, z, z, geom.R4, geom.R5, db
    )  # (6-70)-(6-87)
    phi0 = float(np.arctan2(*(geom.F0 - geom.P0)[::-1]))
    t31, w31, a31 = (np.asarray(x, float) for x in (dy.theta1, dy.omega1, dy.alpha1))
    S = rigid_body_point(P.position, P.velocity, P.acceleration, geom.R3, t31, w31, a31, geom.beta)
    th3 = np.angle(np.exp(1j * (t31 - phi0 - th2)))
    w3, al3 = w31 - w2, a31 - al2
    # coordinate transformation (6-114)/(6-115) and absolute motion (6-116)
    R1 = rot(th1, g.u0)
    T = R1 @ np.column_stack([geom.ex, geom.ey, g.u1])
    a = np.asarray(r.a)
    Wm, Wd = W(w1, g.u0), Wdot(w1, al1, g.u0)

    def lift(v):
        return np.einsum(
            "...ij,...j->...i", T, np.concatenate([v, np.zeros(v.shape[:-1] + (1,))], -1)
        )

    def mv(M, v):
        return np.einsum("...ij,...j->...i", M, v)

    S_w = lift(S.position) + a
    Sd_r = lift(S.velocity)
    Sdot = Sd_r + mv(Wm, S_w - g.a0)
    Sddot = lift(S.acceleration) + mv(Wd, S_w - g.a0) + 2 * mv(Wm, Sd_r)
    Pw = lift(P.position) + a
    Pd_r = lift(P.velocity)
    Pdot = Pd_r + mv(Wm, Pw - g.a0)
    Pddot = lift(P.acceleration) + mv(Wd, Pw - g.a0) + 2 * mv(Wm, Pd_r)
    F_w = lift(dy.P3) + a
    rs, ds = np.asarray(r.status), np.asarray(dy.status)
    status = np.where(
        rs == "cannot_assemble",
        rs,
        np.where(ds == "cannot_assemble", ds, np.where(rs != "ok", rs, ds)),
    )
    if status.ndim == 0:
        st = str(status)
        reason = (
            "ok"
            if st == "ok"
            else (f"RRSS: {r.reason}" if str(rs) == st else f"upper four-bar: {dy.reason}")
        )
    else:
        nb = int(np.sum(status != "ok"))
        reason = "ok" if nb == 0 else f"RRSS: {r.reason}; upper four-bar: {dy.reason}"
    res = np.maximum(np.asarray(r.residual), np.abs(np.linalg.norm(dy.P3 - C, axis=-1) - geom.R5))
    return ThumbState(
        theta1=out(th1),
        theta2=out(th2),
        theta3=out(th3),
        theta1dot=out(w1),
        theta2dot=out(w2),
        theta3dot=out(w3),
        theta1ddot=out(al1),
        theta2ddot=out(al2),
        theta3ddot=out(al3),
        a=a,
        P=Pw,
        Pdot=Pdot,
        Pddot=Pddot,
        S=S_w,
        Sdot=Sdot,
        Sddot=Sddot,
        S_r=S.position,
        F=F_w,
        rrss=r,
        status=out(status),
        reason=reason,
        residual=out(res),
    )


def thumb_spec(geom: ThumbGeometry):
    """Spanning tree + closures of the whole thumb for :class:`ClosedLoop`.

    ground -R(u0 at a0)- R1 -R(u1 at a1)- R2 -R(u1 at P)- R3 (sites F_R3, S);
    R1 -R(u1 at C)- rocker (site F_rocker); ground -ball(b0)- S-S bar (site b_bar); R2 site b_R2.
    Closures: b_R2 = b_bar and F_R3 = F_rocker (3-D points; the planar loop's out-of-plane rows
    are redundant and handled by the least-norm solver)."""
    g = geom.rrss
    R0, Ru = frame_with_z(g.u0), frame_with_z(g.u1)
    Rbar = frame_with_z(g.b1 - g.b0)
    Pw, Fw, Cw, Sw = (geom.to_world(x) for x in (geom.P0, geom.F0, geom.C, geom.S0))
    return LoopSpec(
        name="thumb",
        joints=(
            TreeJoint("r1", "ground", "R1", origin=origin(g.a0, R0)),
            TreeJoint("r2", "R1", "R2", origin=origin(R0.T @ (g.a1 - g.a0), R0.T @ Ru)),
            TreeJoint("r3", "R2", "R3", origin=origin(Ru.T @ (Pw - g.a1))),
            TreeJoint("rocker", "R1", "rocker_link", origin=origin(R0.T @ (Cw - g.a0), R0.T @ Ru)),
            TreeJoint("ball_b0", "ground", "bar", "ball", origin=origin(g.b0, Rbar)),
        ),
        closures=(Closure("b_R2", "b_bar"), Closure("F_R3", "F_rocker")),
        inputs=("r1",),
        sites=(
            ("b_R2", "R2", origin(Ru.T @ (g.b1 - g.a1))),
            ("b_bar", "bar", origin(Rbar.T @ (g.b1 - g.b0))),
            ("F_R3", "R3", origin(Ru.T @ (Fw - Pw))),
            ("F_rocker", "rocker_link", origin(Ru.T @ (Fw - Cw))),
            ("S", "R3", origin(Ru.T @ (Sw - Pw))),
        ),
        length_scale=geom.length_scale,
    )


__all__.append("thumb_spec")
