"""One-shot inverse kinematics: ``aa.ik.solve(robot, T)`` -> :class:`~anthroarm.ik.result.IKResult`.

Method: damped Gauss–Newton (Levenberg–Marquardt) on the pose error with projected steps,
seeds from the closed form or from a table of the arm's own poses, and restarts inside the
joint limits under a time budget.  Per iteration (tool frame, m and rad):

    e = log₆(T(q)⁻¹ T*)  (body twist (v; ω)),   J = ᵇJ(q)  (LOCAL frame Jacobian),
    Δq = Jᵀ (J Jᵀ + λ I)⁻¹ e,   λ = λ₀ + k ‖e‖²   (Chan / Sugihara damping),
    q ← clip(q + Δq, q_min, q_max).

This is the book's feedback-compensation Newton step Δq = J⁻¹ e (Ch. 7 §7-5) made robust: the
damping is the λ → ∞ blend toward the steepest-descent direction Jᵀe of §7-6 (A9) when the
error is large or J is singular, and vanishes near the solution (quadratic convergence).
Joint ranges, the penalty constraints g_i(Q) ≥ 0 of (7-84)–(7-85), are enforced exactly: a
joint whose step would cross its limit is frozen for that step and the step is recomputed
with the other joints (an active set; plain clipping let those joints stall the attempt),
then the result is clipped.  An attempt stops when the error no longer falls by 10 % in three
iterations; the next seed is then tried.  Success is decided on the exact errors ‖p* − p‖ and
the angle of Rᵀ R* from Pinocchio's FK of the returned q.

The kernel is written for the cost of each call from Python (~0.1–0.5 µs per Pinocchio or
NumPy call on these sizes, see ``benchmarks/results/ik.md``): one ``computeJointJacobians`` +
``updateFramePlacement`` per iteration, J Jᵀ + λI built in a preallocated array and factorised
in place by LAPACK ``dposv``, the ``clip`` ufunc, limit hits detected by comparing bytes.

Seeds, in order:

1. the closed-form solutions of :func:`anthroarm.ik.analytic` (nearest the posture first),
   when ``analytic=True``, or with ``analytic="auto"`` and no ``q0`` where the closed form is
   cheap (:func:`_analytic_cheap`: the six-joint book arms, ~10 µs; the human arm's 24-angle
   swivel grid with the compiled kernel, ~20 µs); they are exact, so one evaluation verifies
   them;
2. ``q0`` when given (clipped into the limits);
3. the seed table: :data:`SEED_TABLE` configurations drawn once per robot and frame,
   uniformly inside the limits from a fixed RNG seed, with their poses.  The entry nearest the
   target in ‖p − p*‖² + w²‖R − R*‖²_F (w = :data:`SEED_ROT_WEIGHT` × reach) comes first: the
   distance is linear in the entry's features, so the lookup is one vector–matrix product.
   Where the first and last joints span ≥ :data:`ALIGN_RANGE` (panda, ur5) the table is
   :class:`_Aligned`: the nearest entry up to a turn of those two joints, turned onto the
   target.  Then the next :data:`TABLE_SEEDS` − 1 nearest entries;
4. uniform random configurations inside the limits, until ``max_time`` or ``max_restarts``;
   with ``analytic="auto"`` the closed form joins after :data:`ANALYTIC_AFTER` failed attempts
   where it was not first.

Targets: a 4×4 rigid pose (``mode="pose"``), a position (3,) (``"position"``: e = p* − p with
the LOCAL_WORLD_ALIGNED linear rows of J) or a rotation (3, 3) (``"orientation"``:
e = log₃(Rᵀ R*) with the LOCAL angular rows).  A leading batch axis solves N targets
(:class:`~anthroarm.ik.result.IKBatchResult`), in lockstep (:func:`_solve_lockstep`) where
the table seeds them.

Redundant arms (human arm): ``posture`` adds a secondary objective ½‖q − q_ref‖² in the null
space of the primary task: from a solution, Δq = J⁺e + N s with N = I − Jᵀ(JJᵀ + λI)⁻¹J, until
the null-space step is below :data:`NULL_TOL`.  With a one-dimensional null space (a 7-DOF arm
on a 6-D pose) the step along the self-motion is a secant (quasi-Newton) step on the posture
cost, which converges superlinearly where the plain projected-gradient step s = q_ref − q
converges linearly (slowly where the self-motion curve bends; it used to run out of
iterations on a third of the human-arm targets); a null-space step that would cross a joint
limit stops on it, and a joint at its limit that the pull pushes outward is frozen — the
optimum of a one-dimensional self-motion is then on that limit.  The table seed of such a
problem also penalises ‖q − q_ref‖ (:data:`SEED_POSTURE_WEIGHT`); closed-form seeds are
sorted by ‖q − q_ref‖, so the phase starts on the branch nearest the comfortable posture.
``swivel=φ*`` instead places the elbow at the swivel angle φ* (:mod:`anthroarm.ik.qp.tasks.swivel`).
"""

from __future__ import annotations

import importlib.util
import math
import time
import weakref

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dposv, dpotrs

try:  # the clip ufunc itself: ~0.2 µs against ~1.3 µs for np.clip's Python wrapper
    from numpy._core.umath import clip as _uclip
except ImportError:  # numpy < 2
    try:
        from numpy.core.umath import clip as _uclip
    except ImportError:  # pragma: no cover - a NumPy without the ufunc: the public wrapper
        _uclip = np.clip

from ..errors import UnsupportedModelError
from .qp.targets import as_position, as_rotation, as_se3
from .qp.tasks.posture import comfortable_posture
from .qp.tasks.swivel import swivel_frames as _swivel_frames
from .qp.tasks.swivel import swivel_from_points
from .result import IKBatchResult, IKResult

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_log3 = pin.log3
_log6 = pin.log6
_cjj = pin.computeJointJacobians
_ufp = pin.updateFramePlacement
_gfj = pin.getFrameJacobian

#: Gauss–Newton settings (tuned on panda / ur5 / talos_arm / human_arm7 / prosthetic_arm).
LAMBDA0 = 1e-10   # floor of the damping (keeps JJᵀ + λI positive definite at singularities)
K_DAMP = 0.01     # λ grows with the squared error: large errors -> short, gradient-like steps
MAX_ITER = 60     # iterations per attempt (before the stall test ends it earlier)
STALL = 3         # an attempt ends after STALL iterations without a 10 % error decrease
SEED_TABLE = 2048       # configurations in the per-(robot, frame) seed table
SEED_TABLE_RNG = 20231  # its fixed RNG seed (the table, and so every answer, is reproducible)
SEED_ROT_WEIGHT = 0.25  # w / reach in the seed distance ‖Δp‖² + w²‖ΔR‖²_F
SEED_POSTURE_WEIGHT = 0.05  # w_q / reach: + w_q²‖q − q_ref‖² in that distance for posture problems
TABLE_SEEDS = 8   # nearest table entries tried before uniform random restarts
ALIGN_RANGE = 1.5 * np.pi   # first / last joints with at least this range are aligned (see _Aligned)
ALIGN_WEIGHT = 0.25         # w / reach of the last joint's axis direction in the aligned table's distance
NULL_TOL = 1e-4   # posture / swivel secondary step norm (rad) under which it has settled
NULL_EXTRA = 60   # extra iterations allowed for the secondary objective
NULL_STEP = 1.0   # longest null-space step (rad)
SECANT_RANGE = (0.1, 10.0)  # accepted curvature estimates of the secant null-space step
ANALYTIC_AFTER = 8  # analytic="auto": closed-form seeds join after this many failed attempts
LOCKSTEP_MIN = 8      # batches at least this large iterate all targets together (vectorised LM)
LOCKSTEP_ATTEMPTS = 10 # attempts per target in lockstep; the rest go to the one-target solver
HUMAN_GRID = np.linspace(-np.pi, np.pi, 24, endpoint=False)  # swivel grid of those seeds (human_arm7)

