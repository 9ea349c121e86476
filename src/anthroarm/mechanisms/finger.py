"""The index-finger planar six-bar of book Fig. 2-8, analysed with the §6-5 subroutines
(Fig. 6-14 flowchart, Eqs. (6-66)-(6-87)).

Topology (reconstructed from the Fig. 6-14 flowchart; the figure itself is lost): a Stephenson
six-bar with one input.  Links: the palm (ground, pivots P1 and P4), the proximal phalanx (the
driver, turning by phi1 about P1; carries P2 at R1 and P5 at R2, included angle alpha1), the
middle phalanx (hinged at P2; carries P3 at R3 and the distal joint P6 at R5, included angle
alpha2 from P2->P3 to P2->P6), the bar P4-P3 (R4), the distal phalanx (hinged at P6; carries P7
at R6 and the fingertip P8 at R8, included angle alpha3 from P6->P7 to P6->P8) and the bar
P5-P7 (R7).  The flowchart's steps map to:

1. rigid body (R1, R2) on the proximal phalanx -> P2, P5;
2. dyad (R3, R4) between P2 and P4 -> P3, theta2 (direction P2->P3);
3. rigid body on the middle phalanx (R5 at theta2 + alpha2) -> P6 (the print's "R5, R6");
4. dyad (R6, R7) between P6 and P5 -> P7, theta3 (direction P6->P7);
5. rigid body on the distal phalanx (R8 at theta3 + alpha3) -> fingertip P8 (the print's "R8, R9").

**No bar lengths are printed anywhere in the book.**  :meth:`FingerGeometry.default` holds
lengths **chosen by us** (least-squares fit, :func:`design_finger`) so that the fingertip P8
follows the Chapter 3 grasp curve y = f(x) = 55.61 + 1.133 x - 1.707e-2 x^2 + 0.22e-4 x^3 (mm,
line 1077) for x from 0 to 40 mm, with human-like phalanges (proximal 45, middle 25, distal
22 mm); the fit error is tested.  Units: SI inside (the default geometry is stored in m),
planar frame = the frame of the f(x) curve, angles rad counter-clockwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._util import finite_array, out
from .closed_loop import Closure, LoopSpec, TreeJoint, origin
from .dyads import dyad, rigid_body_point

MM = 1e-3

__all__ = ["FingerGeometry", "FingerState", "finger", "finger_f", "finger_spec", "design_finger"]


def finger_f(x_mm):
    """Chapter 3 fitted fingertip grasp path (握取) y = f(x), mm (line 1077)."""
    x = np.asarray(x_mm, float)
    return 55.61 + 1.133 * x - 1.707e-2 * x**2 + 0.22e-4 * x**3


@dataclass(frozen=True)
class FingerGeometry:
    """Six-bar parameters (m, rad): pivots P1, P4; lengths R1..R8; included angles alpha1..3;
    dyad branches (+1/-1); the driver range [phi_start, phi_end] (rad) the design was made for."""

    P1: np.ndarray
    P4: np.ndarray
    R: tuple  #: (R1, R2, R3, R4, R5, R6, R7, R8)
    alpha: tuple  #: (alpha1, alpha2, alpha3)
    branches: tuple = (1, 1)
    phi_range: tuple = (0.0, 1.0)

    def __post_init__(self):
        object.__setattr__(self, "P1", finite_array("P1", self.P1, (2,)))
        object.__setattr__(self, "P4", finite_array("P4", self.P4, (2,)))
        R = finite_array("R", self.R, (8,))
        if np.any(R <= 0):
            raise ValueError(f"bar lengths R1..R8 must be positive, got {R.tolist()}")
        object.__setattr__(self, "R", tuple(float(x) for x in R))
        object.__setattr__(
            self, "alpha", tuple(float(x) for x in finite_array("alpha", self.alpha, (3,)))
        )
        for b in self.branches:
            if b not in (1, -1):
                raise ValueError(f"branches must be +1/-1, got {self.branches!r}")
        object.__setattr__(
            self,
            "phi_range",
            tuple(float(x) for x in finite_array("phi_range", self.phi_range, (2,))),
        )

    @property
    def length_scale(self) -> float:
        return float(sum(self.R))

    @classmethod
    def from_pose(cls, P1, P2, P3, P4, P5, P6, P7, P8, phi_end, branches=None) -> "FingerGeometry":
        """Geometry from one assembled pose (points (2,), m) — lengths and angles are read off it,
        the pose is phi_start = angle(P2 - P1), and the dyad branches are the ones through it."""
        P = [np.asarray(p, float) for p in (P1, P2, P3, P4, P5, P6, P7, P8)]
        P1, P2, P3, P4, P5, P6, P7, P8 = P

        def ang(v):
            return float(np.arctan2(v[1], v[0]))

        R = (
            np.linalg.norm(P2 - P1),
            np.linalg.norm(P5 - P1),
            np.linalg.norm(P3 - P2),
            np.linalg.norm(P3 - P4),
            np.linalg.norm(P6 - P2),
            np.linalg.norm(P7 - P6),
            np.linalg.norm(P7 - P5),
            np.linalg.norm(P8 - P6),
        )
        alpha = (
            ang(P5 - P1) - ang(P2 - P1),
            ang(P6 - P2) - ang(P3 - P2),
            ang(P8 - P6) - ang(P7 - P6),
        )
        phi0 = ang(P2 - P1)
        if branches is None:
            z = np.zeros(2)
            b1 = min(
                (1, -1),
                key=lambda s: np.linalg.norm(dyad(P2, z, z, P4, z, z, R[2], R[3], s).P3 - P3),
            )
            b2 = min(
                (1, -1),
                key=lambda s: np.linalg.norm(dyad(P6, z, z, P5, z, z, R[5], R[6], s).P3 - P7),
            )
            branches = (b1, b2)
        return cls(
            P1=P1,
            P4=P4,
            R=tuple(float(r) for r in R),
            alpha=alpha,
            branches=tuple(branches),
            phi_range=(phi0, float(phi_end)),
        )

    @classmethod
    def default(cls) -> "FingerGeometry":
        """Our index finger (NOT from the book: no lengths are printed), fitted so that the
        fingertip follows the Chapter 3 curve f(x) for x in [0, 40] mm;
        see :func:`design_finger`."""
        return cls.from_pose(*(np.array(p) * MM for p in _DEFAULT_POSE), phi_end=_DEFAULT_PHI_END)


# the assembled initial pose found by design_finger() (mm): P1 .. P8, and the end of the driver
# range
_DEFAULT_POSE = (
    (69.6723, -4.5266),
    (35.5935, 24.8611),
    (39.5627, 24.3651),
    (59.5686, 5.3915),
    (89.2201, 30.3717),
    (16.6609, 41.1876),
    (15.721, 37.2996),
    (0.0001, 55.5549),
)
_DEFAULT_PHI_END = 2.206381854910214


@dataclass(frozen=True)
class FingerState:
    """Six-bar configuration and rates for driver angle(s) phi1.

    Joint points P2..P8 (..., 2) with velocities/accelerations for P2, P6, P8 (the printed
    outputs of Fig. 6-14); relative joint angles ``q = (mcp, pip, dip)`` (rad) with rates;
    ``status`` "ok" | "dead_point" | "cannot_assemble"."""

    phi1: object
    points: dict
    velocities: dict
    accelerations: dict
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    theta2: object
    theta3: object
    status: object
    reason: str
    residual: object

    @property
    def tip(self) -> np.ndarray:
        return self.points["P8"]


def finger(geom: FingerGeometry, phi1, phi1dot=0.0, phi1ddot=0.0) -> FingerState:
    """Fig. 6-14 pipeline (see the module docstring), vectorised over phi1 (rad)."""
    ph, w, al = np.broadcast_arrays(
        finite_array("phi1", phi1),
        finite_array("phi1dot", phi1dot),
        finite_array("phi1ddot", phi1ddot),
    )
    R1, R2, R3, R4, R5, R6, R7, R8 = geom.R
    a1, a2, a3 = geom.alpha
    z = np.zeros(ph.shape + (2,))
    P1 = np.broadcast_to(geom.P1, z.shape)
    P4 = np.broadcast_to(geom.P4, z.shape)
    p2 = rigid_body_point(P1, z, z, R1, ph, w, al)  # (6-66)
    p5 = rigid_body_point(P1, z, z, R2, ph, w, al, a1)  # (6-67)
    d1 = dyad(
        p2.position, p2.velocity, p2.acceleration, P4, z, z, R3, R4, geom.branches[0]
    )  # (6-70)-(6-87)
    th2, w2, al2 = (np.asarray(x, float) for x in (d1.theta1, d1.omega1, d1.alpha1))
    p6 = rigid_body_point(p2.position, p2.velocity, p2.acceleration, R5, th2, w2, al2, a2)
    d2 = dyad(
        p6.position,
        p6.velocity,
        p6.acceleration,
        p5.position,
        p5.velocity,
        p5.acceleration,
        R6,
        R7,
        geom.branches[1],
    )
    th3, w3, al3 = (np.asarray(x, float) for x in (d2.theta1, d2.omega1, d2.alpha1))
    p8 = rigid_body_point(p6.position, p6.velocity, p6.acceleration, R8, th3, w3, al3, a3)
    mid, dist = th2 + a2, th3 + a3
    q = np.stack([ph, np.angle(np.exp(1j * (mid - ph))), np.angle(np.exp(1j * (dist - mid)))], -1)
    qd = np.stack([w, w2 - w, w3 - w2], -1)
    qdd = np.stack([al, al2 - al, al3 - al2], -1)
    st1, st2 = np.asarray(d1.status), np.asarray(d2.status)
    bad = np.where(st1 != "ok", st1, st2)
    if bad.ndim == 0:
        reason = (
            "ok"
            if bad == "ok"
            else (f"PIP dyad: {d1.reason}" if st1 != "ok" else f"DIP dyad: {d2.reason}")
        )
    else:
        nb = int(np.sum(bad != "ok"))
        reason = (
            "ok"
            if nb == 0
            else f"{nb} of {bad.size} configurations: "
            + ", ".join(sorted(set(bad[bad != "ok"].tolist())))
        )
    res = np.maximum(
        np.abs(np.linalg.norm(d1.P3 - P4, axis=-1) - R4),
        np.abs(np.linalg.norm(d2.P3 - p5.position, axis=-1) - R7),
    )
    pts = {
        "P1": P1,
        "P2": p2.position,
        "P3": d1.P3,
        "P4": P4,
        "P5": p5.position,
        "P6": p6.position,
        "P7": d2.P3,
        "P8": p8.position,
    }
    vel = {
        "P2": p2.velocity,
        "P3": d1.P3dot,
        "P5": p5.velocity,
        "P6": p6.velocity,
        "P7": d2.P3dot,
        "P8": p8.velocity,
    }
    acc = {
        "P2": p2.acceleration,
        "P3": d1.P3ddot,
        "P5": p5.acceleration,
        "P6": p6.acceleration,
        "P7": d2.P3ddot,
        "P8": p8.acceleration,
    }
    return FingerState(
        phi1=out(ph),
        points=pts,
        velocities=vel,
        accelerations=acc,
        q=q,
        qdot=qd,
        qddot=qdd,
        theta2=out(th2),
        theta3=out(th3),
        status=out(bad),
        reason=reason,
        residual=out(res),
    )


def finger_spec(geom: FingerGeometry):
    """Spanning tree + planar closures for :class:`ClosedLoop`, built at the pose phi1 = phi_start
    (q = 0 closes): palm -mcp(P1)- proximal -pip(P2)- middle -dip(P6)- distal; palm -bar1(P4);
    proximal -bar2(P5).  Closures at P3 (middle = bar1) and P7 (distal = bar2), x-y only."""
    s = finger(geom, geom.phi_range[0])
    p = {k: np.r_[np.asarray(v, float), 0.0] for k, v in s.points.items()}
    return LoopSpec(
        name="finger",
        joints=(
            TreeJoint("mcp", "ground", "proximal", origin=origin(p["P1"])),
            TreeJoint("pip", "proximal", "middle", origin=origin(p["P2"] - p["P1"])),
            TreeJoint("dip", "middle", "distal", origin=origin(p["P6"] - p["P2"])),
            TreeJoint("bar1", "ground", "bar1_link", origin=origin(p["P4"])),
            TreeJoint("bar2", "proximal", "bar2_link", origin=origin(p["P5"] - p["P1"])),
        ),
        closures=(
            Closure("P3_middle", "P3_bar1", components=(0, 1)),
            Closure("P7_distal", "P7_bar2", components=(0, 1)),
        ),
        inputs=("mcp",),
        sites=(
            ("P3_middle", "middle", origin(p["P3"] - p["P2"])),
            ("P3_bar1", "bar1_link", origin(p["P3"] - p["P4"])),
            ("P7_distal", "distal", origin(p["P7"] - p["P6"])),
            ("P7_bar2", "bar2_link", origin(p["P7"] - p["P5"])),
            ("P8", "distal", origin(p["P8"] - p["P6"])),
        ),
        length_scale=geom.length_scale,
    )


def _design_build(x):
    """Initial pose (mm) and geometry from the design vector x (see :func:`design_finger`)."""
    mx, my, th0, p3a, p3r, p4x, p4y, p5a, p5r, p7a, p7r, span = x
    e = np.array([np.cos(th0), np.sin(th0)])
    n = np.array([-e[1], e[0]])
    P1 = np.array([mx, my])
    P2 = P1 + 45 * e
    P6 = P2 + 25 * e
    P8 = P6 + 22 * e
    P3 = P2 + p3r * (np.cos(p3a) * e + np.sin(p3a) * n)
    P4 = P1 + p4x * e + p4y * n
    P5 = P1 + p5r * (np.cos(p5a) * e + np.sin(p5a) * n)
    P7 = P6 + p7r * (np.cos(p7a) * e + np.sin(p7a) * n)
    pose = [P1, P2, P3, P4, P5, P6, P7, P8]
    return FingerGeometry.from_pose(*(p * MM for p in pose), phi_end=th0 + span), pose


def _design_residual(x, samples: int = 41):
    """Residuals of the finger fit: y_tip - f(x_tip) (mm), end conditions x_tip = 0 / 40 mm,
    transmission (sin of the dyad angles >= 0.5) and human-like flexion penalties."""
    n_out = samples + 2 + 4 * samples
    try:
        g, _ = _design_build(x)
    except ValueError:
        return np.full(n_out, 1e3)
    ph = np.linspace(g.phi_range[0], g.phi_range[1], samples)
    s = finger(g, ph)
    tip = s.tip / MM
    r = [tip[:, 1] - finger_f(tip[:, 0]), [10 * tip[0, 0], 10 * (tip[-1, 0] - 40.0)]]
    P = s.points
    ok = np.asarray(s.status) == "ok"
    for A, B, C in (("P2", "P3", "P4"), ("P6", "P7", "P5")):
        u = P[A] - P[B]
        v = P[C] - P[B]
        sn = (
            np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
            / np.linalg.norm(u, axis=1)
            / np.linalg.norm(v, axis=1)
        )
        r.append(10 * np.clip(0.5 - sn, 0, None) + 100 * ~ok)
    # human-like: PIP and DIP flex in the MCP's sense, PIP <= 100 deg, DIP <= 80 deg
    sgn = np.sign(g.phi_range[1] - g.phi_range[0])
    for k, lim in ((1, np.deg2rad(100)), (2, np.deg2rad(80))):
        flex = sgn * s.q[:, k]
        r.append(20 * (np.clip(-flex, 0, None) + np.clip(flex - lim, 0, None)))
    out_ = np.concatenate([np.ravel(v) for v in r])
    return out_ if out_.size == n_out else np.full(n_out, 1e3)


def design_finger(x0=None, samples: int = 41, max_nfev: int = 4000):
    """Re-run the least-squares fit behind :meth:`FingerGeometry.default` (takes seconds).

    Design vector x = (MCP x, MCP y [mm], initial finger direction [rad], P3 angle/radius from
    P2, P4 offset from P1 along/normal to the finger, P5 angle/radius from P1, P7 angle/radius
    from P6, driver span [rad]); phalanges fixed at 45 / 25 / 22 mm.  Residuals: see
    ``_design_residual``.  Returns (FingerGeometry, scipy result, initial pose in mm)."""
    from scipy.optimize import least_squares

    x0 = np.array(_DESIGN_X0 if x0 is None else x0, float)
    lo, hi = np.array(_DESIGN_BOUNDS[0], float), np.array(_DESIGN_BOUNDS[1], float)
    res = least_squares(
        _design_residual,
        np.clip(x0, lo, hi),
        args=(samples,),
        x_scale="jac",
        max_nfev=max_nfev,
        bounds=(lo, hi),
    )
    g, pose = _design_build(res.x)
    return g, res, pose


# start of the fit: the best of a random multi-start (bounded: lever arms 4-20 mm, bar pivots within
# 30 mm of the MCP, driver span up to 92 deg)
_DESIGN_X0 = [
    70.104,
    -4.049,
    2.437,
    -2.62,
    6.357,
    23.273,
    -1.796,
    -1.354,
    29.689,
    1.908,
    4.597,
    -0.198,
]
_DESIGN_BOUNDS = (
    [-150, -150, -np.pi, -np.pi, 4, -30, -30, -np.pi, 5, -np.pi, 4, -1.6],
    [150, 150, np.pi, np.pi, 20, 30, 30, np.pi, 40, np.pi, 15, 1.6],
)
