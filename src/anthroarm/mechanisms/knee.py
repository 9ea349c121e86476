"""Polycentric (four-bar) prosthetic knee and the path of its instantaneous centre of rotation.

The book (§2-5, l. 845–913, Fig. 2-18) names the two prosthetic knees, a single hinge and a
four-bar ("polycentric") linkage, without dimensions.  The four-bar knee is a planar four-bar
(:func:`anthroarm.mechanisms.fourbar_cartesian`, book §5-3) in the sagittal plane: the thigh
(socket) part is the ground link, the anterior and posterior links are the crank and the rocker,
and the shank hangs from the distal link, the coupler.  Knee flexion is the rotation of the
coupler relative to the thigh.

The **instantaneous centre of rotation** (ICR) of the shank relative to the thigh is the
intersection of the lines of the anterior and posterior links (Aronhold–Kennedy theorem); its
path over flexion is the fixed centrode.  Design criterion (literature, not the book): C. W.
Radcliffe, "Four-bar linkage prosthetic knee mechanisms: kinematics, alignment and prescription
criteria", *Prosthetics and Orthotics International* 18 (1994) 159–173: at full extension the
knee is stable under a heel-strike load when the ICR lies **posterior** to the TKA line (the line
from the trochanter, i.e. hip, to the ankle); a high ICR (proximal) gives a large zone of
voluntary control.  :func:`stability_margin` is that signed distance.

Frame and units: the thigh frame of the sagittal plane, x anterior, y proximal (up), origin at
any point of the thigh part (the default geometry: the nominal knee centre); metres, radians,
flexion positive when the foot moves posteriorly (the shank turns clockwise in this frame).

Bad input: lengths or pivots that do not form a linkage raise
:class:`~anthroarm.errors.ParameterError` (a ``ValueError``); a flexion the
linkage cannot reach, or a pose with parallel links (ICR at infinity), is a status, never NaN:
``status`` in {"ok", "cannot_assemble", "dead_point", "parallel_links"} with zeros in the
numbers of that sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..spatial.polar import from_xy, rotate, to_xy
from ._util import finite_array
from .fourbar import fourbar_cartesian

#: |sin| of the angle between the two links below this: the lines are parallel (ICR at infinity)
PARALLEL_TOL = 1e-9
#: the most samples :func:`icr_path` takes (1e5 flexion steps: far below a µrad)
MAX_PATH_SAMPLES = 100_000

__all__ = [
    "KneeGeometry",
    "KneeState",
    "default_knee",
    "knee_pose",
    "knee_flexion",
    "icr_path",
    "stability_margin",
    "PARALLEL_TOL",
    "MAX_PATH_SAMPLES",
]


@dataclass(frozen=True)
class KneeGeometry:
    """A four-bar knee at full extension, thigh frame (m): the proximal pivots of the anterior
    and posterior links on the thigh part (``prox_ant``, ``prox_post``), their distal pivots on
    the shank part (``dist_ant``, ``dist_post``) and the ``ankle`` point carried by the shank."""

    prox_ant: np.ndarray
    prox_post: np.ndarray
    dist_ant: np.ndarray
    dist_post: np.ndarray
    ankle: np.ndarray

    def __post_init__(self):
        for name in ("prox_ant", "prox_post", "dist_ant", "dist_post", "ankle"):
            object.__setattr__(
                self, name, finite_array(name, getattr(self, name), (2,)).astype(float)
            )
        pairs = {
            "anterior link": (self.prox_ant, self.dist_ant),
            "posterior link": (self.prox_post, self.dist_post),
            "thigh part": (self.prox_ant, self.prox_post),
            "shank part": (self.dist_ant, self.dist_post),
        }
        for what, (a, b) in pairs.items():
            if not np.hypot(*(b - a)) > 0.0:
                raise ParameterError(
                    f"knee: the {what} has zero length (pivots {a.tolist()} and {b.tolist()} "
                    "coincide)"
                )

    @property
    def lengths(self) -> tuple[float, float, float, float]:
        """(ground r1, anterior r2, distal r3, posterior r4), m: the four-bar of §5-3."""
        d = np.hypot
        return (
            float(d(*(self.prox_post - self.prox_ant))),
            float(d(*(self.dist_ant - self.prox_ant))),
            float(d(*(self.dist_post - self.dist_ant))),
            float(d(*(self.dist_post - self.prox_post))),
        )


def default_knee() -> KneeGeometry:
    """An example four-bar knee (ours; the book prints no dimensions): links converging
    proximally so that the ICR at extension sits about 9 cm above the distal pivots and behind
    the anterior link, the usual layout of polycentric knees (Radcliffe 1994, Fig. 5).
    Ankle 0.42 m below the knee."""
    return KneeGeometry(
        prox_ant=(0.008, 0.030),
        prox_post=(-0.016, 0.030),
        dist_ant=(0.020, -0.010),
        dist_post=(-0.020, -0.015),
        ankle=(0.0, -0.42),
    )


@dataclass(frozen=True)
class KneeState:
    """Knee poses for an array of crank angles: ``flexion`` (rad), ``icr`` (N, 2) fixed-centrode
    points in the thigh frame, ``icr_shank`` (N, 2) the same points in the shank's extension
    frame (moving centrode), ``dist_ant``/``dist_post``/``ankle`` (N, 2) the moving points,
    ``theta2`` the anterior link angle (rad), ``status`` (N,) and ``ok`` (N,).  Where ``ok`` is
    False the numbers are 0 and ``status`` says why."""

    theta2: np.ndarray
    flexion: np.ndarray
    icr: np.ndarray
    icr_shank: np.ndarray
    dist_ant: np.ndarray
    dist_post: np.ndarray
    ankle: np.ndarray
    status: np.ndarray
    ok: np.ndarray


def _branch(knee: KneeGeometry) -> tuple[int, float, float]:
    """Assembly branch of the four-bar through the extension pose, the crank angle and the
    coupler angle there."""
    g = knee.prox_post - knee.prox_ant
    r1, r2, r3, r4 = knee.lengths
    a = knee.dist_ant - knee.prox_ant
    th2 = float(np.arctan2(a[1], a[0]))
    c = knee.dist_post - knee.dist_ant
    th3 = float(np.arctan2(c[1], c[0]))
    errs = []
    for br in (1, -1):
        s = fourbar_cartesian(g, r2, r3, r4, th2, branch=br)
        errs.append(abs(np.angle(np.exp(1j * (float(s.theta3) - th3)))))
    return (1 if errs[0] <= errs[1] else -1), th2, th3


def knee_pose(knee: KneeGeometry, theta2) -> KneeState:
    """Knee pose(s) at anterior-link angle(s) ``theta2`` (rad, absolute from +x, thigh frame),
    on the assembly branch of the extension pose (book §5-3 four-bar, :func:`fourbar_cartesian`).

    ICR: the intersection of the lines prox_ant–dist_ant and prox_post–dist_post
    (Aronhold–Kennedy)."""
    th2 = np.atleast_1d(finite_array("theta2", theta2)).astype(float)
    br, _, th3_ext = _branch(knee)
    r1, r2, r3, r4 = knee.lengths
    s = fourbar_cartesian(knee.prox_post - knee.prox_ant, r2, r3, r4, th2, branch=br)
    th3 = np.atleast_1d(np.asarray(s.theta3, float))
    th4 = np.atleast_1d(np.asarray(s.theta4, float))
    status = np.array(np.broadcast_to(np.asarray(s.status, dtype=object), th2.shape), dtype=object)
    A = knee.prox_ant + r2 * np.stack([np.cos(th2), np.sin(th2)], -1)
    B = A + r3 * np.stack([np.cos(th3), np.sin(th3)], -1)
    u = np.stack([np.cos(th2), np.sin(th2)], -1)  # anterior link direction
    w = np.stack([np.cos(th4), np.sin(th4)], -1)  # posterior link direction
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    parallel = np.abs(cross) < PARALLEL_TOL
    status = np.where((status == "ok") & parallel, "parallel_links", status)
    ok = status == "ok"
    safe = np.where(ok, cross, 1.0)
    d = knee.prox_post - knee.prox_ant
    t = (d[0] * w[:, 1] - d[1] * w[:, 0]) / safe  # prox_ant + t u = prox_post + s w
    icr = knee.prox_ant + t[:, None] * u
    # shank rotation relative to its extension pose: the coupler turned by th3 - th3_ext
    phi = np.where(ok, np.angle(np.exp(1j * (th3 - th3_ext))), 0.0)
    # planar rotations as complex products, Eq. (5-5) (spatial.polar)
    icr_shank = knee.dist_ant + to_xy(rotate(from_xy(np.where(ok[:, None], icr - A, 0.0)), -phi))
    ankle = A + to_xy(rotate(from_xy(knee.ankle - knee.dist_ant), phi))
    z = ~ok
    for arr in (icr, icr_shank, A, B, ankle):
        arr[z] = 0.0
    flexion = np.where(ok, -phi, 0.0)
    return KneeState(th2, flexion, icr, icr_shank, A, B, ankle, status.astype(str), ok)


def knee_flexion(knee: KneeGeometry, flexion) -> KneeState:
    """Knee pose(s) at the given flexion angle(s) (rad, 0 = the extension geometry): the crank
    angle is found on the assembled range of the extension branch by bracketing and bisection
    (flexion is monotonic in the crank angle between dead points).  A flexion the linkage
    cannot reach gets status "cannot_assemble" (numbers 0)."""
    target = np.atleast_1d(finite_array("flexion", flexion)).astype(float)
    if target.ndim != 1 or target.size == 0:
        raise ParameterError(
            f"flexion must be one angle or a non-empty 1-D array (rad), got shape {target.shape}"
        )
    _, th2_ext, _ = _branch(knee)
    # sample the crank around the extension angle, keep the assembled run that contains it
    grid = th2_ext + np.linspace(-np.pi, np.pi, 4001)
    s = knee_pose(knee, grid)
    i0 = int(np.argmin(np.abs(grid - th2_ext)))
    lo = hi = i0
    while lo > 0 and s.ok[lo - 1]:
        lo -= 1
    while hi < len(grid) - 1 and s.ok[hi + 1]:
        hi += 1
    f = s.flexion[lo : hi + 1]
    g = grid[lo : hi + 1]
    d = np.diff(f)
    mono = np.all(d > 0) or np.all(d < 0)
    if not mono:  # keep the monotonic run through the extension pose
        sign = np.sign(d[min(i0 - lo, len(d) - 1)])
        a = b = i0 - lo
        while a > 0 and np.sign(d[a - 1]) == sign:
            a -= 1
        while b < len(d) and np.sign(d[b]) == sign:
            b += 1
        f, g = f[a : b + 1], g[a : b + 1]
    order = np.argsort(f)
    f, g = f[order], g[order]
    th2 = np.interp(target, f, g)
    inside = (target >= f[0] - 1e-12) & (target <= f[-1] + 1e-12)
    for _ in range(60):  # Newton-free refinement: secant on the sampled bracket
        st = knee_pose(knee, th2)
        err = np.where(inside & st.ok, st.flexion - target, 0.0)
        if np.abs(err).max(initial=0.0) < 1e-13:
            break
        h = 1e-7
        st2 = knee_pose(knee, th2 + h)
        slope = np.where(inside & st.ok & st2.ok, (st2.flexion - st.flexion) / h, 1.0)
        slope = np.where(np.abs(slope) < 1e-12, 1.0, slope)
        th2 = th2 - err / slope
    st = knee_pose(knee, th2)
    ok = st.ok & inside
    status = np.where(ok, st.status, np.where(inside, st.status, "cannot_assemble"))
    status = np.where(~ok & (status == "ok"), "cannot_assemble", status)
    z = ~ok
    for arr in (st.icr, st.icr_shank, st.dist_ant, st.dist_post, st.ankle):
        arr[z] = 0.0
    return KneeState(
        np.where(ok, th2, 0.0),
        np.where(ok, st.flexion, 0.0),
        st.icr,
        st.icr_shank,
        st.dist_ant,
        st.dist_post,
        st.ankle,
        status.astype(str),
        ok,
    )


def icr_path(knee: KneeGeometry, max_flexion: float = np.radians(120.0), n: int = 121) -> KneeState:
    """The ICR path (fixed centrode) from full extension to ``max_flexion`` (rad; Table 2.4:
    knee flexion about 120°) in ``n`` equal steps of flexion.  Samples the linkage cannot
    reach carry status "cannot_assemble"."""
    if not (isinstance(n, (int, np.integer)) and 2 <= n <= MAX_PATH_SAMPLES):
        raise ParameterError(f"n must be an integer in 2..{MAX_PATH_SAMPLES}, got {n!r}")
    m = float(finite_array("max_flexion", max_flexion))
    return knee_flexion(knee, np.linspace(0.0, m, int(n)))


def stability_margin(knee: KneeGeometry, hip) -> float:
    """Radcliffe's (1994) alignment stability at full extension: the signed distance (m) of the
    ICR from the TKA line (hip/trochanter ``hip`` (2,) to the ``ankle``, thigh frame), positive
    when the ICR lies posterior to the line (stable under a heel-strike load).  ValueError if
    the links are parallel at extension (no finite ICR)."""
    hip = finite_array("hip", hip, (2,)).astype(float)
    st = knee_pose(knee, _branch(knee)[1])
    if not st.ok[0]:
        raise ParameterError(f"knee: no finite ICR at extension ({st.status[0]})")
    line = knee.ankle - hip
    n = np.hypot(*line)
    if not n > 0:
        raise ParameterError("knee: the hip and the ankle coincide")
    p = st.icr[0] - hip
    # anterior is +x: the ICR is posterior when it lies on the -x side of the line (line points
    # down)
    return float((p[0] * line[1] - p[1] * line[0]) / n)