_CHAINS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()

#: The budget ``max_time`` is CPU time of the calling thread: on a busy machine a wall-clock
#: budget turns into failures that depend on the load; with a CPU-time budget (and the fixed
#: restart seed) the same call gives the same answer.  Wall time can exceed it when the process
#: is descheduled.
_clock = time.thread_time

_POSE, _POSITION, _ORIENTATION = 0, 1, 2
_KIND = {"pose": _POSE, "position": _POSITION, "orientation": _ORIENTATION}


class _Chain:
    """Per (robot, frame) workspace: model, own data, limits, reach bound, seed table and the
    preallocated arrays of the Gauss–Newton kernel."""

    def __init__(self, robot, fid: int):
        model = robot.model
        if model.nq != model.nv:
            raise UnsupportedModelError(f"{robot.name}: aa.ik.solve supports 1-DOF joints (revolute, prismatic); "
                                        f"this model has nq={model.nq} != nv={model.nv}")
        self.robot = robot
        self.model = model
        self.data = model.createData()
        self.fid = fid
        self.n = model.nq
        self.lo = np.array(model.lowerPositionLimit, dtype=float)
        self.hi = np.array(model.upperPositionLimit, dtype=float)
        self.lo_s = np.where(np.isfinite(self.lo), self.lo, -np.pi)   # sampling box
        self.hi_s = np.where(np.isfinite(self.hi), self.hi, np.pi)
        # reach bound: |p_frame| <= sum of the joint offsets on the path + tool offset
        # (+ the largest travel of prismatic joints); rotations preserve lengths
        frame = model.frames[fid]
        jid = frame.parentJoint
        reach = float(np.linalg.norm(frame.placement.translation))
        for j in model.supports[jid][1:]:
            reach += float(np.linalg.norm(model.jointPlacements[j].translation))
            jm = model.joints[j]
            if "Prismatic" in jm.shortname() or "Translation" in jm.shortname():
                i = jm.idx_q
                reach += float(max(abs(self.lo_s[i]), abs(self.hi_s[i])))
        self.reach = reach
        self.path = [model.joints[j].idx_q for j in model.supports[jid][1:]]
        self.default_ref = comfortable_posture(robot)
        self.analytic_first = _analytic_cheap(robot, fid)
        # kernel workspace: J Jᵀ + λI is built in place (its diagonal is a view) and handed to
        # LAPACK as its transpose (Fortran order, symmetric) so that dposv factorises in place
        self.A = {m: np.empty((m, m)) for m in (3, 6)}
        self.AF = {m: a.T for m, a in self.A.items()}
        self.Ad = {m: a.reshape(-1)[:: m + 1] for m, a in self.A.items()}
        self.e6 = np.empty(6)
        self._table = None
        self._aligned = None
        self._penalty = {}

    def clip(self, q):
        return np.minimum(np.maximum(q, self.lo), self.hi)

    def random(self, gen, size=None):
        if gen[0] is None:
            gen[0] = np.random.default_rng(gen[1])
        return self.lo_s + (self.hi_s - self.lo_s) * gen[0].random(self.n if size is None else (size, self.n))

    # ------------------------------------------------------------------ seed table
    def table(self):
        """(Q (K, n), G_pose (16, K), G_pos (4, K), G_rot (9, K)): the configurations and, per
        target kind, the matrix G whose product x·G with the target's features x is the seed
        distance of every entry up to a constant: for a pose, x = T*.ravel() (16,) and
        ‖Δp‖² + w²‖ΔR‖²_F = |p|² − 2p·p* − 2w² R:R* + const (the rows of G against T*'s bottom
        row (0, 0, 0, 1) hold 0, 0, 0, |p|²); for a position x = (p*, 1), for a rotation x = R*
        flattened.  Stored transposed: x·G reads G row by row (~2.5× faster than G·x here)."""
        if self._table is None:
            K = SEED_TABLE
            rng = np.random.default_rng(SEED_TABLE_RNG)
            Q = self.lo_s + (self.hi_s - self.lo_s) * rng.random((K, self.n))
            H = np.empty((K, 3, 4))
            model, data, fid = self.model, self.data, self.fid
            for k, q in enumerate(Q):
                pin.framesForwardKinematics(model, data, q)
                H[k] = data.oMf[fid].homogeneous[:3]
            w2 = (SEED_ROT_WEIGHT * max(self.reach, 1e-3)) ** 2
            P = H[:, :, 3]
            c = (P * P).sum(1)
            G = np.zeros((K, 4, 4))
            G[:, :3, :3] = -2.0 * w2 * H[:, :, :3]
            G[:, :3, 3] = -2.0 * P
            G[:, 3, 3] = c
            Gpos = np.column_stack((-2.0 * P, c))
            self._table = (Q, np.ascontiguousarray(G.reshape(K, 16).T), np.ascontiguousarray(Gpos.T),
                           np.ascontiguousarray(-H[:, :, :3].reshape(K, 9).T))
        return self._table

    def aligned(self):
        """The :class:`_Aligned` seed table of this chain, or None where it does not apply."""
        if self._aligned is None:
            self._aligned = _Aligned.make(self) or False
        return self._aligned or None

    def posture_penalty(self, q_ref):
        """w_q²‖Q − q_ref‖² over the table (cached per q_ref)."""
        key = q_ref.tobytes()
        pen = self._penalty.get(key)
        if pen is None:
            Q = self.table()[0]
            wq2 = (SEED_POSTURE_WEIGHT * max(self.reach, 1e-3)) ** 2
            pen = wq2 * ((Q - q_ref) ** 2).sum(1)
            if len(self._penalty) > 16:
                self._penalty.clear()
            self._penalty[key] = pen
        return pen


