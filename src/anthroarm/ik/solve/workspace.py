"""Per-(robot, frame) data of :func:`anthroarm.ik.solve`, built from ``robot.chain``, and the
per-thread workspaces.

Thread-safety contract: :class:`Shared` (limits, reach, seed tables) is immutable once built
(the tables are built once under a lock); everything a solve writes — the ``pin.Data`` and the
kernel's preallocated arrays — lives in a :class:`Workspace` of the calling thread
(``threading.local``), including the buffers of the attempt kernel (:class:`.lm.Buffers`).
So one Robot may be solved for from several threads at once.

Memory: the cache maps a Robot *weakly* to its Shared objects, and nothing in them refers to
the Robot (only to its ``pin.Model`` and ``Chain``), so a Robot dropped by the caller is freed
with its tables.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pinocchio as pin

from ...chain import CONTINUOUS, PRISMATIC
from .. import closed_form
from ..fk import PathFrames
from ..qp.tasks.posture import comfortable_posture, has_comfortable_posture
from . import seeds
from .lm import Buffers


class Shared:
    """What every thread solving for (robot, frame) shares, in θ — the independent joints'
    positions in v order (rad or m; :meth:`anthroarm.chain.Chain.angles` restricted to
    ``chain.independent``):

    * ``lo``, ``hi``: joint limits (±inf for a continuous joint);
    * ``lo_s``, ``hi_s``: the sampling box of seeds (:attr:`anthroarm.chain.Chain.sampling_box`);
      joints off the frame's path (no effect on it) are pinned to the reference posture;
    * ``on_path``: (n,) bool, the joints that move the frame (a mimic joint counts for its source);
    * ``reach``: bound on the frame's distance from the base (m, :meth:`~anthroarm.chain.Chain.reach`);
    * ``ref``: the comfortable posture (:func:`~anthroarm.ik.qp.tasks.posture.comfortable_posture`);
      ``posture_auto``: it again where ``posture="auto"`` applies it (the human arm), else None;
    * ``has_closed_form``, ``closed_form_first`` (see :func:`anthroarm.ik.solve.seeds.closed_form_cheap`),
      ``nearest``, ``nearest_swivel`` (:func:`anthroarm.ik.closed_form.nearest_solver`,
      :func:`~anthroarm.ik.closed_form.nearest_swivel_solver`);
    * the seed table and the aligned seed table, built on first use.
    """

    def __init__(self, robot, fid: int):
        chain = robot.chain
        self.model = robot.model
        self.chain = chain
        self.fid = fid
        ind = [chain.joints[i] for i in chain.independent]
        self.n = len(ind)
        self.nq = chain.nq
        self.lo = np.array([j.lower for j in ind])
        self.hi = np.array([j.upper for j in ind])
        self.continuous = np.array([j.kind == CONTINUOUS for j in ind])
        self.prismatic = np.array([j.kind == PRISMATIC for j in ind])
        self.to_q = _Configuration(chain) if self.continuous.any() else None
        v_of = {j.index: k for k, j in enumerate(ind)}
        self.on_path = np.zeros(self.n, dtype=bool)
        for i in chain.path(fid):
            j = chain.joints[i]
            self.on_path[v_of[j.mimic.source if j.is_mimic else i]] = True
        self.dof = int(self.on_path.sum())  # joints that move the frame
        self.reach = chain.reach(fid)
        self.ref = self.theta(comfortable_posture(robot))
        self.ref.setflags(write=False)
        self._ref_arg = self.ref.copy()  # what the compiled calls take for it (:meth:`as_arg`)
        self.posture_auto = self.ref if has_comfortable_posture(robot) else None
        lo_s, hi_s = (np.array(b) for b in chain.sampling_box)
        self.lo_s = np.where(self.on_path, lo_s, self.ref)
        self.hi_s = np.where(self.on_path, hi_s, self.ref)
        info = closed_form.closed_form_info(robot, fid)
        self.has_closed_form = info is not None
        self.swivel_family = bool(info is not None and info.swivel)
        self.held = closed_form.held_joint(robot, fid)  # θ index of a 7-joint arm's held joint
        self.closed_form_first = seeds.closed_form_cheap(robot, fid)
        self.nearest = closed_form.nearest_solver(
            robot, fid
        )  # closed-form seeds in one call, or None
        self.nearest_swivel = closed_form.nearest_swivel_solver(
            robot, fid
        )  # the same for an SRS arm
        self.all_on_path = bool(self.on_path.all())
        self.local = threading.local()
        self._lock = threading.Lock()
        self._table = None
        self._aligned = None
        self._penalty = {}
        self.warm = (
            set()
        )  # the settings whose closed-form kernels are loaded (api._warm_closed_form)
        self.path = PathFrames(chain, fid)  # the chain's FK arrays for the attempt kernel (.lm)

    def as_arg(self, th):
        """θ as the compiled calls take it: a writable array — Numba compiles a read-only array
        apart from a writable one, so a first call of either kind would compile the same kernel
        again.  The read-only ``ref`` (and ``posture_auto``) gives its writable twin, made
        once (a copy a call cost ~0.5 µs of a ~20 µs solve); another read-only array a copy."""
        if th is self.ref:
            return self._ref_arg
        return th if th.flags.writeable else th.copy()

    def theta(self, q) -> np.ndarray:
        """θ (n,) or (N, n) of a configuration q in Pinocchio's layout (a copy)."""
        q = np.asarray(q, dtype=float)
        if self.to_q is None:
            return q.copy()
        return self.chain.angles(q)[..., list(self.chain.independent)]

    def q(self, th) -> np.ndarray:
        """Pinocchio's q of θ (a copy): (cos θ, sin θ) for the continuous joints."""
        return th.copy() if self.to_q is None else self.to_q(th)

    def table(self, data):
        """The seed table (:func:`anthroarm.ik.solve.seeds.build_table`), built once."""
        if self._table is None:
            with self._lock:
                if self._table is None:
                    self._table = seeds.build_table(self, data)
        return self._table

    def aligned(self, data):
        """The :class:`~anthroarm.ik.solve.seeds.Aligned` table, or None where it does not apply."""
        if self._aligned is None:
            table = self.table(data)
            with self._lock:
                if self._aligned is None:
                    self._aligned = seeds.Aligned.make(self, data, table[0]) or False
        return self._aligned or None

    def posture_penalty(self, data, q_ref):
        """w_q²‖Θ − θ_ref‖² over the table (cached for the last few θ_ref)."""
        key = q_ref.tobytes()
        pen = self._penalty.get(key)
        if pen is None:
            pen = seeds.posture_penalty(self, self.table(data)[0], q_ref)
            if len(self._penalty) > 16:
                self._penalty = {}
            self._penalty[key] = pen
        return pen


