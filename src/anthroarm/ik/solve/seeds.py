"""Seeds of :func:`anthroarm.ik.solve`: the seed table of the arm's own poses, its aligned
form, and the closed-form solutions.

The seed table holds :data:`SEED_TABLE` configurations drawn once per (robot, frame), uniformly
in the sampling box of the joints on the frame's path (:attr:`anthroarm.chain.Chain.sampling_box`,
a continuous joint's angle in [−π, π]) from a fixed RNG seed, with their poses.  The entry
nearest the target in ‖p − p*‖² + w²‖R − R*‖²_F (w = :data:`SEED_ROT_WEIGHT` × reach, m) comes
first: the distance is linear in the entry's features, so the lookup is one vector–matrix
product.  Where the first and last joints of the path are revolute and span ≥
:data:`ALIGN_RANGE` the table is :class:`Aligned`: the nearest entry up to a turn of those two
joints, turned onto the target.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ...chain import PRISMATIC
from ...errors import UnsupportedModelError
from .. import closed_form
from ..geometric import NO_REF
from ..vec3 import WRAP_MAX
from .targets import POSE

SEED_TABLE = 2048  # configurations in the per-(robot, frame) seed table
SEED_TABLE_RNG = 20231  # its fixed RNG seed (the table, and so every answer, is reproducible)
SEED_ROT_WEIGHT = 0.25  # w / reach in the seed distance ‖Δp‖² + w²‖ΔR‖²_F
SEED_POSTURE_WEIGHT = 0.05  # w_q / reach: + w_q²‖θ − θ_ref‖² in that distance for posture problems
TABLE_SEEDS = 8  # nearest table entries tried before uniform random restarts
ALIGN_RANGE = np.pi  # first / last joints spanning at least a half turn are aligned (see Aligned; so101: median 10 % faster)
ALIGN_WEIGHT = 0.25  # w / reach of the last joint's axis direction in the aligned table's distance
#: swivel angles (rad) of a redundant arm's closed-form seeds: 16 (human_arm7, 100 random poses:
#: the answer misses the member of the family nearest the comfortable posture on 2, median solve
#: 0.24 ms; 24 angles: 2 and 0.28 ms; 12: 4 and 0.21 ms; 8: 7 and 0.20 ms)
SWIVEL_GRID = np.linspace(-np.pi, np.pi, 16, endpoint=False)
#: the swivel angles tried first where any solution will do (no posture objective), 90° apart
SWIVEL_GRID_COARSE = SWIVEL_GRID[::4].copy()  # C order: the compiled calls' one array type
#: a closed form costing at most this (µs, ``ClosedForm.cost_us``) is tried first
CHEAP_US = 50.0


def build_table(sh, data):
    """(Θ (K, n), G_pose (16, K), G_pos (4, K), G_rot (9, K)): the configurations θ and, per
    target kind, the matrix G whose product x·G with the target's features x is the seed
    distance of every entry up to a constant: for a pose, x = T*.ravel() (16,) and
    ‖Δp‖² + w²‖ΔR‖²_F = |p|² − 2p·p* − 2w² R:R* + const (the rows of G against T*'s bottom
    row (0, 0, 0, 1) hold 0, 0, 0, |p|²); for a position x = (p*, 1), for a rotation x = R*
    flattened.  Stored transposed: x·G reads G row by row (~2.5× faster than G·x here)."""
    K = SEED_TABLE
    rng = np.random.default_rng(SEED_TABLE_RNG)
    Th = sh.lo_s + (sh.hi_s - sh.lo_s) * rng.random((K, sh.n))
    Q = Th if sh.to_q is None else sh.to_q(Th)
    H = np.empty((K, 3, 4))
    model, fid = sh.model, sh.fid
    for k, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        H[k] = data.oMf[fid].homogeneous[:3]
    w2 = (SEED_ROT_WEIGHT * max(sh.reach, 1e-3)) ** 2
    P = H[:, :, 3]
    c = (P * P).sum(1)
    G = np.zeros((K, 4, 4))
    G[:, :3, :3] = -2.0 * w2 * H[:, :, :3]
    G[:, :3, 3] = -2.0 * P
    G[:, 3, 3] = c
    Gpos = np.column_stack((-2.0 * P, c))
    Th.setflags(write=False)
    return (
        Th,
        np.ascontiguousarray(G.reshape(K, 16).T),
        np.ascontiguousarray(Gpos.T),
        np.ascontiguousarray(-H[:, :, :3].reshape(K, 9).T),
    )


def posture_penalty(sh, Th, th_ref):
    """w_q²‖Θ − θ_ref‖² (K,) over the table Θ, w_q = :data:`SEED_POSTURE_WEIGHT` × reach."""
    wq2 = (SEED_POSTURE_WEIGHT * max(sh.reach, 1e-3)) ** 2
    return wq2 * ((Th - th_ref) ** 2).sum(1)


class Aligned:
    """Seed table of a pose target aligned on the first and the last joint of the path.

    Turning the first joint by Δ turns everything after it rigidly about that joint's (fixed)
    axis: T(θ₁ + Δ, …) = Rot(a₁, c₁, Δ) T(θ).  Turning the last joint spins the joint-n frame
    W about its own axis: the point p_W and the axis direction z_W = R_W aₙ do not change.  So a
    table entry matches a target up to these two angles when (ρ, h, z_W) agree, with ρ, h the
    distance from and height along the first axis of p_W and z_W expressed in the half-plane
    of p_W (the canonical frame, turned by −φ about a₁, φ the azimuth of p_W).  The nearest
    entry in ‖Δρ‖² + ‖Δh‖² + w²‖Δz_W‖² (linear in the entry's features: one mat-vec) is then
    turned: θ₁ += φ* − φ_k, and θₙ by the angle about aₙ between the entry's and the target's
    joint-n frames (atan2 of two dot products).  Every table entry thus stands for a
    two-parameter family of poses (measured: median 5 iterations instead of 6–7 on panda and
    ur5, and fewer restarts).

    Applies to paths of ≥ 3 joints whose first and last joints are revolute (or continuous),
    not mimic, with a range of at least :data:`ALIGN_RANGE`; the axes are the chain's
    (``Joint.axis``, joint frame).  An alignment outside a joint's range is wrapped by 2π or
    clipped."""

    __slots__ = (
        "iq1",
        "iqn",
        "c1",
        "B",
        "Bc1",
        "an",
        "un",
        "vn",
        "AUV",
        "Fi",
        "G",
        "phi",
        "U",
        "V",
        "w",
        "lo1",
        "hi1",
        "lon",
        "hin",
    )

    @classmethod
    def make(cls, sh, data, Th):
        chain = sh.chain
        path = chain.path(sh.fid)
        if len(path) < 3:
            return None
        J1, Jn = chain.joints[path[0]], chain.joints[path[-1]]
        if any(j.is_mimic or j.kind == PRISMATIC for j in (J1, Jn)):
            return None
        i1, i_n = J1.idx_v, Jn.idx_v
        if sh.hi[i1] - sh.lo[i1] < ALIGN_RANGE or sh.hi[i_n] - sh.lo[i_n] < ALIGN_RANGE:
            return None
        self = cls.__new__(cls)
        model = sh.model
        pin.forwardKinematics(model, data, sh.q(sh.ref))
        M1 = data.oMi[J1.index + 1]
        a1 = M1.rotation @ J1.axis
        self.c1 = M1.translation.copy()
        self.B = np.array((*_perp(a1), a1))  # rows: world -> first-axis basis
        anl = np.asarray(Jn.axis)
        un, vn = _perp(anl)
        self.an, self.un, self.vn = anl, un, vn
        f = chain.frame(sh.fid)
        self.Fi = pin.SE3(f.rotation, f.translation).inverse()
        self.iq1, self.iqn = i1, i_n
        self.lo1, self.hi1, self.lon, self.hin = (
            float(x) for x in (sh.lo[i1], sh.hi[i1], sh.lo[i_n], sh.hi[i_n])
        )
        self.w = ALIGN_WEIGHT * max(sh.reach, 1e-3)
        self.AUV = np.column_stack((anl, un, vn))
        self.Bc1 = self.B @ self.c1
        K = len(Th)
        feats = np.empty((K, 6))
        self.phi = np.empty(K)
        self.U = []
        self.V = []
        jn = Jn.index + 1
        for k, q in enumerate(Th if sh.to_q is None else sh.to_q(Th)):
            pin.forwardKinematics(model, data, q)
            W = data.oMi[jn]
            feats[k], self.phi[k], u, v = self._canon(W.translation, W.rotation)
            self.U.append(u)
            self.V.append(v)
        # score = |f|² − 2 f·x (+ |x|², the same for every entry), as one product G·(x, 1)
        f5 = feats[:, :5]
        self.G = np.ascontiguousarray(np.column_stack((-2.0 * f5, (f5 * f5).sum(1))).T)  # (6, K)
        self.phi = self.phi.tolist()  # plain floats: scalar arithmetic in seed() is cheaper
        return self

    def _canon(self, p, R):
        """Features (ρ, h, w z'), 1 of a joint-n frame (world position ``p``, rotation ``R``), its
        azimuth φ, and its uₙ, vₙ directions in the canonical frame (plain floats: 3-vectors
        cost less in Python than in NumPy)."""
        (dx, dy, dh), (z, u, v) = (
            (self.B.dot(p) - self.Bc1).tolist(),
            self.B.dot(R).dot(self.AUV).T.tolist(),
        )
        phi = math.atan2(dy, dx)
        co, si = math.cos(phi), math.sin(phi)
        w = self.w
        return (
            (
                math.hypot(dx, dy),
                dh,
                w * (co * z[0] + si * z[1]),
                w * (co * z[1] - si * z[0]),
                w * z[2],
                1.0,
            ),
            phi,
            (co * u[0] + si * u[1], co * u[1] - si * u[0], u[2]),
            (co * v[0] + si * v[1], co * v[1] - si * v[0], v[2]),
        )

    def query(self, Ms):
        """(scores (K,), φ*, u*) of target ``Ms``: u* the canonical uₙ direction of its joint-n frame."""
        W = Ms * self.Fi
        x, phi, u, _ = self._canon(W.translation, W.rotation)
        return np.array(x).dot(self.G), phi, u

    def seed(self, th, k, phi, u):
        """Table configuration θ (entry k, a copy) turned onto the target: first joint by the
        azimuth difference, last joint about its axis (wrapped by 2π or clipped into the range)."""
        i = self.iq1
        th[i] = _wrap(float(th[i]) + phi - self.phi[k], self.lo1, self.hi1)
        U, V = self.U[k], self.V[k]
        d = math.atan2(
            V[0] * u[0] + V[1] * u[1] + V[2] * u[2], U[0] * u[0] + U[1] * u[1] + U[2] * u[2]
        )
        i = self.iqn
        th[i] = _wrap(float(th[i]) + d, self.lon, self.hin)
        return th


def _perp(a):
    """(u, v) completing the unit vector ``a`` to a right-handed orthonormal basis (u, v, a)."""
    t = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = t - a * (a @ t)
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def _wrap(x, lo, hi):
    """x moved by a multiple of 2π into [lo, hi] if possible, else clipped."""
    if x < lo:
        x += 2.0 * math.pi * math.ceil((lo - x) / (2.0 * math.pi))
    elif x > hi:
        x -= 2.0 * math.pi * math.ceil((x - hi) / (2.0 * math.pi))
    return min(max(x, lo), hi)


class TableSeeds:
    """The seed-table entries nearest a target, nearest first (copies; for a pose target with an
    :class:`Aligned` table, turned onto the target): the nearest by one ``argmin``, the next
    :data:`TABLE_SEEDS` − 1 sorted when first needed; then ``None``."""

    __slots__ = ("ws", "sc", "k0", "order", "i", "al", "phi", "u")

    def __init__(self, ws, tg, th_ref):
        al = ws.aligned() if tg.kind == POSE else None
        if al is not None:
            sc, self.phi, self.u = al.query(tg.Ms)
        else:
            sc = tg.x.dot(ws.table()[1 + tg.kind])
        if th_ref is not None:
            sc = sc + ws.posture_penalty(th_ref)
        self.al = al
        self.ws = ws
        self.sc = sc
        self.k0 = -1
        self.order = None
        self.i = 0

    def next(self):
        sc = self.sc
        if self.i == 0:
            k = self.k0 = int(sc.argmin())
        else:
            if self.order is None:
                n = min(TABLE_SEEDS, len(sc) - 1)
                idx = np.argpartition(sc, n)[: n + 1]
                idx = idx[np.argsort(sc[idx])]
                self.order = [0] + [int(i) for i in idx if i != self.k0][: TABLE_SEEDS - 1]
            if self.i >= len(self.order):
                return None
            k = self.order[self.i]
        self.i += 1
        th = self.ws.table()[0][k].copy()
        return th if self.al is None else self.al.seed(th, k, self.phi, self.u)


# ------------------------------------------------------------------------------ closed form
def closed_form_cheap(robot, fid) -> bool:
    """True when ``analytic="auto"`` puts the closed form first (where it exists,
    :func:`anthroarm.ik.closed_form.closed_form_info`): a call costs about as much as a few
    Gauss–Newton iterations (``cost_us`` ≤ :data:`CHEAP_US`: a closed 6R class or an SRS arm's
    swivel grid, ~10 µs per pose and swivel angle in one compiled call; an arm solved by a
    search, :data:`anthroarm.ik.geometric.SEARCHED`, costs milliseconds and joins after
    ``ANALYTIC_AFTER`` failed attempts).  Fixed per robot, so the same call gives the same
    answer."""
    info = closed_form.closed_form_info(robot, fid)
    return info is not None and info.cost_us <= CHEAP_US


def analytic_seeds(robot, ws, tg, th_ref, swivel=None, grid=None, any_solution=False):
    """Closed-form solutions (K, n) in θ, the one nearest ``th_ref`` first, a note ("" or why
    the closed form failed), and the first one's (position, rotation) errors (m, rad) where
    the one-call kernel of a closed class computed them (its FK), else None.  A redundant arm
    (a swivel family of solutions) is solved at ``swivel`` (rad) if given, else on ``grid``
    (where ``any_solution``, only up to the first angle that has one).
    A 7-joint arm whose last joint is held
    (``param=`` of the closed form) is solved at that joint's value in the seed-table entry
    nearest the target (one closed-form call: 8 branches), then at the values of the next
    :data:`TABLE_SEEDS` − 1 entries (panda, 1000 random poses: 73 % answered at the nearest
    entry, 98 % within 8); where none gives a solution inside the limits, the general
    :func:`~anthroarm.ik.closed_form.analytic` at the nearest entry's value (polishing, rescue
    along the self-motions), then on the closed form's own grid of values."""
    sh = ws.sh
    none = np.zeros((0, sh.n))
    if tg.kind != POSE or not sh.has_closed_form:
        return none, "", None
    angles = (
        swivel if swivel is not None else grid
    )  # the swivel angles of an SRS arm (None: default)
    kw = {"swivel": angles} if sh.swivel_family and angles is not None else {}
    T = tg.H
    if th_ref is not None:  # one array type for the compiled calls (the shared posture: read-only)
        th_ref = sh.as_arg(th_ref)
    if sh.nearest_swivel is not None and th_ref is not None:
        g = np.atleast_1d(  # the grids are C-order module arrays: one type, no copy a call
            np.asarray(closed_form.DEFAULT_SWIVEL if angles is None else angles, dtype=float)
        )
        if (np.abs(g) < WRAP_MAX).all():
            one = sh.nearest_swivel(T, th_ref, g, any_solution)
            if one is not None:  # one compiled call, nearest first
                return one[0], "", one[1:]
    try:
        prm, table = None, None
        if sh.held is not None:
            table = TableSeeds(ws, tg, None)
            prm = float(table.next()[sh.held])
        if sh.nearest is not None:
            ref = NO_REF if th_ref is None else th_ref
            p = prm
            while True:
                one = sh.nearest(T, ref, 0.0 if p is None else p)
                if one is not None:  # one compiled call, nearest first
                    return one[0], "", (None if one[1] is None else one[1:])
                th = None if table is None else table.next()
                if th is None:
                    break
                p = float(th[sh.held])  # the held joint of the next-nearest table entry
        res = closed_form.analytic(robot, T, param=prm, frame=sh.fid) if prm is not None else None
        if res is None or not len(res):
            res = closed_form.analytic(robot, T, frame=sh.fid, **kw)
        S = sh.theta(np.asarray(res.solutions, dtype=float).reshape(-1, sh.nq))
    except (ValueError, ArithmeticError, UnsupportedModelError) as exc:  # a seed source only
        return none, f"analytic seed failed: {exc}", None
    if len(S) > 1:
        D = S - th_ref
        k = int((D * D).sum(1).argmin())
        if k:  # nearest first (the order of the others matters little)
            S[[0, k]] = S[[k, 0]]
    return S, "", None