class _Aligned:
    """Seed table of a pose target aligned on the first and the last joint of the chain.

    Turning the first joint by Δ turns everything after it rigidly about that joint's (fixed)
    axis: T(q₁ + Δ, …) = Rot(a₁, c₁, Δ) T(q).  Turning the last joint spins the joint-n frame
    W about its own axis: the point p_W and the axis direction z_W = R_W aₙ do not change.  So a
    table entry matches a target up to these two angles when (ρ, h, z_W) agree, with ρ, h the
    distance from and height along the first axis of p_W and z_W expressed in the half-plane
    of p_W (the canonical frame, turned by −φ about a₁, φ the azimuth of p_W).  The nearest
    entry in ‖Δρ‖² + ‖Δh‖² + w²‖Δz_W‖² (linear in the entry's features: one mat-vec) is then
    turned: q₁ += φ* − φ_k, and qₙ by the angle about aₙ between the entry's and the target's
    joint-n frames (atan2 of two dot products).  Every table entry thus stands for a
    two-parameter family of poses: with the same 2048 entries the seed lies nearer the target
    (measured: median 5 iterations instead of 6–7 on panda and ur5, and fewer restarts).

    Applies to chains of ≥ 3 joints whose first and last joints are revolute with a range of at
    least :data:`ALIGN_RANGE` (panda, ur5; not talos_arm, whose wrist spans 1.4 rad): an
    alignment that falls outside a joint's range is wrapped by 2π or clipped."""

    __slots__ = ("iq1", "iqn", "c1", "B", "Bc1", "an", "un", "vn", "AUV", "Fi", "G", "phi", "U", "V", "w", "lo1",
                 "hi1", "lon", "hin")

    @staticmethod
    def _axis(model, data, jid, q):
        """Unit axis (joint-local) of revolute joint ``jid``, or None for another joint."""
        if model.joints[jid].nq != 1 or "Prismatic" in model.joints[jid].shortname() \
                or model.joints[jid].shortname().endswith(("PX", "PY", "PZ")):
            return None
        i = model.joints[jid].idx_q
        q2 = q.copy()
        q2[i] += 0.5
        pin.forwardKinematics(model, data, q)
        M1 = data.oMi[jid].copy()
        pin.forwardKinematics(model, data, q2)
        M2 = data.oMi[jid]
        if np.linalg.norm(M2.translation - M1.translation) > 1e-9:
            return None
        w = pin.log3(M1.rotation.T @ M2.rotation) / 0.5
        return w / np.linalg.norm(w) if abs(np.linalg.norm(w) - 1.0) < 1e-6 else None

    @classmethod
    def make(cls, ch):
        model, data = ch.model, ch.data
        frame = model.frames[ch.fid]
        path = list(model.supports[frame.parentJoint][1:])
        if len(path) < 3:
            return None
        j1, jn = path[0], path[-1]
        i1, i_n = model.joints[j1].idx_q, model.joints[jn].idx_q
        if ch.hi[i1] - ch.lo[i1] < ALIGN_RANGE or ch.hi[i_n] - ch.lo[i_n] < ALIGN_RANGE:
            return None
        q0 = ch.default_ref.copy()
        a1l, anl = cls._axis(model, data, j1, q0), cls._axis(model, data, jn, q0)
        if a1l is None or anl is None:
            return None
        self = cls.__new__(cls)
        pin.forwardKinematics(model, data, q0)
        M1 = data.oMi[j1]
        a1 = M1.rotation @ a1l
        self.c1 = M1.translation.copy()
        t = np.array([1.0, 0.0, 0.0]) if abs(a1[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        e1 = t - a1 * (a1 @ t)
        e1 /= np.linalg.norm(e1)
        self.B = np.array([e1, np.cross(a1, e1), a1])          # rows: world -> first-axis basis
        t = np.array([1.0, 0.0, 0.0]) if abs(anl[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        un = t - anl * (anl @ t)
        un /= np.linalg.norm(un)
        self.an, self.un, self.vn = anl, un, np.cross(anl, un)
        self.Fi = frame.placement.inverse()
        self.iq1, self.iqn = i1, i_n
        self.lo1, self.hi1, self.lon, self.hin = ch.lo[i1], ch.hi[i1], ch.lo[i_n], ch.hi[i_n]
        self.w = ALIGN_WEIGHT * max(ch.reach, 1e-3)
        self.AUV = np.column_stack((anl, un, self.vn))
        self.Bc1 = self.B @ self.c1
        Q = ch.table()[0]
        K = len(Q)
        f = np.empty((K, 6))
        self.phi = np.empty(K)
        self.U = []
        self.V = []
        for k, q in enumerate(Q):
            pin.forwardKinematics(model, data, q)
            W = data.oMi[jn]
            f[k], self.phi[k], u, v = self._canon(W.translation, W.rotation)
            self.U.append(u)
            self.V.append(v)
        # score = |f|² − 2 f·x (+ |x|², the same for every entry), as one product G·(x, 1)
        f5 = f[:, :5]
        self.G = np.ascontiguousarray(np.column_stack((-2.0 * f5, (f5 * f5).sum(1))).T)   # (6, K), see _Chain.table
        return self

    def _canon(self, p, R):
        """Features (ρ, h, w z'), 1 of a joint-n frame (world position ``p``, rotation ``R``), its
        azimuth φ, and its uₙ, vₙ directions in the canonical frame (plain floats: 3-vectors
        cost less in Python than in NumPy)."""
        (dx, dy, dh), (z, u, v) = (self.B.dot(p) - self.Bc1).tolist(), self.B.dot(R).dot(self.AUV).T.tolist()
        phi = math.atan2(dy, dx)
        co, si = math.cos(phi), math.sin(phi)
        w = self.w
        return ((math.hypot(dx, dy), dh, w * (co * z[0] + si * z[1]), w * (co * z[1] - si * z[0]), w * z[2], 1.0), phi,
                (co * u[0] + si * u[1], co * u[1] - si * u[0], u[2]), (co * v[0] + si * v[1], co * v[1] - si * v[0], v[2]))

    def query(self, Ms):
        """(scores (K,), φ*, u*) of target ``Ms``: u* the canonical uₙ direction of its joint-n frame."""
        W = Ms * self.Fi
        x, phi, u, _ = self._canon(W.translation, W.rotation)
        return np.array(x).dot(self.G), phi, u

    def seed(self, q, k, phi, u):
        """Table configuration ``q`` (entry k, a copy) turned onto the target: first joint by the
        azimuth difference, last joint about its axis (wrapped by 2π or clipped into the range)."""
        i = self.iq1
        q[i] = _wrap(q[i] + phi - self.phi[k], self.lo1, self.hi1)
        U, V = self.U[k], self.V[k]
        d = math.atan2(V[0] * u[0] + V[1] * u[1] + V[2] * u[2], U[0] * u[0] + U[1] * u[1] + U[2] * u[2])
        i = self.iqn
        q[i] = _wrap(q[i] + d, self.lon, self.hin)
        return q


def _wrap(x, lo, hi):
    """x moved by a multiple of 2π into [lo, hi] if possible, else clipped."""
    if x < lo:
        x += 2.0 * math.pi * math.ceil((lo - x) / (2.0 * math.pi))
    elif x > hi:
        x -= 2.0 * math.pi * math.ceil((x - hi) / (2.0 * math.pi))
    return min(max(x, lo), hi)


_last = [lambda: None, -1, None]   # (weakref to the last robot, fid, chain): skips the dict lookups


def _chain(robot, fid: int) -> _Chain:
    last = _last
    if last[0]() is robot and last[1] == fid:
        return last[2]
    d = _CHAINS.get(robot)
    if d is None:
        d = _CHAINS[robot] = {}
    ch = d.get(fid)
    if ch is None:
        ch = d[fid] = _Chain(robot, fid)
    last[0], last[1], last[2] = weakref.ref(robot), fid, ch
    return ch


# ------------------------------------------------------------------------------ targets
class _Target:
    """One target: kind, T* (``pin.SE3``), p* (3,), R* (3, 3), tolerances, task dimension m,
    and the seed-table features x = T*[:3].ravel() (12,) for a pose, p* or R* alone otherwise.

    Pose errors are the body twist e = log₆(T(q)⁻¹ T*) = (v; ω) with the LOCAL Jacobian;
    ‖ω‖ is the rotation error and the position error is ‖t‖ of T(q)⁻¹ T* (= ‖p* − p‖), while
    v = V(ω)⁻¹ t with ‖V(ω)⁻¹‖ ≤ (1 + ‖ω‖)², so ‖e‖² ≤ tsum = tol_p²(1 + tol_r)² + tol_r² is
    necessary for convergence: the kernel checks the errors exactly only then.  A position is
    p* − p (world, LOCAL_WORLD_ALIGNED rows), a rotation log₃(Rᵀ R*) (LOCAL rows)."""

    __slots__ = ("kind", "mode", "m", "Ms", "ps", "Rs", "tol_p", "tol_r", "tp2", "tr2", "tsum", "x")

    def __init__(self, mode, tgt, tol_p, tol_r, x=None):
        self.mode = mode
        self.kind = _KIND[mode]
        self.tol_p = tol_p
        self.tol_r = tol_r
        self.tp2 = tol_p * tol_p
        self.tr2 = tol_r * tol_r
        self.tsum = (self.tp2 * (1.0 + tol_r) ** 2 + self.tr2) * (1.0 + 1e-12)
        self.Ms = None
        if mode == "pose":
            self.m = 6
            self.Ms = tgt
            self.ps = tgt.translation
            self.Rs = tgt.rotation
            self.x = tgt.homogeneous.ravel() if x is None else x
        elif mode == "position":
            self.m = 3
            self.ps = np.asarray(tgt, dtype=float)
            self.Rs = None
            self.x = np.append(self.ps, 1.0)
        else:
            self.m = 3
            self.ps = None
            self.Rs = np.ascontiguousarray(tgt, dtype=float)
            self.x = self.Rs.reshape(9)

    def errors(self, ch, q):
        """(pos_err m, rot_err rad) at q (Pinocchio FK); 0.0 for the unchecked part."""
        pin.framesForwardKinematics(ch.model, ch.data, q)
        M = ch.data.oMf[ch.fid]
        pe = re = 0.0
        if self.kind != _ORIENTATION:
            d = self.ps - M.translation
            pe = math.sqrt(d.dot(d))
        if self.kind != _POSITION:
            w = _log3(M.rotation.T.dot(self.Rs))
            re = math.sqrt(w.dot(w))
        return pe, re

    def lin(self, ch, q):
        """(J (m, n), e (m,), pos_err², rot_err²) at q, in the kernel's frames; leaves FK and
        the joint Jacobians in ch.data."""
        model, data, fid = ch.model, ch.data, ch.fid
        _cjj(model, data, q)
        M = _ufp(model, data, fid)
        if self.kind == _POSE:
            Mt = M.actInv(self.Ms)
            e = _log6(Mt).vector
            t = Mt.translation
            w = e[3:]
            return _gfj(model, data, fid, LOCAL), e, t.dot(t), w.dot(w)
        if self.kind == _POSITION:
            ep = self.ps - M.translation
            return _gfj(model, data, fid, LWA)[:3], ep, ep.dot(ep), 0.0
        ew = _log3(M.rotation.T.dot(self.Rs))
        return _gfj(model, data, fid, LOCAL)[3:], ew, 0.0, ew.dot(ew)

    def scores(self, ch):
        """Seed-table distance of every table entry to this target (up to a constant)."""
        return self.x.dot(ch.table()[1 + self.kind])


# ------------------------------------------------------------------------------ one attempt
def _attempt(ch, tg, q, deadline):
    """Damped Gauss–Newton from ``q`` (the kernel; see the module docstring).

    Returns (q, converged, iterations, pos_err², rot_err², best_q, best_E): the last iterate
    with its squared errors, and the iterate of least ‖e‖² seen."""
    model, data, fid, lo, hi = ch.model, ch.data, ch.fid, ch.lo, ch.hi
    kind, Ms, ps, Rs, tp2, tr2, tsum = tg.kind, tg.Ms, tg.ps, tg.Rs, tg.tp2, tg.tr2, tg.tsum
    m = tg.m
    A, AF, Ad = ch.A[m], ch.AF[m], ch.Ad[m]
    ref_E = best_E = math.inf
    best_q = q
    stall = 0
    it = 0
    pe2 = re2 = 0.0
    while it < MAX_ITER:
        it += 1
        _cjj(model, data, q)
        if kind == _POSE:
            Mt = _ufp(model, data, fid).actInv(Ms)
            e = _log6(Mt).vector
            E = e.dot(e)
            if E <= tsum:             # necessary for convergence (see _Target): check exactly
                t = Mt.translation
                w = e[3:]
                pe2 = t.dot(t)
                re2 = w.dot(w)
                if pe2 <= tp2 and re2 <= tr2:
                    return q, True, it, pe2, re2, q, E
            J = _gfj(model, data, fid, LOCAL)
        elif kind == _POSITION:
            e = ps - _ufp(model, data, fid).translation
            E = pe2 = e.dot(e)
            if pe2 <= tp2:
                return q, True, it, pe2, 0.0, q, E
            J = _gfj(model, data, fid, LWA)[:3]
        else:
            e = _log3(_ufp(model, data, fid).rotation.T.dot(Rs))
            E = re2 = e.dot(e)
            if re2 <= tr2:
                return q, True, it, 0.0, re2, q, E
            J = _gfj(model, data, fid, LOCAL)[3:]
        if E < best_E:
            best_E = E
            best_q = q
        if E < 0.9 * ref_E:
            ref_E = E
            stall = 0
        else:
            stall += 1
            if stall >= STALL:
                break
        if not it & 3 and _clock() > deadline:  # every 4th iteration: the clock costs ~0.4 µs
            break
        lam = LAMBDA0 + K_DAMP * E
        np.dot(J, J.T, out=A)
        Ad += lam
        x, info = dposv(AF, e, overwrite_a=1)[1:]
        if info:  # not positive definite (NaN/inf): give up this attempt
            break
        qn = q + x.dot(J)
        qc = _uclip(qn, lo, hi)
        if qc.tobytes() != qn.tobytes():      # (byte comparison: ~20× cheaper than (qc != qn).any())
            # active set: the joints the step pushes past a limit stay where they are; the
            # other joints take the step (recomputed without them), then it is clipped
            J[:, qc != qn] = 0.0
            np.dot(J, J.T, out=A)
            Ad += lam
            x, info = dposv(AF, e, overwrite_a=1)[1:]
            if info:
                break
            qc = _uclip(q + x.dot(J), lo, hi)
        q = qc
    return q, False, it, pe2, re2, best_q, best_E


# ------------------------------------------------------------------------------ secondary objectives
def _refine_posture(ch, tg, q, q_ref, deadline):
    """Second phase for redundant arms: from ``q`` (a solution, or a closed-form seed),
    minimise ½‖q − q_ref‖² along the self-motion (null space of the task) while Gauss–Newton
    keeps the task error at zero.  A joint at its limit that the step would push past it is
    frozen (its column of J and its share of the posture pull are dropped) and the step
    recomputed: with a one-dimensional self-motion the optimum then lies where that joint sits
    at its limit.  Other steps are clipped.

    Returns (q, pos_err², rot_err², iterations): the last iterate that meets the tolerances
    and its errors, or (None, …) if no iterate did."""
    lo, hi = ch.lo, ch.hi
    m = tg.m
    one_dim = ch.n - m == 1
    A, AF, Ad = ch.A[m], ch.AF[m], ch.Ad[m]
    tp2, tr2 = tg.tp2, tg.tr2
    h_lo, h_hi = SECANT_RANGE
    good = None
    gpe2 = gre2 = math.inf
    it = 0
    p_prev = None     # last null-space direction (unnormalised) and its g, s
    g_prev = s_prev = 0.0
    h = 1.0
    lin = tg.lin
    while it < NULL_EXTRA:
        J, e, pe2, re2 = lin(ch, q)
        it += 1
        ok = pe2 <= tp2 and re2 <= tr2
        if ok:
            good, gpe2, gre2 = q, pe2, re2
        elif not it & 3 and _clock() > deadline:
            break
        lam = LAMBDA0 + K_DAMP * (pe2 + re2)
        frozen = None
        while True:
            np.dot(J, J.T, out=A)
            Ad += lam
            x, info = dposv(AF, e, overwrite_a=1)[1:]   # AF now holds the Cholesky factor
            if info:
                return good, gpe2, gre2, it
            dq = x.dot(J)
            z = q_ref - q          # N (q_ref − q − Δq) = N (q_ref − q) + O(λ): Δq lies in the row space
            if frozen is not None:
                z[frozen] = 0.0
            p = z - dpotrs(AF, J.dot(z))[0].dot(J)     # N z: projection on the null space
            g = math.sqrt(p.dot(p))
            if one_dim and frozen is None and g > 0.0:
                # secant step along the self-motion direction t = p/g: g = tᵀ(q_ref − q) is minus
                # the derivative of the cost along t; its change per unit move estimates the curvature
                if p_prev is not None:
                    if p.dot(p_prev) < 0.0:
                        g = -g
                    if abs(s_prev) > 1e-12:
                        hk = (g_prev - g) / s_prev
                        h = min(hk, h_hi) if hk >= h_lo else 1.0
                s = g / h
                if abs(s) > NULL_STEP:
                    s = math.copysign(NULL_STEP, s)
                n2 = abs(s)
                qn = q + dq + p * (s / g)
            else:
                s = 0.0
                n2 = g
                qn = q + dq + (p if g <= NULL_STEP else p * (NULL_STEP / g))  # long moves leave the linearisation
            qc = _uclip(qn, lo, hi)
            if frozen is not None or qc.tobytes() == qn.tobytes():
                break
            out = (qc != qn) & ((q == lo) | (q == hi))   # at a limit and pushed past it
            if not out.any():
                # the null-space move crosses a limit: shorten it so that the first joint to
                # cross stops on its limit (clipping the whole step would spoil the pose)
                step = qn - q - dq
                base = q + dq
                with np.errstate(divide="ignore", invalid="ignore"):
                    sig = np.where(step > 0.0, (hi - base) / step, np.where(step < 0.0, (lo - base) / step, np.inf))
                sig = min(max(float(sig.min()), 0.0), 1.0)
                qn = base + sig * step
                s *= sig
                n2 *= sig
                qc = _uclip(qn, lo, hi)
                break
            frozen = out                       # active set: freeze, recompute once
            J = J.copy()
            J[:, out] = 0.0
        if ok and n2 < NULL_TOL:
            break
        if s != 0.0:
            clipped = qc.tobytes() != qn.tobytes()
            s_prev = p.dot(qc - q) / g if clipped else s   # the move made along t = p/g
            if ok and clipped and abs(s_prev) < 0.1 * n2:
                break   # a joint limit blocks the self-motion: constrained optimum
            p_prev, g_prev = (p if g > 0.0 else -p), g     # p_prev oriented like t
        else:
            p_prev = None                      # the secant memory is void after a frozen step
        q = qc
    else:
        pe, re = tg.errors(ch, q)
        if pe * pe <= tp2 and re * re <= tr2:
            good, gpe2, gre2 = q, pe * pe, re * re
    return good, gpe2, gre2, it


class _Swivel:
    """Null-space step that moves the elbow swivel angle to ``target`` (rad)."""

    def __init__(self, ch: _Chain, frames, target: float):
        self.ch = ch
        self.ids = [ch.robot.frame_id(f) for f in frames]
        self.target = target
        self.err = np.inf

    def __call__(self, q, dq1, J, cfac):
        model, data = self.ch.model, self.ch.data
        pts = [pin.updateFramePlacement(model, data, i).translation for i in self.ids]
        try:
            phi, grads = swivel_from_points(*pts)
        except ValueError:  # straight arm: the swivel angle is undefined here
            self.err = np.inf
            return np.zeros_like(q)
        j = np.zeros(len(q))
        for g, i in zip(grads, self.ids):
            j += g @ pin.getFrameJacobian(model, data, i, LWA)[:3]
        d = self.target - phi
        d = math.atan2(math.sin(d), math.cos(d))
        self.err = abs(d)
        nj = j - J.T @ dpotrs(cfac, J @ j)[0]          # N jᵀ
        den = float(j @ nj) + 1e-9
        return nj * ((d - float(j @ dq1)) / den)


def _refine(ch, tg, q, secondary, deadline):
    """Second phase toward a general secondary objective (the swivel angle): from a solution
    ``q``, move in the null space of the primary task, Gauss–Newton corrected (the pose error
    may grow in between and is driven back).  Returns the last iterate that meets the
    tolerances (the phase-1 solution if none does), and the iterations used."""
    good = q
    it = 0
    while it < NULL_EXTRA and _clock() <= deadline:
        J, e, pe2, re2 = tg.lin(ch, q)
        it += 1
        ok = pe2 <= tg.tp2 and re2 <= tg.tr2
        if ok:
            good = q
        A = J @ J.T
        A.flat[:: A.shape[0] + 1] += LAMBDA0 + K_DAMP * (pe2 + re2)
        cfac, x, info = dposv(A, e)
        if info != 0:
            break
        dq = J.T @ x
        dq2 = secondary(q, dq, J, cfac)
        n2 = math.sqrt(dq2 @ dq2)
        if ok and n2 < NULL_TOL:
            break
        if n2 > NULL_STEP:  # long null-space moves leave the linearisation: shorten them
            dq2 *= NULL_STEP / n2
        q = np.minimum(np.maximum(q + dq + dq2, ch.lo), ch.hi)
    else:
        pe, re = tg.errors(ch, q)
        if pe * pe <= tg.tp2 and re * re <= tg.tr2:
            good = q
    return good, it


def _settle_swivel(robot, ch, tg, target, sw, q_ref, qs, pe, re, analytic, msg):
    """After the null-space refinement: if the swivel target is still off, try the closed form
    at that angle (another branch of the self-motion may hold it); report what remains.
    Returns (q, pos_err, rot_err, seed tag or "", message)."""
    off = _swivel_offset(ch, sw, qs)
    if off <= 1e-6:
        return qs, pe, re, "", msg
    tried = ""
    if analytic is not False:
        ref = ch.default_ref if q_ref is None else q_ref
        S, _ = _analytic_seeds(robot, ch, tg.mode, target, ref, sw.target)
        cf = _analytic_module()
        if cf is not None and ch.fid == robot.tool_id and cf.has_analytic(robot):
            tried = " and the closed form has no solution at that angle inside the limits"
        for cand in S:
            pe_c, re_c = tg.errors(ch, cand)
            if pe_c * pe_c <= tg.tp2 and re_c * re_c <= tg.tr2:
                return cand, pe_c, re_c, "analytic", "converged from an analytic seed at the requested swivel angle"
    msg += (f"; swivel angle off by {off:.3g} rad: not reachable along this solution's self-motion within the "
            f"joint limits{tried} (the hand pose is exact)")
    return qs, pe, re, "", msg


def _swivel_offset(ch, sw: _Swivel, q) -> float:
    """|wrapped swivel(q) − target| (rad); inf where the swivel is undefined (straight arm)."""
    pin.framesForwardKinematics(ch.model, ch.data, q)
    pts = [ch.data.oMf[i].translation for i in sw.ids]
    try:
        phi = swivel_from_points(*pts)[0]
    except ValueError:
        return float("inf")
    d = sw.target - phi
    return abs(math.atan2(math.sin(d), math.cos(d)))


# ------------------------------------------------------------------------------ targets
def _rigid_se3(T):
    """``pin.SE3`` of a float64 4×4 ``T`` that is rigid to 1e-12 (checked in plain Python, a
    few µs cheaper than :func:`~anthroarm.ik.qp.targets.as_se3`), else None: then ``as_se3``
    decides (re-orthonormalises within its tolerance, or raises naming the defect)."""
    if T.dtype != np.float64:
        return None
    a, b, c, d = T.tolist()
    if d != [0.0, 0.0, 0.0, 1.0] or not math.isfinite(sum(a) + sum(b) + sum(c)):
        return None
    err = max(abs(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1.0), abs(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] - 1.0),
              abs(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - 1.0), abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]),
              abs(a[0] * c[0] + a[1] * c[1] + a[2] * c[2]), abs(b[0] * c[0] + b[1] * c[1] + b[2] * c[2]))
    det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
           + a[2] * (b[0] * c[1] - b[1] * c[0]))
    if err > 1e-12 or det < 0.0:
        return None
    return pin.SE3(T)