class _Configuration:
    """q of θ for a chain with continuous joints: :meth:`anthroarm.chain.Chain.configuration`
    for one θ written with plain floats (~1 µs instead of ~4 µs for its loop over the joints;
    tested equal to it); batches (N, n) go to the chain."""

    __slots__ = ("chain", "nq", "lin", "cont")

    def __init__(self, chain):
        self.chain, self.nq = chain, chain.nq
        ind = [chain.joints[i] for i in chain.independent]
        self.lin = [
            (j.idx_q, v) for v, j in enumerate(ind) if j.kind != CONTINUOUS
        ]  # (q index, θ index)
        self.cont = [(j.idx_q, v) for v, j in enumerate(ind) if j.kind == CONTINUOUS]

    def __call__(self, th):
        if th.ndim != 1:
            return self.chain.configuration(th)
        t = th.tolist()
        q = [0.0] * self.nq
        for i, k in self.lin:
            q[i] = t[k]
        for i, k in self.cont:
            q[i] = math.cos(t[k])
            q[i + 1] = math.sin(t[k])
        return np.array(q)


class Workspace:
    """The calling thread's view of a :class:`Shared`: its own ``pin.Data`` and the kernel's
    preallocated arrays (J Jᵀ + λI built in place, handed to LAPACK as its transpose: Fortran
    order, symmetric), plus the shared fields the kernel reads, copied for fast access."""

    __slots__ = ("sh", "model", "data", "fid", "n", "lo", "hi", "to_q", "lin", "lm", "prepared")

    def __init__(self, sh: Shared):
        self.sh = sh
        self.model, self.fid, self.n, self.lo, self.hi, self.to_q = (
            sh.model,
            sh.fid,
            sh.n,
            sh.lo,
            sh.hi,
            sh.to_q,
        )
        self.data = sh.model.createData()
        self.lm = Buffers(sh.path, sh.lo, sh.hi)  # the attempt kernel's arrays (.lm.attempt)
        self.prepared = set()  # the settings whose one-time work is done (api._prepare)
        self.lin = {}  # dimension -> (A, its transpose (Fortran order), its diagonal), see kernel.solve_damped
        for m in {3, 6, min(sh.n, 6)}:  # and n × n for an arm with fewer joints than the task
            A = np.empty((m, m))
            self.lin[m] = (A, A.T, A.reshape(-1)[:: m + 1])

    def table(self):
        return self.sh.table(self.data)

    def aligned(self):
        return self.sh.aligned(self.data)

    def posture_penalty(self, q_ref):
        return self.sh.posture_penalty(self.data, q_ref)

    def fk(self, th) -> pin.SE3:
        pin.framesForwardKinematics(
            self.model, self.data, th if self.to_q is None else self.to_q(th)
        )
        return self.data.oMf[self.fid]


def _frames(robot) -> dict:
    return {}


def workspace(robot, fid: int) -> Workspace:
    """The calling thread's workspace for (robot, frame id ``fid``)."""
    frames = robot.derived("ik.solve.shared", _frames)  # frame id -> Shared, kept on the robot
    sh = frames.get(fid)
    if sh is None:
        sh = frames.setdefault(fid, Shared(robot, fid))
    ws = getattr(sh.local, "ws", None)
    if ws is None:
        ws = sh.local.ws = Workspace(sh)
    return ws
