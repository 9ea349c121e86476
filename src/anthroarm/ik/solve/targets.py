"""Targets of :func:`anthroarm.ik.solve`: parsing (pose, position, rotation, batches) and the
error and Jacobian the kernel iterates on.

Pose errors are the body twist e = log₆(T(θ)⁻¹ T*) = (v; ω) with the LOCAL frame Jacobian
(Pinocchio order, m and rad); ‖ω‖ is the rotation error and the position error is the length of
the translation of T(θ)⁻¹ T* (= ‖p* − p‖).  A position target has e = p* − p (world axes) with
the LOCAL_WORLD_ALIGNED linear rows of J, a rotation target e = log₃(Rᵀ R*) with the LOCAL
angular rows.  The configuration θ is the independent joints' positions
(:class:`~anthroarm.ik.solve.workspace.Workspace`); Jacobian columns are Pinocchio's v.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ..qp.targets import as_position, as_rigid, as_rotation

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_log3 = pin.log3
_log6 = pin.log6
_cjj = pin.computeJointJacobians
_ufp = pin.updateFramePlacement
_gfj = pin.getFrameJacobian

POSE, POSITION, ORIENTATION = 0, 1, 2
KIND = {"pose": POSE, "position": POSITION, "orientation": ORIENTATION}


class Target:
    """One target: kind, T* (``H`` (4, 4), and as ``pin.SE3`` ``Ms``, made on first use), p* (3,),
    R* (3, 3), tolerances (m, rad), task dimension m, and the seed-table features x: T*.ravel()
    (16,) for a pose, (p*, 1) for a position, R*.ravel() for a rotation (see
    :meth:`anthroarm.ik.solve.seeds.build_table`).  A pose ``tgt`` is a rigid 4×4 float array
    (:func:`~anthroarm.ik.qp.targets.as_rigid`, not copied) or a ``pin.SE3``."""

    __slots__ = (
        "kind",
        "mode",
        "m",
        "H",
        "_Ms",
        "ps",
        "Rs",
        "tol_p",
        "tol_r",
        "tp2",
        "tr2",
        "tsum",
        "x",
        "ref",
        "rows",
    )

    def __init__(self, mode, tgt, tol_p, tol_r):
        self.mode = mode
        self.kind = KIND[mode]
        self.tol_p = tol_p
        self.tol_r = tol_r
        self.tp2 = tol_p * tol_p
        self.tr2 = tol_r * tol_r
        # a pose's v = V(ω)⁻¹ t with ‖V(ω)⁻¹‖ ≤ (1 + ‖ω‖)², so ‖e‖² ≤ tsum is necessary for
        # convergence: the exact errors are computed only then (see residual)
        self.tsum = (self.tp2 * (1.0 + tol_r) ** 2 + self.tr2) * (1.0 + 1e-12)
        self.H = self._Ms = self.ps = self.Rs = None
        if mode == "pose":
            self.m, self.ref, self.rows = 6, LOCAL, None
            if tgt.__class__ is not np.ndarray and isinstance(tgt, pin.SE3):
                self._Ms, tgt = tgt, tgt.homogeneous
            self.H = tgt
            self.ps = tgt[:3, 3]
            self.Rs = tgt[:3, :3]
            self.x = tgt.reshape(16)
        elif mode == "position":
            self.m, self.ref, self.rows = 3, LWA, slice(0, 3)
            self.ps = np.asarray(tgt, dtype=float)
            self.x = np.append(self.ps, 1.0)
        else:
            self.m, self.ref, self.rows = 3, LOCAL, slice(3, 6)
            self.Rs = np.ascontiguousarray(tgt, dtype=float)
            self.x = self.Rs.reshape(9)

    @property
    def Ms(self) -> pin.SE3:
        """T* as a ``pin.SE3`` (a pose target only)."""
        if self._Ms is None:
            self._Ms = pin.SE3(self.H)
        return self._Ms

    def residual(self, ws, th):
        """(e (m,), ‖e‖², pos_err², rot_err²) at θ (0.0 for the unchecked part; a pose's both
        inf where ‖e‖² > tsum, i.e. surely not converged); leaves FK and the joint Jacobians in
        ``ws.data`` for :meth:`jacobian`."""
        model, data = ws.model, ws.data
        _cjj(model, data, th if ws.to_q is None else ws.to_q(th))
        M = _ufp(model, data, ws.fid)
        kind = self.kind
        if kind == POSE:
            Mt = M.actInv(self.Ms)
            e = _log6(Mt).vector
            E = e.dot(e)
            if E > self.tsum:
                return e, E, math.inf, math.inf
            t = Mt.translation
            w = e[3:]
            return e, E, t.dot(t), w.dot(w)
        if kind == POSITION:
            e = self.ps - M.translation
            E = e.dot(e)
            return e, E, E, 0.0
        e = _log3(M.rotation.T.dot(self.Rs))
        E = e.dot(e)
        return e, E, 0.0, E

    def jacobian(self, ws):
        """J (m, nv) of the last :meth:`residual`, in the frame of its error."""
        J = _gfj(ws.model, ws.data, ws.fid, self.ref)
        return J if self.rows is None else J[self.rows]

    def errors(self, ws, th):
        """(pos_err m, rot_err rad) at θ from Pinocchio's FK; 0.0 for the unchecked part."""
        pin.framesForwardKinematics(ws.model, ws.data, th if ws.to_q is None else ws.to_q(th))
        M = ws.data.oMf[ws.fid]
        pe = re = 0.0
        if self.kind != ORIENTATION:
            d = self.ps - M.translation
            pe = math.sqrt(d.dot(d))
        if self.kind != POSITION:
            w = _log3(M.rotation.T.dot(self.Rs))
            re = math.sqrt(w.dot(w))
        return pe, re

    def ok(self, pe2, re2) -> bool:
        return pe2 <= self.tp2 and re2 <= self.tr2