def _parse(robot, T, mode):
    """-> (mode, batch: bool, list of targets)."""
    if mode not in (None, "pose", "position", "orientation"):
        raise ValueError(f"mode must be None, 'pose', 'position' or 'orientation', got {mode!r}")
    if isinstance(T, pin.SE3):
        T = T.homogeneous
    arr = np.asarray(T, dtype=float)
    sh = arr.shape
    if sh == (4, 4) or (arr.ndim == 3 and sh[1:] == (4, 4)):
        m = mode or "pose"
        batch = arr.ndim == 3
        items = arr if batch else [arr]
        out = []
        for i, a in enumerate(items):
            name = f"T[{i}]" if batch else "T"
            M = as_se3(a, name)
            out.append(M if m == "pose" else (M.translation.copy() if m == "position" else M.rotation.copy()))
        return m, batch, out
    if mode == "position" and arr.ndim == 2 and sh[1] == 3:
        return "position", True, [as_position(a, f"T[{i}]") for i, a in enumerate(arr)]
    if sh == (3,):
        if mode not in (None, "position"):
            raise ValueError(f"a (3,) target is a position; mode={mode!r} needs a 4x4 pose")
        return "position", False, [as_position(arr, "T")]
    if sh == (3, 3) or (arr.ndim == 3 and sh[1:] == (3, 3)):
        if mode not in (None, "orientation"):
            raise ValueError(f"a 3x3 target is a rotation; mode={mode!r} needs a 4x4 pose")
        batch = arr.ndim == 3
        items = arr if batch else [arr]
        return "orientation", batch, [as_rotation(a, f"T[{i}]" if batch else "T") for i, a in enumerate(items)]
    if arr.ndim == 2 and sh[1] == 3 and mode is None:
        return "position", True, [as_position(a, f"T[{i}]") for i, a in enumerate(arr)]
    raise ValueError(f"target T must be a 4x4 pose, a position (3,), a rotation (3, 3), or a batch of them "
                     f"with a leading axis; got shape {sh}")


