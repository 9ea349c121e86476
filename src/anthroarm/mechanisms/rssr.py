"""Spatial RSSR four-bar in closed form: 002 text §4-2, Eqs. (4-18)-(4-31), and the complex +
j-vector form of book §5-2 (Fig. 5-3).

Mechanism (002 §4-2): link 1 is the frame; link 2 is the input crank, a revolute about the unit
axis ``ua`` through ``a0`` (input angle alpha); the S-S coupler joins the sphere centres ``a``
(on the crank) and ``b`` (on the output); link 4 is the output, a revolute about ``ub`` through
``b0`` (output angle beta).  ``a1``, ``b1`` are the sphere centres at alpha = beta = 0.  World
frame, SI units, angles in rad, positive right-handed about the axes.

Position (4-18)-(4-22): E cos(beta) + F sin(beta) + G = 0 with
E = (a - b0)^T [I - Q_ub](b1 - b0), F = (a - b0)^T [P_ub](b1 - b0),
G = (a - b0)^T [Q_ub](b1 - b0) + 1/2[|a1 - b1|^2 - |a - b0|^2 - |b1 - b0|^2];
beta = 2 atan2(-F +/- sqrt(E^2 + F^2 - G^2), G - E) — ``branch=+1`` is the "+" root (beta').
Velocity (4-26), acceleration (4-30, reconstructed: the printed stray term belongs inside the
bracket with [P_ub-dot], zero for a fixed axis).  Assembly (4-31): E^2 + F^2 - G^2 >= 0; the input
is a crank when this holds over a full turn (:func:`rssr_crank_test`).

No NaN: outside the assembly range a state has ``assembled=False`` and beta is the nearest
configuration (the discriminant clipped to 0); at a branch point (discriminant 0, the coupler in
the plane of the output's motion) ``dead_point=True`` and the rates are reported as 0.

Numbers at the float range: the radii of the geometry are computed without overflow (vectors
divided by a power of two first); a state whose numbers cannot be represented (E^2 + F^2 - G^2
grows as the fourth power of the lengths, the accelerations as the square of the rates) is a
``ValueError`` naming the quantity, never inf or NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._util import (
    assembly_status,
    finite_array,
    norm,
    out,
    point3,
    positive_length,
    pow2_scale,
    representable_fields,
    rot,
    skew,
    unit_axis,
)

DEAD_POINT_TOL = 1e-7

__all__ = [
    "RSSRGeometry",
    "RSSRState",
    "RSSRCrankTest",
    "rssr_position",
    "rssr",
    "rssr_crank_test",
    "rssr_branch_through",
    "rssr_efg",
    "rssr_polar",
]


def _diff(p, q):
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return p - q


def _pow2(d):
    return pow2_scale(norm("a difference of the points", d))


@dataclass(frozen=True)
class RSSRGeometry:
    """Crank axis ``ua`` through ``a0``, sphere centre ``a1``; output axis ``ub`` through ``b0``,
    sphere centre ``b1`` (all world frame, m; axes unit vectors)."""

    a0: np.ndarray
    ua: np.ndarray
    a1: np.ndarray
    b0: np.ndarray
    ub: np.ndarray
    b1: np.ndarray

    def __post_init__(self):
        for n in ("a0", "a1", "b0", "b1"):
            object.__setattr__(self, n, point3(n, getattr(self, n)))
        object.__setattr__(self, "ua", unit_axis("ua", self.ua))
        object.__setattr__(self, "ub", unit_axis("ub", self.ub))
        if self.coupler_length == 0.0:
            raise ValueError(f"a1 and b1 coincide ({self.a1.tolist()}): zero-length coupler")
        if self.crank_radius == 0.0:
            raise ValueError(f"a1 = {self.a1.tolist()} lies on the crank axis: zero crank radius")
        if self.rocker_radius == 0.0:
            raise ValueError(f"b1 = {self.b1.tolist()} lies on the output axis: zero rocker radius")

    @property
    def coupler_length(self) -> float:
        return float(norm("a1 - b1", _diff(self.a1, self.b1)))

    @property
    def crank_radius(self) -> float:
        d = _diff(self.a1, self.a0)
        s = _pow2(d)  # d / 2^k: no overflow of the projection
        return float(s * norm("crank radius", d / s - self.ua * (self.ua @ (d / s))))

    @property
    def rocker_radius(self) -> float:
        d = _diff(self.b1, self.b0)
        s = _pow2(d)
        return float(s * norm("rocker radius", d / s - self.ub * (self.ub @ (d / s))))

    @property
    def length_scale(self) -> float:
        return self.coupler_length + self.crank_radius + self.rocker_radius


@dataclass(frozen=True)
class RSSRState:
    """Output of the RSSR for input angle(s) alpha: beta and rates, sphere centres a, b with
    velocities/accelerations (..., 3), E, F, G, the discriminant E^2 + F^2 - G^2, status."""

    alpha: object
    beta: object
    alphadot: object
    betadot: object
    alphaddot: object
    betaddot: object
    a: np.ndarray
    b: np.ndarray
    adot: np.ndarray
    bdot: np.ndarray
    addot: np.ndarray
    bddot: np.ndarray
    E: object
    F: object
    G: object
    discriminant: object
    branch: int
    assembled: object
    dead_point: object
    status: object
    reason: str
    residual: object  #: | |a - b| - |a1 - b1| |, m

    @property
    def ok(self):
        return out(np.logical_and(self.assembled, np.logical_not(self.dead_point)))


@dataclass(frozen=True)
class RSSRCrankTest:
    """(4-31) over a full turn: ``is_crank`` iff min E^2 + F^2 - G^2 >= 0; ``intervals`` of alpha
    (rad) where the linkage assembles; ``kind`` "crank" | "rocker" | "cannot_assemble"."""

    is_crank: bool
    kind: str
    min_discriminant: float
    alpha_at_min: float
    intervals: tuple


def _check_branch(branch):
    if branch not in (1, -1):
        raise ValueError(f"branch must be +1 or -1, got {branch!r}")
    return int(branch)


def rssr_efg(geom: RSSRGeometry, alpha):
    """E, F, G of (4-21) and the crank sphere centre a(alpha) (4-19), vectorised over alpha."""
    al = finite_array("alpha", alpha)
    Ra = rot(al, geom.ua)
    a = np.einsum("...ij,j->...i", Ra, geom.a1 - geom.a0) + geom.a0  # (4-19)
    c = a - geom.b0
    d = geom.b1 - geom.b0
    P = skew(geom.ub)
    Q = np.outer(geom.ub, geom.ub)
    E = c @ ((np.eye(3) - Q) @ d)
    F = c @ (P @ d)
    L2 = np.float64(geom.coupler_length) ** 2  # numpy: inf on overflow, not OverflowError
    G = c @ (Q @ d) + 0.5 * (L2 - np.einsum("...i,...i", c, c) - d @ d)
    return E, F, G, a


def _beta(E, F, G, s, root):
    """beta = 2 atan2(-F + s root, G - E) (4-22); uses the equivalent (G + E)/(-F - s root) form
    where the first one degenerates (0/0), so beta = +/-pi is found too."""
    n1, d1 = -F + s * root, G - E
    n2, d2 = G + E, -F - s * root
    use1 = np.hypot(n1, d1) >= np.hypot(n2, d2)
    half = np.where(use1, np.arctan2(n1, d1), np.arctan2(n2, d2))
    b = 2 * half
    return np.mod(b + np.pi, 2 * np.pi) - np.pi


def rssr_position(geom: RSSRGeometry, alpha, branch: int = 1) -> RSSRState:
    """Output angle beta for input alpha (scalar or array), Eqs. (4-19)-(4-22); rates zero."""
    return rssr(geom, alpha, 0.0, 0.0, branch)


def rssr(geom: RSSRGeometry, alpha, alphadot=0.0, alphaddot=0.0, branch: int = 1) -> RSSRState:
    """Position, velocity (4-23)-(4-26) and acceleration (4-27)-(4-30) of the RSSR.

    beta' = a'^T (a - b) / ((a - b)^T [P_ub](b - b0))                        (4-26)
    beta'' = [(a - b)^T (a'' - beta'^2 [P_ub]^2 (b - b0)) + |a' - b'|^2] / ((a - b)^T [P_ub](b -
    b0))   (4-30) with a' = alpha' [P_ua](a - a0) (4-24), a'' = [E_{alpha',alpha'',ua}](a - a0)
    (4-28)."""
    s = _check_branch(branch)
    al, ad, add = np.broadcast_arrays(
        finite_array("alpha", alpha),
        finite_array("alphadot", alphadot),
        finite_array("alphaddot", alphaddot),
    )
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        E, F, G, a = rssr_efg(geom, al)
        disc = E * E + F * F - G * G
        scale2 = (
            np.float64(
                geom.rocker_radius * (geom.coupler_length + geom.crank_radius + geom.rocker_radius)
            )
            ** 2
        )
        assembled = disc >= -1e-12 * scale2
        root = np.sqrt(np.clip(disc, 0.0, None))
        beta = _beta(E, F, G, s, root)
        Rb = rot(beta, geom.ub)
        b = np.einsum("...ij,j->...i", Rb, geom.b1 - geom.b0) + geom.b0  # (4-20)
        Pa, Pb = skew(geom.ua), skew(geom.ub)
        ra, rb = a - geom.a0, b - geom.b0
        ab = a - b
        adot = ad[..., None] * (ra @ Pa.T)  # (4-24)
        addot = add[..., None] * (ra @ Pa.T) + (ad**2)[..., None] * (ra @ (Pa @ Pa).T)  # (4-28)
        den = np.einsum("...i,...i", ab, rb @ Pb.T)
        dead = assembled & (np.abs(den) < DEAD_POINT_TOL * geom.coupler_length * geom.rocker_radius)
        good = assembled & ~dead
        dens = np.where(good, den, 1.0)
        bd = np.where(good, np.einsum("...i,...i", adot, ab) / dens, 0.0)  # (4-26)
        bdot = bd[..., None] * (rb @ Pb.T)  # (4-25)
        rel = adot - bdot
        num = np.einsum(
            "...i,...i", ab, addot - (bd**2)[..., None] * (rb @ (Pb @ Pb).T)
        ) + np.einsum("...i,...i", rel, rel)
        bdd = np.where(good, num / dens, 0.0)  # (4-30)
        bddot = bdd[..., None] * (rb @ Pb.T) + (bd**2)[..., None] * (rb @ (Pb @ Pb).T)  # (4-29)
        res = np.abs(np.linalg.norm(ab, axis=-1) - geom.coupler_length)
        st, reason = assembly_status(
            assembled,
            dead,
            al,
            disc,
            "alpha",
            "branch point: E^2 + F^2 - G^2 = 0, the two closures meet; rates unbounded, reported "
            "as 0",
            " (4-31)",
        )
        if not np.all(good):  # keep the rates of bad entries exactly zero
            z = ~good[..., None]
            bdot, bddot = np.where(z, 0.0, bdot), np.where(z, 0.0, bddot)
    st_ = RSSRState(
        alpha=out(al),
        beta=out(beta),
        alphadot=out(ad),
        betadot=out(bd),
        alphaddot=out(add),
        betaddot=out(bdd),
        a=a,
        b=b,
        adot=adot,
        bdot=bdot,
        addot=addot,
        bddot=bddot,
        E=out(E),
        F=out(F),
        G=out(G),
        discriminant=out(disc),
        branch=s,
        assembled=out(assembled),
        dead_point=out(dead),
        status=out(st),
        reason=reason,
        residual=out(res),
    )
    return representable_fields(
        st_,
        f"length scale {geom.length_scale:.3g} m, alphadot up to "
        f"{np.max(np.abs(ad)):.3g} rad/s, alphaddot up to {np.max(np.abs(add)):.3g} rad/s^2",
    )


def rssr_branch_through(geom: RSSRGeometry, alpha0: float = 0.0, beta0: float = 0.0) -> int:
    """The branch sign (+1 / -1) whose closure passes through (alpha0, beta0) — by default the
    reference configuration a1, b1 ("choose by continuity", 002 §4-2)."""
    st = [rssr_position(geom, alpha0, s) for s in (1, -1)]
    err = [abs(np.angle(np.exp(1j * (x.beta - beta0)))) for x in st]
    return 1 if err[0] <= err[1] else -1


def rssr_crank_test(geom: RSSRGeometry, samples: int = 3600) -> RSSRCrankTest:
    """Assembly condition (4-31) over a full turn of the input.

    E, F, G are affine in (cos alpha, sin alpha), so the discriminant is a trigonometric
    polynomial of degree 2; it is sampled densely and its minimum refined with a bounded scalar
    search.  Intervals where the linkage assembles are returned (rad, in [-pi, pi])."""
    from scipy.optimize import minimize_scalar

    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 8:
        raise ValueError(
            f"samples must be an integer >= 8 (points over the turn of the input), got {samples!r}"
        )
    al = np.linspace(-np.pi, np.pi, int(samples), endpoint=False)
    E, F, G, _ = rssr_efg(geom, al)
    disc = E * E + F * F - G * G
    i = int(np.argmin(disc))
    h = 2 * np.pi / samples

    def f(x):
        e, fq, g, _ = rssr_efg(geom, x)
        return float(e * e + fq * fq - g * g)

    r = minimize_scalar(
        f, bounds=(al[i] - h, al[i] + h), method="bounded", options={"xatol": 1e-12}
    )
    mn, amin = (float(r.fun), float(r.x)) if r.fun < disc[i] else (float(disc[i]), float(al[i]))
    ok = disc >= 0
    intervals = []
    if ok.all():
        intervals = [(-np.pi, np.pi)]
    elif ok.any():
        k = 0
        n = len(al)
        while k < n:
            if ok[k]:
                j = k
                while j + 1 < n and ok[j + 1]:
                    j += 1
                intervals.append((float(al[k]), float(al[j])))
                k = j + 1
            else:
                k += 1
        if len(intervals) > 1 and ok[0] and ok[-1]:  # wraps around +/-pi
            first, last = intervals[0], intervals[-1]
            intervals = [(last[0], first[1] + 2 * np.pi)] + intervals[1:-1]
    kind = "crank" if mn >= 0 else ("rocker" if ok.any() else "cannot_assemble")
    return RSSRCrankTest(
        is_crank=mn >= 0,
        kind=kind,
        min_discriminant=mn,
        alpha_at_min=amin,
        intervals=tuple(intervals),
    )


def rssr_polar(r2, r3, r4, C, theta2, phi2, branch: int = 1):
    """The book's §5-2 RSSR (Fig. 5-3) by complex + j vectors: output angle phi4 (rad).

    The crank (radius r2, R joint at the origin) turns in the vertical plane of azimuth theta2
    (phi2 = polar angle of the crank from +z, Eq. (5-23)); the rocker (radius r4) turns about an
    axis parallel to y through C = (a, b, c), in the plane y = b (theta4 = 0); coupler r3.
    A sin(phi4) + B cos(phi4) = D with A = a - r2 s(phi2) c(theta2), B = c - r2 c(phi2),
    D = [r3^2 - r4^2 - (b - r2 s(theta2) s(phi2))^2 - A^2 - B^2] / (2 r4),
    phi4 = 2 atan((A +/- sqrt(A^2 + B^2 - D^2)) / (B + D)).
    Returns (phi4, assembled).  The same mechanism as :func:`rssr` with ua = (-sin theta2, cos
    theta2, 0), a0 = 0, a = r2 (s phi2 c theta2, s phi2 s theta2, c phi2), ub = (0, 1, 0), b0 = C,
    b = C + r4 (sin phi4, 0, cos phi4), and the reference sphere centres a1, b1 taken at any closed
    configuration (|a1 - b1| = r3); the tests check both ways."""
    r2, r3, r4 = positive_length("r2", r2), positive_length("r3", r3), positive_length("r4", r4)
    a, bb, c = point3("C", C)
    s = _check_branch(branch)
    th2 = finite_array("theta2", theta2)
    p2 = finite_array("phi2", phi2)
    A = a - r2 * np.sin(p2) * np.cos(th2)
    B = c - r2 * np.cos(p2)
    D = (r3**2 - r4**2 - (bb - r2 * np.sin(th2) * np.sin(p2)) ** 2 - A**2 - B**2) / (2 * r4)
    disc = A * A + B * B - D * D
    root = np.sqrt(np.clip(disc, 0.0, None))
    # same root as 2 atan((A + s root)/(B + D)), written with atan2 and the degenerate-safe twin
    n1, d1 = A + s * root, B + D
    n2, d2 = D - B, A - s * root
    half = np.where(np.hypot(n1, d1) >= np.hypot(n2, d2), np.arctan2(n1, d1), np.arctan2(n2, d2))
    phi4 = np.mod(2 * half + np.pi, 2 * np.pi) - np.pi
    return out(phi4), out(disc >= -1e-12 * (r2 + r3 + r4) ** 4)