def parse(T, mode):
    """-> (mode, batch: bool, list of targets: rigid 4×4 arrays, p (3,) or R (3, 3)).
    ``ValueError`` naming the defect for a wrong shape, NaN or a non-rigid transform.

    The usual call, one 4×4 ``numpy.ndarray`` pose, goes straight to
    :func:`~anthroarm.ik.qp.targets.as_rigid` (whose own fast path takes a clean float64 array
    as it is); a batch's poses each go through it too, below."""
    if T.__class__ is np.ndarray and T.shape == (4, 4) and mode in (None, "pose"):
        return "pose", False, [as_rigid(T, "T")]
    if mode not in (None, "pose", "position", "orientation"):
        raise ValueError(f"mode must be None, 'pose', 'position' or 'orientation', got {mode!r}")
    if isinstance(T, pin.SE3):
        T = T.homogeneous
    arr = np.asarray(T, dtype=float)
    sh = arr.shape
    if sh == (4, 4) or (arr.ndim == 3 and sh[1:] == (4, 4)):
        m = mode or "pose"
        batch = arr.ndim == 3
        out = []
        for i, a in enumerate(arr if batch else [arr]):
            H = as_rigid(a, f"T[{i}]" if batch else "T")
            out.append(
                H if m == "pose" else (H[:3, 3].copy() if m == "position" else H[:3, :3].copy())
            )
        return m, batch, out
    if sh == (3,):
        if mode not in (None, "position"):
            raise ValueError(f"a (3,) target is a position; mode={mode!r} needs a 4x4 pose")
        return "position", False, [as_position(arr, "T")]
    if (sh == (3, 3) and mode != "position") or (arr.ndim == 3 and sh[1:] == (3, 3)):
        if mode not in (None, "orientation"):
            raise ValueError(f"a 3x3 target is a rotation; mode={mode!r} needs a 4x4 pose")
        batch = arr.ndim == 3
        return (
            "orientation",
            batch,
            [
                as_rotation(a, f"T[{i}]" if batch else "T")
                for i, a in enumerate(arr if batch else [arr])
            ],
        )
    if arr.ndim == 2 and sh[1] == 3 and mode in (None, "position"):
        return "position", True, [as_position(a, f"T[{i}]") for i, a in enumerate(arr)]
    raise ValueError(
        f"target T must be a 4x4 pose, a position (3,), a rotation (3, 3), or a batch of them "
        f"with a leading axis; got shape {sh}" + (f" (mode={mode!r})" if mode else "")
    )


def check_options(tol_pos, tol_rot, max_time, max_restarts, rng, analytic) -> None:
    """The scalar options of :func:`anthroarm.ik.solve` (every robot kind), or
    ValueError/TypeError naming the bad one: tolerances and ``max_time`` positive finite numbers
    (not bools), ``max_restarts`` None or a non-negative integer, ``rng`` None, a non-negative
    int, a SeedSequence or a Generator, ``analytic`` "auto", True or False."""
    if not (
        type(tol_pos) is float
        and type(tol_rot) is float
        and type(max_time) is float  # the usual call
        and 0.0 < tol_pos < math.inf
        and 0.0 < tol_rot < math.inf
        and 0.0 < max_time < math.inf
    ):
        for name, v in (("tol_pos", tol_pos), ("tol_rot", tol_rot), ("max_time", max_time)):
            if not (
                isinstance(v, (int, float, np.floating))
                and not isinstance(v, bool)
                and math.isfinite(v)
                and v > 0
            ):
                raise ValueError(f"{name} must be a positive finite number, got {v!r}")
    if max_restarts is not None and (
        isinstance(max_restarts, bool) or int(max_restarts) != max_restarts or max_restarts < 0
    ):
        raise ValueError(f"max_restarts must be a non-negative integer, got {max_restarts!r}")
    if not (
        rng is None
        or isinstance(rng, (np.random.Generator, np.random.SeedSequence))
        or (isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0)
    ):
        raise TypeError(
            f"rng must be None, a non-negative int, a numpy SeedSequence or Generator, got {rng!r}"
        )
    if analytic not in ("auto", True, False):
        raise ValueError(f"analytic must be 'auto', True or False, got {analytic!r}")


def check_q0(robot, q0, batch: bool, n: int):
    """``q0`` as ``robot.check_q`` gives it ((nq,) or (N, nq)), None for None; ValueError for
    an (N, nq) ``q0`` without a batch of N targets (``n`` targets given)."""
    if q0 is None:
        return None
    Q0 = robot.check_q(q0, name="q0")
    if Q0.ndim == 2 and (not batch or len(Q0) != n):
        raise ValueError(f"q0 of shape {Q0.shape} needs a batch of {len(Q0)} targets")
    return Q0