_ANALYTIC = []   # the closed-form module (or None), looked up once


def _analytic_module():
    if not _ANALYTIC:
        mod = None
        if importlib.util.find_spec("anthroarm.ik.closed_form") is not None:
            from . import closed_form

            if hasattr(closed_form, "analytic") and hasattr(closed_form, "has_analytic"):
                mod = closed_form
        _ANALYTIC.append(mod)
    return _ANALYTIC[0]


def _analytic_cheap(robot, fid) -> bool:
    """True when ``analytic="auto"`` puts the closed form first: the robot has one for this
    frame and a call costs about as much as a few Gauss–Newton iterations — the scalar kernels
    of the six-joint book arms (~10–20 µs), the human arm's swivel grid only with the compiled
    kernel of :mod:`.analytic_c` (~15 µs; ~0.5 ms in NumPy).  Fixed per robot and environment,
    so the same call gives the same answer."""
    cf = _analytic_module()
    try:
        if cf is None or fid != robot.tool_id or not cf.has_analytic(robot):
            return False
        if robot.spec.name != "human_arm7":
            return True
        from . import analytic_c

        return bool(analytic_c.enabled() and analytic_c.compiler() is not None)
    except Exception:  # a seed source only
        return False


def _analytic_seeds(robot, ch, mode, target, ref, swivel, grid=None, T=None):
    """Closed-form solutions (K, nq), the one nearest ``ref`` first, or an empty array."""
    if mode != "pose" or ch.fid != robot.tool_id:
        return np.zeros((0, ch.n)), ""
    cf = _analytic_module()
    if cf is None or not cf.has_analytic(robot):
        return np.zeros((0, ch.n)), ""
    try:
        kw = {}
        if robot.name == "human_arm7":
            if swivel is not None:
                kw["swivel"] = swivel
            elif grid is not None:
                kw["swivel"] = grid
        res = cf.analytic(robot, target.homogeneous if T is None else T, **kw)
        S = np.asarray(res.solutions, dtype=float).reshape(-1, ch.n)
    except Exception as exc:  # a seed source only: never let it break the solve
        return np.zeros((0, ch.n)), f"analytic seed failed: {exc}"
    if len(S) > 1:
        D = S - ref
        c = (D * D).dot(np.ones(ch.n))
        k = int(c.argmin())
        if k:                                  # nearest first (the order of the others matters little)
            S[[0, k]] = S[[k, 0]]
    return S, ""


# ------------------------------------------------------------------------------ public API
def solve(robot, T, q0=None, frame=None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, max_time: float = 0.05,
          *, mode: str | None = None, max_restarts: int | None = None, rng=None, posture="auto",
          swivel: float | None = None, swivel_frames=None, analytic="auto", warm_start: bool = False):
    """Inverse kinematics of ``robot`` for target ``T`` (see the module docstring).

    Parameters
    ----------
    robot : anthroarm.Robot
    T : 4×4 pose (or ``pin.SE3``), position (3,), rotation (3, 3), or a batch with a leading axis N.
        World frame, metres.  ``ValueError`` for NaN, a wrong shape or a non-rigid transform.
    q0 : (nq,) or (N, nq), optional
        Initial guess (clipped into the limits).  Default: the nearest entry of the seed table
        (for a posture problem, nearest with a penalty on the distance to the posture).
    frame : str, optional
        Frame to place (default the tool); unknown names raise
        :class:`~anthroarm.errors.UnknownFrameError` listing the valid ones.
    tol_pos, tol_rot : float
        Success tolerances, m and rad.
    max_time : float
        Time budget per target, s of CPU time of the calling thread (restarts stop when it is
        spent); see :data:`_clock`.
    mode : None, "pose", "position", "orientation"
        Override the target kind (e.g. ``"position"`` with a 4×4 ``T`` uses its translation).
    max_restarts : int, optional
        Cap on restarts, i.e. seeds after the first (default: limited by ``max_time`` only).
    rng : int or numpy Generator, optional
        Seed of the random restarts (default 0: reproducible results).
    posture : "auto", None or (nq,)
        Reference posture for the null space of redundant arms; ``"auto"`` uses the comfortable
        posture for the human arm (``human_arm7``) and nothing otherwise.
    swivel : float, optional
        Elbow swivel angle (rad) for a human arm (overrides ``posture``); ``swivel_frames``
        = (shoulder, elbow, wrist) frame names for arms outside the catalog.
    analytic : "auto", True or False
        Closed-form seeds (see the module docstring).
    warm_start : bool
        Batch only: seed target i with the solution of target i − 1 (trajectories).

    Returns
    -------
    IKResult, or IKBatchResult for a batch.  Every returned q is within the joint limits.
    """
    fid = robot.frame_id(frame)
    ch = _chain(robot, fid)
    x = None
    if type(T) is np.ndarray and T.shape == (4, 4) and mode in (None, "pose") and (M := _rigid_se3(T)) is not None:
        mode, batch, targets = "pose", False, [M]
        x = T.ravel()
    else:
        mode, batch, targets = _parse(robot, T, mode)
    if not (type(tol_pos) is float and type(tol_rot) is float and type(max_time) is float   # the usual call
            and 0.0 < tol_pos < math.inf and 0.0 < tol_rot < math.inf and 0.0 < max_time < math.inf):
        for name, v in (("tol_pos", tol_pos), ("tol_rot", tol_rot), ("max_time", max_time)):
            if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a positive finite number, got {v!r}")
    if max_restarts is not None and (int(max_restarts) != max_restarts or max_restarts < 0):
        raise ValueError(f"max_restarts must be a non-negative integer, got {max_restarts!r}")
    if analytic not in ("auto", True, False):
        raise ValueError(f"analytic must be 'auto', True or False, got {analytic!r}")
    # seeds
    if q0 is None:
        Q0 = None
    else:
        Q0 = robot.check_q(q0, name="q0")
        if Q0.ndim == 2 and (not batch or len(Q0) != len(targets)):
            raise ValueError(f"q0 of shape {Q0.shape} needs a batch of {len(Q0)} targets")
    # secondary objective (redundant arms)
    if isinstance(posture, str):
        if posture != "auto":
            raise ValueError(f"posture must be 'auto', None or a configuration, got {posture!r}")
        q_ref = ch.default_ref if robot.name in ("human_arm7",) else None
    elif posture is None:
        q_ref = None
    else:
        q_ref = ch.clip(robot.check_q(posture, name="posture"))
    sw_frames = None
    if swivel is not None:
        swivel = float(swivel)
        if not math.isfinite(swivel):
            raise ValueError(f"swivel must be finite, got {swivel}")
        sw_frames = _swivel_frames(robot, swivel_frames)
    redundant = ch.n > (6 if mode == "pose" else 3)
    # the restart generator is created on first use (most solves need no restart)
    gen = [rng] if isinstance(rng, np.random.Generator) else [None, 0 if rng is None else rng]

    q_ref_sec = q_ref if redundant and swivel is None else None
    sw_sec = (sw_frames, swivel) if (redundant and swivel is not None) else None
    if not batch:
        return _solve_one(robot, ch, _Target(mode, targets[0], float(tol_pos), float(tol_rot), x), targets[0], Q0,
                          max_time, max_restarts, gen, q_ref_sec, sw_sec, analytic)
    tgs = [_Target(mode, t, float(tol_pos), float(tol_rot), x) for t in targets]
    if Q0 is None:
        seeds = [None] * len(targets)
    else:
        seeds = [Q0[i] if Q0.ndim == 2 else Q0 for i in range(len(targets))]
    closed_form_first = analytic is True or (analytic == "auto" and Q0 is None and ch.analytic_first and mode == "pose")
    if batch and not warm_start and len(targets) >= LOCKSTEP_MIN and not closed_form_first:
        results = _solve_lockstep(robot, ch, tgs, targets, seeds, max_time, max_restarts, gen, q_ref_sec, sw_sec,
                                  analytic)
    else:
        results = []
        prev = None
        for i, tgt in enumerate(targets):
            seed = prev if (warm_start and prev is not None and Q0 is None) else seeds[i]
            res = _solve_one(robot, ch, tgs[i], tgt, seed, max_time, max_restarts, gen, q_ref_sec, sw_sec,
                             analytic)
            results.append(res)
            prev = res.q
    return IKBatchResult(
        q=np.array([r.q for r in results]).reshape(len(results), ch.n),
        success=np.array([r.success for r in results], dtype=bool),
        status=[r.status for r in results],
        pos_err=np.array([r.pos_err for r in results]), rot_err=np.array([r.rot_err for r in results]),
        iterations=np.array([r.iterations for r in results], dtype=int),
        restarts=np.array([r.restarts for r in results], dtype=int),
        messages=[r.message for r in results], mode=mode)


class _TableSeeds:
    """The seed-table entries nearest a target, nearest first (copies; for a pose target on a
    chain with an :class:`_Aligned` table, turned onto the target): the nearest by one
    ``argmin``, the next :data:`TABLE_SEEDS` − 1 sorted when first needed; then ``None``."""

    __slots__ = ("ch", "sc", "k0", "order", "i", "al", "phi", "u")

    def __init__(self, ch, tg, q_ref):
        al = ch.aligned() if tg.kind == _POSE else None
        if al is not None:
            sc, self.phi, self.u = al.query(tg.Ms)
        else:
            sc = tg.scores(ch)
        if q_ref is not None:
            sc = sc + ch.posture_penalty(q_ref)
        self.al = al
        self.ch = ch
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
        q = self.ch.table()[0][k].copy()
        return q if self.al is None else self.al.seed(q, k, self.phi, self.u)


def _solve_lockstep(robot, ch, tgs, targets, seeds, max_time, max_restarts, gen, q_ref, sw, analytic):
    """Batch form: every target iterates the same damped Gauss–Newton step together, the linear
    algebra vectorised over the batch (``np.linalg.solve`` on (N, m, m)); Pinocchio's FK and
    Jacobians are still one call per target.  Converged targets leave the batch; a target whose
    attempt stalls restarts from its next seed (the seed table's next nearest entry, then a
    random configuration), up to :data:`LOCKSTEP_ATTEMPTS` attempts, after which it is handed to
    the one-target solver (all its seeds, restarts and the time budget).  Same answers'
    quality, less time per target."""
    model, data, fid = ch.model, ch.data, ch.fid
    N, n = len(tgs), ch.n
    kind = tgs[0].kind
    m = tgs[0].m
    tp2, tr2 = tgs[0].tp2, tgs[0].tr2
    lo, hi = ch.lo, ch.hi
    # first seeds: q0, else the nearest table entry (vectorised over the batch)
    tseeds = [None] * N
    Q = np.empty((N, n))
    need = [k for k in range(N) if seeds[k] is None]
    if need:
        for k in need:
            tseeds[k] = _TableSeeds(ch, tgs[k], q_ref)
            Q[k] = tseeds[k].next()
    for k in range(N):
        if seeds[k] is not None:
            Q[k] = seeds[k]
    Q = ch.clip(Q)
    J = np.empty((N, m, n))
    E = np.empty((N, m))
    TR = np.empty((N, 3))
    Ms = [tg.Ms for tg in tgs]
    PE2 = np.zeros(N)
    RE2 = np.zeros(N)
    its = np.zeros(N, dtype=int)
    att_it = np.zeros(N, dtype=int)
    attempts = np.ones(N, dtype=int)
    best = np.full(N, np.inf)
    stall = np.zeros(N, dtype=int)
    converged = np.zeros(N, dtype=bool)
    max_attempts = LOCKSTEP_ATTEMPTS if max_restarts is None else min(LOCKSTEP_ATTEMPTS, int(max_restarts) + 1)
    active = np.arange(N)
    eye = np.eye(m)
    while active.size:
        if kind == _POSE:                     # Pinocchio: one call per target
            for k in active:
                _cjj(model, data, Q[k])
                Mt = _ufp(model, data, fid).actInv(Ms[k])
                E[k] = _log6(Mt).vector
                TR[k] = Mt.translation
                J[k] = _gfj(model, data, fid, LOCAL)
            PE2[active] = (TR[active] ** 2).sum(1)
            RE2[active] = (E[active, 3:] ** 2).sum(1)
        elif kind == _POSITION:
            for k in active:
                _cjj(model, data, Q[k])
                E[k] = tgs[k].ps - _ufp(model, data, fid).translation
                J[k] = _gfj(model, data, fid, LWA)[:3]
            PE2[active] = (E[active] ** 2).sum(1)
        else:
            for k in active:
                _cjj(model, data, Q[k])
                E[k] = _log3(_ufp(model, data, fid).rotation.T.dot(tgs[k].Rs))
                J[k] = _gfj(model, data, fid, LOCAL)[3:]
            RE2[active] = (E[active] ** 2).sum(1)
        its[active] += 1
        att_it[active] += 1
        ok = (PE2[active] <= tp2) & (RE2[active] <= tr2)
        converged[active[ok]] = True
        active = active[~ok]
        if not active.size:
            break
        Ee = (E[active] ** 2).sum(1)
        improved = Ee < 0.9 * best[active]
        best[active] = np.where(improved, Ee, best[active])
        stall[active] = np.where(improved, 0, stall[active] + 1)
        ended = (stall[active] >= STALL) | (att_it[active] >= MAX_ITER)
        if ended.any():
            ek = active[ended]
            retry = ek[attempts[ek] < max_attempts]
            for k in retry:                   # next seed: the next table entry, then random
                if tseeds[k] is None:
                    tseeds[k] = _TableSeeds(ch, tgs[k], q_ref)
                qn = tseeds[k].next()
                Q[k] = ch.random(gen) if qn is None else qn
            attempts[retry] += 1
            att_it[retry] = 0
            stall[retry] = 0
            best[retry] = np.inf
            stepping = active[~ended]          # retried targets are evaluated first, next round
            active = np.concatenate([stepping, retry])
        else:
            stepping = active
        if stepping.size:                     # vectorised damped Gauss–Newton step
            Js = J[stepping]
            Es = E[stepping]
            lam = (LAMBDA0 + K_DAMP * (Es ** 2).sum(1))[:, None, None]
            Jt = Js.transpose(0, 2, 1)
            try:
                x = np.linalg.solve(Js @ Jt + lam * eye, Es[..., None])
            except np.linalg.LinAlgError:    # a singular system: hand those targets over
                active = np.setdiff1d(active, stepping)
                continue
            Qs = Q[stepping]
            Qn = Qs + (Jt @ x)[..., 0]
            Qc = np.minimum(np.maximum(Qn, lo), hi)
            out = Qc != Qn
            rows = out.any(axis=1)
            if rows.any():                    # active set (see _attempt), for the rows that need it
                Jr = Js[rows] * ~out[rows][:, None, :]
                Jrt = Jr.transpose(0, 2, 1)
                try:
                    xr = np.linalg.solve(Jr @ Jrt + lam[rows] * eye, Es[rows][..., None])
                    Qr = Qs[rows] + (Jrt @ xr)[..., 0]
                    Qc[rows] = np.minimum(np.maximum(Qr, lo), hi)
                except np.linalg.LinAlgError:
                    pass
            Q[stepping] = Qc
    results = []
    for k in range(N):
        restarts = int(attempts[k] - 1)
        tg = tgs[k]
        if converged[k] and q_ref is None and sw is None:
            tag = ("q0" if seeds[k] is not None else "table") if restarts == 0 else "restart"
            results.append(IKResult(Q[k].copy(), True, "success", math.sqrt(PE2[k]), math.sqrt(RE2[k]), int(its[k]),
                                    restarts, f"converged from a {tag} seed (batch)", tg.mode, tag))
        elif converged[k]:                    # redundant arm: null-space settling, one target at a time
            r = _solve_one(robot, ch, tg, targets[k], Q[k], max_time, max_restarts, gen, q_ref, sw, analytic)
            r.iterations += int(its[k])
            r.restarts += restarts
            results.append(r)
        else:                                 # stalled LOCKSTEP_ATTEMPTS times: the full one-target solver
            r = _solve_one(robot, ch, tg, targets[k], seeds[k], max_time, max_restarts, gen, q_ref, sw, analytic)
            r.iterations += int(its[k])
            results.append(r)
    return results


def _solve_one(robot, ch, tg, target, seed, max_time, max_restarts, gen, q_ref, sw, analytic):
    t0 = _clock()
    deadline = t0 + max_time
    # reachability (a sufficient test for "unreachable": farther than the summed link offsets)
    out_of_reach = ""
    if tg.kind != _ORIENTATION:
        dist = math.sqrt(tg.ps.dot(tg.ps))
        if dist > ch.reach + tg.tol_p:
            out_of_reach = (f"target is {dist:.4g} m from the base origin but the chain reaches at most "
                            f"{ch.reach:.4g} m (sum of its link offsets)")
    # seeds: closed form (analytic=True, or "auto" where it is cheap and no q0 is given), q0,
    # the seed table nearest first, uniform random
    ana = None
    ana_i = 0
    note = ""
    if not out_of_reach and (analytic is True or (analytic == "auto" and seed is None and ch.analytic_first)):
        ref = q_ref if q_ref is not None else (ch.default_ref if seed is None else seed)
        ana, note = _analytic_seeds(robot, ch, tg.mode, target, ref, sw[1] if sw else None, HUMAN_GRID,
                                    tg.x.reshape(4, 4) if tg.kind == _POSE else None)
    table = None      # seed-table entries, nearest first (made when needed)
    total_it = 0
    best_q, best_E = None, math.inf
    restarts = 0
    attempt = 0
    secondary = None
    while True:
        if ana is not None and ana_i < len(ana):
            q, seeds_tag = ana[ana_i].copy(), "analytic"
            ana_i += 1
        elif seed is not None:
            q, seeds_tag = np.minimum(np.maximum(np.asarray(seed, dtype=float), ch.lo), ch.hi), "q0"
            seed = None
        else:
            if table is None:
                table = _TableSeeds(ch, tg, q_ref)
            q, seeds_tag = table.next(), "table"
            if q is None:
                q, seeds_tag = ch.random(gen), "restart"
        if attempt:
            restarts += 1
        if seeds_tag == "analytic" and q_ref is not None and sw is None:
            # a closed-form solution: straight to the posture phase, which verifies it
            qs, pe2, re2, it = _refine_posture(ch, tg, q, q_ref, deadline + 0.5 * max_time)
            total_it += it
            attempt += 1
            if qs is not None:
                return IKResult(qs, True, "success", math.sqrt(pe2), math.sqrt(re2), total_it, restarts,
                                "converged from an analytic seed", tg.mode, seeds_tag)
        qs, ok, it, pe2, re2, bq, bE = _attempt(ch, tg, q, deadline)
        total_it += it
        attempt += 1
        if bE < best_E:
            best_q, best_E = bq, bE
        if ok:
            pe, re = math.sqrt(pe2), math.sqrt(re2)
            msg = f"converged from a {seeds_tag} seed"
            if sw is not None:
                secondary = _Swivel(ch, sw[0], sw[1])
                qs, it2 = _refine(ch, tg, qs, secondary, deadline + 0.5 * max_time)
                total_it += it2
                pe, re = tg.errors(ch, qs)
                qs, pe, re, tag, msg = _settle_swivel(robot, ch, tg, target, secondary, q_ref, qs, pe, re, analytic,
                                                      msg)
                seeds_tag = tag or seeds_tag
            elif q_ref is not None:
                qs2, pe2, re2, it2 = _refine_posture(ch, tg, qs, q_ref, deadline + 0.5 * max_time)
                total_it += it2
                if qs2 is not None:
                    qs, pe, re = qs2, math.sqrt(pe2), math.sqrt(re2)
            return IKResult(qs, True, "success", pe, re, total_it, restarts, msg, tg.mode, seeds_tag)
        if out_of_reach and attempt >= 3:
            break
        if analytic == "auto" and ana is None and not out_of_reach and attempt >= ANALYTIC_AFTER:
            ana, note = _analytic_seeds(robot, ch, tg.mode, target, best_q, sw[1] if sw else None, HUMAN_GRID)
        if _clock() > deadline:
            break
        if max_restarts is not None and restarts >= max_restarts:
            break
    if best_q is not None:
        q = best_q
    pe, re = tg.errors(ch, q)
    el = (_clock() - t0) * 1e3
    if out_of_reach:
        status, why = "out_of_reach", out_of_reach
    else:
        status = "not_converged"
        why = (f"no configuration within the joint limits reached tol_pos={tg.tol_p:g} m / "
               f"tol_rot={tg.tol_r:g} rad after {total_it} iterations, {restarts} restarts, {el:.1f} ms CPU "
               f"(max_time {max_time * 1e3:g} ms); the target is probably outside the joint-limited workspace")
    msg = f"{why}; closest pose found: pos_err {pe:.3g} m, rot_err {re:.3g} rad" + (f"; {note}" if note else "")
    return IKResult(q, False, status, pe, re, total_it, restarts, msg, tg.mode, seeds_tag)
