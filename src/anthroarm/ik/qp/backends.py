"""QP backends of the differential IK: persistent workspaces for OSQP, daqp, proxqp, quadprog,
and a generic qpsolvers path for any other installed solver.

Every backend solves

    min ½ xᵀ H x + cᵀ x   s.t.   lo ≤ x ≤ hi   (box, ±inf allowed),   A x = b   (optional)

and returns ``(x, status)`` with status ``"optimal"``, ``"infeasible"`` or ``"failed"``.  The
returned x is clipped into [lo, hi] (a no-op up to the solver tolerance), so joint limits
encoded as the box are never violated.

Why persistent workspaces (peers.md §4.2): through ``qpsolvers.solve_qp`` OSQP costs ~1 ms per
7-variable QP because the dense→CSC conversion (``csc_matrix``, ``sp.triu``) dominates, and at its
default tolerance it deviates 1.7e-4 from a dense solver (pink#163).  :class:`OSQPBackend`
builds the sparse structure once (full upper-triangular pattern of H, identity plus a dense
equality block for A), then per step only updates the values and solves warm-started; its answer
is made to match a dense solver by an exact solve on the active set it found (:func:`polish_box`,
accepted with a KKT certificate) or, with equality rows, by a tight tolerance (eps 1e-11).
daqp, quadprog and proxqp are called directly (no qpsolvers conversion layer); ``"qpsolvers:NAME"``
goes through ``qpsolvers.solve_qp`` for solvers without a direct path.

:meth:`Backend.solve_ws` is the entry of :func:`~anthroarm.ik.qp.step`: it reads the step's
preallocated arrays (finite box, ``B = [lo; −hi]``) and skips the conversions of ``solve``.  There
quadprog's compiled routine is called with preallocated arrays (:mod:`._qpgen2`, bit-identical to
``quadprog.solve_qp``), and ProxQP keeps a warm-started workspace whose active set is solved
exactly (:func:`polish_box`), as OSQP's is.
"""

from __future__ import annotations

import ctypes
import importlib.util
import math

import numpy as np

from ...errors import SolverNotAvailableError
from . import _qpgen2

try:
    from eigenpy import LLT
except ImportError:  # pragma: no cover - eigenpy comes with pinocchio
    LLT = None

BIG = 1e20  # finite stand-in for an infinite bound (solvers differ in how they read inf)


def _module_available(name: str) -> bool:
    return importlib.util.find_spec(name) is not None


DIRECT = {"osqp": "osqp", "daqp": "daqp", "quadprog": "quadprog", "proxqp": "proxsuite"}


def available_solvers() -> list[str]:
    """Names accepted by :func:`make_backend` on this machine: the direct backends whose module
    is installed, then ``"qpsolvers:NAME"`` for every solver qpsolvers can run (the slow,
    rebuild-per-call path)."""
    names = [n for n, mod in DIRECT.items() if _module_available(mod)]
    try:
        import qpsolvers

        names += [f"qpsolvers:{s}" for s in qpsolvers.available_solvers]
    except ImportError:  # pragma: no cover - qpsolvers is a dependency
        pass
    return names


def _finite(x: np.ndarray) -> np.ndarray:
    if math.isfinite(x @ x):  # the common case costs one dot product (inf/nan propagate)
        return x
    return np.minimum(np.maximum(x, -BIG), BIG)


def polish_box(ws, z, sol, LLT, eye):
    """Exact solution of the box QP of the step workspace ``ws`` (min ½xᵀHx + cᵀx, lo ≤ x ≤ hi)
    on the active set read from an iterative solver's answer ``sol.x`` and bound multipliers
    ``z`` (z < 0 at a lower, z > 0 at an upper bound).  OSQP's polish rule picks the set: lower
    bound active where x − lo < −z, upper where hi − x < z (a warm-started z keeps vanishing,
    e.g. 1e-26, entries of bounds that were active before; ``sol.x`` is read only when z ≠ 0).

    With x_u = −H⁻¹c (``LLT``: a Cholesky factorisation, eigenpy's) and the bounds b_A on the
    active set A, x = x_u + H⁻¹E_A μ with μ = (E_Aᵀ H⁻¹ E_A)⁻¹ (b_A − x_{u,A}), so that
    Hx + c = E_A μ.  Returned (a fresh array, clipped into the box) only with a KKT certificate:
    x within the box (clipping moves it by ≤ 1e-12) and μ ≥ −1e-8 at lower, μ ≤ 1e-8 at upper
    bounds; else None.  ``eye`` is the identity (n, n)."""
    llt = LLT(ws.H)
    x = llt.solve(ws.c)
    np.negative(x, out=x)
    if z.dot(z) != 0.0:  # some multiplier nonzero (cheaper than z.any())
        # the rule entry by entry in Python: cheaper than six array operations at n ≈ 7
        act, lower = [], []
        for i, (xi, zi, li, hi_) in enumerate(
            zip(sol.x.tolist(), z.tolist(), ws.lo.tolist(), ws.hi.tolist())
        ):
            if xi - li < -zi:
                act.append(i)
                lower.append(li)
            elif hi_ - xi < zi:
                act.append(i)
                lower.append(None)
        if len(act) == 1:
            i = act[0]
            b = lower[0] if lower[0] is not None else float(ws.hi[i])
            y = llt.solve(eye[i])  # column i of H⁻¹
            mu = (b - float(x[i])) / float(y[i])
            if (mu < -1e-8) if lower[0] is not None else (mu > 1e-8):
                return None
            x += y * mu
            x[i] = b
        elif act:
            low = np.array([v is not None for v in lower])
            bA = np.where(low, ws.lo[act], ws.hi[act])
            Y = llt.solve(eye[:, act])  # H⁻¹ E_A, (n, k)
            mu = np.linalg.solve(Y[act], bA - x[act])
            if (mu[low] < -1e-8).any() or (mu[~low] > 1e-8).any():
                return None
            x += Y @ mu
            x[act] = bA
    # within the box: clipping into it moves x by at most 1e-12 (2-norm; False for NaN)
    xc = np.maximum(x, ws.lo)
    np.minimum(xc, ws.hi, out=xc)
    d = np.subtract(xc, x, out=x)
    if not d.dot(d) <= 1e-24:
        return None
    return xc


class Backend:
    """Base class: ``solve(H, c, lo, hi, A=None, b=None) -> (x, status)``."""

    name = "base"

    def __init__(self, n: int, n_eq: int = 0):
        self.n = int(n)
        self.n_eq = int(n_eq)
        self._raw_info = None
        self._info: dict = {}

    @property
    def last_info(self) -> dict:
        """Solver details of the last solve (status, iterations, ...)."""
        raw = self._raw_info
        if raw is not None:
            self._info = self._info_from(raw)
            self._raw_info = None
        return self._info

    @last_info.setter
    def last_info(self, info: dict) -> None:
        self._info = info
        self._raw_info = None

    def _info_from(self, raw) -> dict:  # pragma: no cover - only backends that set _raw_info
        return dict(raw)

    def solve(self, H, c, lo, hi, A=None, b=None):  # pragma: no cover - interface
        raise NotImplementedError

    def solve_ws(self, ws, A=None, b=None):
        """:meth:`solve` on the arrays of a step workspace (``ws.H``, ``ws.c``, ``ws.lo``,
        ``ws.hi`` finite, ``ws.B`` = [lo; −hi]; see :mod:`anthroarm.ik.qp.step`).  The returned
        x is a fresh array.  Backends override it to skip conversions."""
        return self.solve(ws.H, ws.c, ws.lo, ws.hi, A, b)

    @staticmethod
    def _finish_box(x, lo, hi):
        """``_finish`` without equality rows: x clipped into [lo, hi] (a fresh array)."""
        if not math.isfinite(x.dot(x)):
            return None, "failed"
        x = np.maximum(x, lo)
        return np.minimum(x, hi, out=x), "optimal"

    @staticmethod
    def _clip_box(x, lo, hi):
        """x clipped into [lo, hi] (a fresh array), for a direct solver that reported success
        on finite data (step checked H, c and the box): its x is finite."""
        x = np.maximum(x, lo)
        return np.minimum(x, hi, out=x), "optimal"

    def _finish(self, x, lo, hi, A, b, status):
        """Clip into the box and check the equality residual; map failures to a status."""
        if x is None or not math.isfinite(x @ x):
            return None, status if status != "optimal" else "failed"
        x = np.minimum(np.maximum(x, lo), hi)
        if A is not None and len(b):
            res = float(np.abs(A @ x - b).max())
            self.last_info["eq_residual"] = res
            if res > 1e-6 * max(1.0, float(np.abs(b).max())):
                return None, "infeasible"
        return x, status

    def _polish(self, H, c, lo, hi, A, b, x, y):
        """Exact solution on the active set guessed from the duals ``y`` (OSQP's polish rule:
        lower bound active if x − lo < −y, upper if hi − x < y): the KKT system with the active
        rows of H replaced by x_i = bound.  Accepted only if it is primal feasible and the
        multipliers have the right signs; else ``None``."""
        n = self.n
        yb = y[:n]
        act_lo = (x - lo) < -yb
        act_hi = (hi - x) < yb
        act = act_lo | act_hi
        K = H.copy()
        rhs = -c
        has_act = bool(act.any())
        if has_act:
            K[act] = np.eye(n)[act]
            rhs = rhs.copy()
            rhs[act] = np.where(act_lo, lo, hi)[act]
        try:
            if A is None or not len(A):
                xp = np.linalg.solve(K, rhs)
                g = H @ xp + c
            else:
                m = len(A)
                At = A.T.copy()
                At[act] = 0.0
                KKT = np.block([[K, At], [A, np.zeros((m, m))]])
                sol = np.linalg.solve(KKT, np.concatenate([rhs, b]))
                xp = sol[:n]
                g = H @ xp + c + A.T @ sol[n:]
        except np.linalg.LinAlgError:
            return None
        tol = 1e-9
        if np.maximum.reduce(lo - xp) > tol or np.maximum.reduce(xp - hi) > tol:
            return None
        if has_act and (
            np.minimum.reduce(np.where(act_lo, g, 0.0)) < -1e-8
            or np.maximum.reduce(np.where(act_hi, g, 0.0)) > 1e-8
        ):
            return None
        return xp


class OSQPBackend(Backend):
    """OSQP with a persistent workspace (sparse structure built once, ``update`` + warm start).

    Box-only QPs (``n_eq = 0``, every step without hard constraints): ADMM to eps 1e-9, then the
    active set it found is solved exactly (:func:`polish_box`, accepted only with a KKT
    certificate).  ADMM's stopping test bounds scaled residuals, not x: on human_arm7, whose H
    has eigenvalues down to the posture weight² (1e-6), x was up to 1e-5 off quadprog even at
    eps 1e-11, while the polished answer is within 1e-12, and at eps 1e-9 ADMM needs about half
    the iterations (median 65 instead of 115 there).  Without a certificate, ADMM continues to
    eps 1e-11 and its x is used (polished if possible).  With equality rows: eps 1e-11 and
    ADMM's x.  OSQP's own polishing prints to stdout even with verbose=False (osqp 1.1.3) when
    there is no active set, so it stays off; when ADMM stops early (max_iter, inaccurate) the
    reduced KKT system on the duals' active set is solved (:meth:`Backend._polish`)."""

    name = "osqp"
    # rho 10: on 300 steps of a panda tracking QP the answer is within 1e-10 of quadprog at a
    # median 30 warm-started ADMM iterations at eps 1e-11 (with the default rho 0.1 it was 3e-6 off)
    SETTINGS = dict(
        verbose=False,
        eps_abs=1e-11,
        eps_rel=1e-11,
        eps_prim_inf=1e-9,
        eps_dual_inf=1e-9,
        rho=10.0,
        polishing=False,
        max_iter=4000,
        warm_starting=True,
        adaptive_rho=True,
        check_termination=5,
    )
    EPS_BOX = 1e-9  # ADMM tolerance of box-only QPs, followed by the exact polish
    EPS_TIGHT = 1e-11  # without a polish certificate

    def __init__(self, n: int, n_eq: int = 0, **settings):
        super().__init__(n, n_eq)
        import osqp
        import scipy.sparse as sp

        self._osqp = osqp
        # upper-triangular pattern of H in CSC order (column by column, rows 0..j)
        cols = np.concatenate([np.full(j + 1, j) for j in range(n)])
        rows = np.concatenate([np.arange(j + 1) for j in range(n)])
        self._tri = rows * n + cols  # flat indices into H (row-major) of the CSC entries
        P = sp.csc_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
        # A = [I; Aeq] with a dense pattern for the equality block; Ax in CSC order is
        # vstack([1, Aeq[:, j]]) column by column
        arows = np.concatenate([np.concatenate([[j], n + np.arange(n_eq)]) for j in range(n)])
        acols = np.repeat(np.arange(n), 1 + n_eq)
        A = sp.csc_matrix((np.ones(len(arows)), (arows, acols)), shape=(n + n_eq, n))
        assert P.nnz == len(rows) and A.nnz == len(arows)
        self._ones = np.ones((1, n))
        self.settings = {**self.SETTINGS, **settings}
        self._LLT = LLT
        self._eye = np.eye(n)
        # box-only QPs are polished: ADMM can stop earlier (unless the caller set eps itself)
        self._loose = (
            n_eq == 0
            and LLT is not None
            and "eps_abs" not in settings
            and "eps_rel" not in settings
        )
        if self._loose:
            self.settings.update(eps_abs=self.EPS_BOX, eps_rel=self.EPS_BOX)
        self.solver = osqp.OSQP()
        self.solver.setup(
            P, np.zeros(n), A, -np.full(n + n_eq, BIG), np.full(n + n_eq, BIG), **self.settings
        )
        ext = getattr(self.solver, "_solver", None)
        self._ext = (
            ext
            if all(
                hasattr(ext, a)
                for a in ("update_data_vec", "update_data_mat", "solve", "info", "solution")
            )
            else None
        )
        self._solved = osqp.SolverStatus.OSQP_SOLVED
        if (
            self._loose and self._ext is None
        ):  # pragma: no cover - other osqp versions: no polish path
            self.solver.update_settings(eps_abs=self.EPS_TIGHT, eps_rel=self.EPS_TIGHT)
            self._loose = False

    def solve(self, H, c, lo, hi, A=None, b=None):
        n_eq = 0 if A is None else len(A)
        if n_eq != self.n_eq:
            raise ValueError(f"OSQPBackend built for {self.n_eq} equality rows, got {n_eq}")
        lo_f, hi_f = _finite(lo), _finite(hi)
        if self._loose:  # box-only with the polish: the same path as a step
            return self.solve_ws(
                _BoxQP(np.ascontiguousarray(H, dtype=float), np.asarray(c, dtype=float), lo_f, hi_f)
            )
        if n_eq:
            l = np.concatenate([lo_f, b])
            u = np.concatenate([hi_f, b])
            Ax = np.vstack([self._ones, A]).ravel(order="F")
        else:
            l, u, Ax = lo_f, hi_f, None
        ext = self._ext
        if ext is not None:
            # the compiled solver directly: osqp's Python ``update``/``solve`` wrappers add ~15 µs
            # per call (derivative cache, a SimpleNamespace of every info field)
            ext.update_data_vec(q=c, l=l, u=u)
            ext.update_data_mat(P_x=H.take(self._tri), P_i=None, A_x=Ax, A_i=None)
            ext.solve()
            info = ext.info
            x = ext.solution.x
        else:  # pragma: no cover - other osqp versions
            kw = {"Ax": Ax} if Ax is not None else {}
            self.solver.update(Px=H.take(self._tri), q=c, l=l, u=u, **kw)
            res = self.solver.solve(raise_error=False)
            info, x = res.info, res.x
            return self._status(info, x, res.y, H, c, lo, hi, A, b)
        return self._status(info, x, ext.solution.y, H, c, lo, hi, A, b)

    def _status(self, info, x, y, H, c, lo, hi, A, b):
        """Map OSQP's status to (x, status): polish when ADMM stopped early, reset the warm
        start after a failure."""
        st = info.status_val
        self.last_info = {"status": st, "iter": info.iter}
        S = self._osqp.SolverStatus
        if st == S.OSQP_SOLVED:
            return self._finish(np.array(x), lo, hi, A, b, "optimal")
        if st in (S.OSQP_PRIMAL_INFEASIBLE, S.OSQP_PRIMAL_INFEASIBLE_INACCURATE):
            self.solver.warm_start(x=np.zeros(self.n), y=np.zeros(self.n + self.n_eq))
            return None, "infeasible"
        if st in (S.OSQP_SOLVED_INACCURATE, S.OSQP_MAX_ITER_REACHED):
            x = np.array(x)
            xp = self._polish(H, c, lo, hi, A, b, x, np.array(y))
            self.last_info["polished"] = xp is not None
            if xp is not None or st == S.OSQP_SOLVED_INACCURATE:
                return self._finish(x if xp is None else xp, lo, hi, A, b, "optimal")
        self.solver.warm_start(x=np.zeros(self.n), y=np.zeros(self.n + self.n_eq))
        return None, "failed"

    def solve_ws(self, ws, A=None, b=None):
        ext = self._ext
        if A is not None or ext is None:
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, A, b)
        # the workspace box is finite already (±BIG): no _finite, no concatenation
        ext.update_data_vec(q=ws.c, l=ws.lo, u=ws.hi)
        ext.update_data_mat(P_x=ws.H.take(self._tri), P_i=None, A_x=None, A_i=None)
        ext.solve()
        info = ext.info
        sol = ext.solution
        if info.status_val == self._solved and self._LLT is not None:
            # the active set ADMM found, solved exactly (KKT-checked)
            x = polish_box(ws, sol.y, sol, self._LLT, self._eye)
            if x is None and self._loose:
                # no certificate: ADMM continues (warm) to the tight tolerance, then polish again
                self.solver.update_settings(eps_abs=self.EPS_TIGHT, eps_rel=self.EPS_TIGHT)
                try:
                    ext.solve()
                finally:
                    self.solver.update_settings(eps_abs=self.EPS_BOX, eps_rel=self.EPS_BOX)
                info = ext.info
                if info.status_val == self._solved:
                    x = polish_box(ws, sol.y, sol, self._LLT, self._eye)
            if x is not None:
                self._raw_info = (info, True)
                return x, "optimal"
        if info.status_val == self._solved:
            self._raw_info = (info, False)
            return self._finish_box(sol.x, ws.lo, ws.hi)  # fresh array
        return self._status(info, sol.x, sol.y, ws.H, ws.c, ws.lo, ws.hi, None, None)

    def _info_from(self, raw):
        info, polished = raw
        return {"status": info.status_val, "iter": info.iter, "polished": polished}


class _BoxQP:
    """The step-workspace fields :meth:`Backend.solve_ws` reads, for a QP given as arrays."""

    __slots__ = ("H", "c", "lo", "hi")

    def __init__(self, H, c, lo, hi):
        self.H, self.c, self.lo, self.hi = H, c, lo, hi


class DaqpBackend(Backend):
    """daqp (dual active set), called directly; box rows as simple bounds."""

    name = "daqp"

    def __init__(self, n: int, n_eq: int = 0):
        super().__init__(n, n_eq)
        import daqp

        self._daqp = daqp
        self._sense = np.zeros(n + n_eq, dtype=ctypes.c_int)
        self._sense[n:] = 5  # equality rows: active + immutable
        self._A0 = np.zeros((0, n))

    def _info_from(self, raw):
        flag, info = raw
        return {"exitflag": flag, "iter": info.get("iterations")}

    def solve(self, H, c, lo, hi, A=None, b=None):
        if A is None or not len(A):
            bu, bl, Am = _finite(hi), _finite(lo), self._A0
        else:
            bu = np.concatenate([_finite(hi), b])
            bl = np.concatenate([_finite(lo), b])
            Am = np.ascontiguousarray(A)
        x, _, flag, info = self._daqp.solve(H, c, Am, bu, bl, self._sense)
        self.last_info = {"exitflag": flag, "iter": info.get("iterations")}
        if flag > 0:
            return self._finish(x, lo, hi, A, b, "optimal")
        return None, "infeasible" if flag == -1 else "failed"

    def solve_ws(self, ws, A=None, b=None):
        if A is not None:
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, A, b)
        x, _, flag, info = self._daqp.solve(ws.H, ws.c, self._A0, ws.hi, ws.lo, self._sense)
        self._raw_info = (flag, info)  # last_info is built when read
        if flag > 0:
            return self._clip_box(x, ws.lo, ws.hi)
        return None, "infeasible" if flag == -1 else "failed"


class QuadprogBackend(Backend):
    """quadprog (Goldfarb–Idnani), called directly.  The box becomes the constant inequality
    block [I; −I] (infinite bounds replaced by ±1e20, never active), built once.

    Box-only QPs of :func:`~anthroarm.ik.qp.step` call quadprog's compiled ``qpgen2_`` routine
    with preallocated arrays (:mod:`anthroarm.ik.qp._qpgen2`: the same routine and inputs as
    ``quadprog.solve_qp``, bit-identical results, without its ~8 µs of per-call allocation);
    where that is unavailable, and for equality rows, ``quadprog.solve_qp`` is called."""

    name = "quadprog"

    def __init__(self, n: int, n_eq: int = 0):
        super().__init__(n, n_eq)
        import quadprog

        self._qp = quadprog
        self._eye = np.eye(n)
        self._C = np.hstack([np.zeros((n, n_eq)), self._eye, -self._eye])
        self._direct = _qpgen2.make(n) if n_eq == 0 else None

    def solve(self, H, c, lo, hi, A=None, b=None):
        meq = 0 if A is None else len(A)
        if meq:
            self._C[:, :meq] = A.T
            bb = np.concatenate([b, _finite(lo), -_finite(hi)])
        else:
            bb = np.concatenate([_finite(lo), -_finite(hi)])
        try:
            x = self._qp.solve_qp(H, -c, self._C, bb, meq)[0]
        except ValueError as exc:
            msg = str(exc)
            self.last_info = {"error": msg}
            if "inconsistent" in msg:
                return None, "infeasible"
            if "positive definite" not in msg:
                return None, "failed"
            # singular H: retry once with a tiny Tikhonov term
            eps = 1e-10 * max(1.0, float(np.trace(H)) / self.n)
            try:
                x = self._qp.solve_qp(H + eps * self._eye, -c, self._C, bb, meq)[0]
            except ValueError:
                return None, "failed"
        else:
            self.last_info = {}
        return self._finish(x, lo, hi, A, b, "optimal")

    def solve_ws(self, ws, A=None, b=None):
        if A is not None:
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, A, b)
        # ws.B = [lo; −hi] is quadprog's b for C = [I, −I]
        direct = self._direct
        if direct is not None:
            rc, x = direct.solve(ws.H, ws.c, ws.B)
            if rc == 0:
                self.last_info = {}
                return self._clip_box(x, ws.lo, ws.hi)  # a fresh array (x is the buffer)
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, None, None)  # errors handled there
        try:
            x = self._qp.solve_qp(ws.H, np.negative(ws.c, out=ws.nc), self._C, ws.B, 0)[0]
        except ValueError:
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, None, None)  # error handling there
        self.last_info = {}
        return self._finish_box(x, ws.lo, ws.hi)


class ProxqpBackend(Backend):
    """proxsuite ProxQP (dense), followed by an active-set polish (ProxQP's eps bounds
    residuals, not x: on IK QPs, whose H has eigenvalues down to the posture weight², x is
    1e-4 off without it).

    Box-only QPs of :func:`~anthroarm.ik.qp.step` use one persistent ``proxqp.dense.QP``
    (``update`` + warm start from the previous result, eps 1e-9): ProxQP identifies the active
    bounds (its multipliers z, z < 0 at a lower and z > 0 at an upper bound) and
    :meth:`_polish_box` solves the equality-constrained QP on that set exactly, accepting it
    only with a KKT certificate (primal feasible, multipliers of the right sign).  Anything else
    (equality rows, a failed certificate, a solver status other than solved) runs the one-shot
    ``proxqp.dense.solve`` at eps 1e-10 followed by :meth:`Backend._polish`."""

    name = "proxqp"
    EPS_WARM = 1e-9

    def __init__(self, n: int, n_eq: int = 0):
        super().__init__(n, n_eq)
        from proxsuite import proxqp

        self._proxqp = proxqp
        self._eye = np.eye(n)
        self._Q = None  # persistent box-QP workspace (created on the first solve_ws)
        self._solved = proxqp.QPSolverOutput.PROXQP_SOLVED
        self._LLT = LLT

    def solve_ws(self, ws, A=None, b=None):
        if A is not None or self._LLT is None:
            return self.solve(ws.H, ws.c, ws.lo, ws.hi, A, b)
        proxqp = self._proxqp
        Q = self._Q
        if Q is None:
            Q = proxqp.dense.QP(self.n, 0, self.n, False)
            st = Q.settings
            st.eps_abs, st.eps_rel, st.verbose = self.EPS_WARM, 0.0, False
            st.initial_guess = proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
            Q.init(ws.H, ws.c, None, None, self._eye, ws.lo, ws.hi)
            self._Q = Q
        else:
            Q.update(H=ws.H, g=ws.c, l=ws.lo, u=ws.hi)
        Q.solve()
        r = Q.results
        if r.info.status == self._solved:
            x = self._polish_box(ws, r)
            if x is not None:
                self._raw_info = r.info
                return x, "optimal"
        else:
            self._Q = None  # start afresh next time
        return self.solve(ws.H, ws.c, ws.lo, ws.hi)

    def _info_from(self, info):
        return {"status": str(info.status), "iter": info.iter, "polished": True}

    def _polish_box(self, ws, r):
        """:func:`polish_box` on ProxQP's results ``r`` (answer ``r.x``, multipliers ``r.z``)."""
        return polish_box(ws, r.z, r, self._LLT, self._eye)

    def solve(self, H, c, lo, hi, A=None, b=None):
        proxqp = self._proxqp
        Aeq, beq = (None, None) if A is None or not len(A) else (A, b)
        r = proxqp.dense.solve(
            H,
            c,
            Aeq,
            beq,
            self._eye,
            _finite(lo),
            _finite(hi),
            eps_abs=1e-10,
            eps_rel=0.0,
            verbose=False,
        )
        st = r.info.status
        S = proxqp.QPSolverOutput
        self.last_info = {"status": str(st), "iter": r.info.iter}
        if st == S.PROXQP_SOLVED:
            x = np.array(r.x)
            xp = self._polish(H, c, lo, hi, A, b, x, np.array(r.z))
            self.last_info["polished"] = xp is not None
            return self._finish(x if xp is None else xp, lo, hi, A, b, "optimal")
        if st == S.PROXQP_PRIMAL_INFEASIBLE:
            return None, "infeasible"
        return None, "failed"


class QpsolversBackend(Backend):
    """Any solver qpsolvers can run (``"qpsolvers:clarabel"``, ...); rebuilds per call."""

    def __init__(self, n: int, n_eq: int = 0, solver: str = "osqp"):
        super().__init__(n, n_eq)
        self.solver = solver
        self.name = f"qpsolvers:{solver}"

    def solve(self, H, c, lo, hi, A=None, b=None):
        import qpsolvers

        kw = {}
        if A is not None and len(A):
            kw = {"A": A, "b": b}
        try:
            x = qpsolvers.solve_qp(H, c, lb=_finite(lo), ub=_finite(hi), solver=self.solver, **kw)
        except Exception as exc:  # solver-specific exception types
            self.last_info = {"error": repr(exc)}
            return None, "failed"
        if x is None:
            return None, "infeasible" if A is not None and len(A) else "failed"
        return self._finish(np.array(x), lo, hi, A, b, "optimal")


_DIRECT_CLASSES = {
    "osqp": OSQPBackend,
    "daqp": DaqpBackend,
    "quadprog": QuadprogBackend,
    "proxqp": ProxqpBackend,
}


def make_backend(solver: str, n: int, n_eq: int = 0) -> Backend:
    """A fresh backend for ``n`` variables and ``n_eq`` equality rows.

    ``solver``: ``"osqp"`` (default of :func:`~anthroarm.ik.qp.step`), ``"daqp"``,
    ``"quadprog"``, ``"proxqp"``, or ``"qpsolvers:NAME"``.  A bare name that only qpsolvers knows
    is accepted too.  An unknown or uninstalled solver raises
    :class:`~anthroarm.errors.SolverNotAvailableError` listing the installed ones."""
    if not isinstance(solver, str):
        raise SolverNotAvailableError(
            f"solver must be a string, got {solver!r}; installed: {', '.join(available_solvers())}"
        )
    avail = available_solvers()
    if solver in _DIRECT_CLASSES and solver in avail:
        return _DIRECT_CLASSES[solver](n, n_eq)
    name = solver.split(":", 1)[1] if solver.startswith("qpsolvers:") else solver
    if f"qpsolvers:{name}" in avail:
        return QpsolversBackend(n, n_eq, name)
    pip = PIP_NAMES.get(name)
    raise SolverNotAvailableError(
        f"QP solver {solver!r} is not installed; installed solvers: {', '.join(avail)}. "
        + (f"Install it (pip install {pip}) or " if pip else "Either install it or ")
        + "pass one of the installed ones (solver=..., --solver on the command line)"
    )


#: the PyPI package of each QP backend a user may name (for the message of a missing one)
PIP_NAMES = {
    "osqp": "osqp",
    "daqp": "daqp",
    "quadprog": "quadprog",
    "proxqp": "proxsuite",
    "proxsuite": "proxsuite",
    "clarabel": "clarabel",
    "ecos": "ecos",
    "highs": "highspy",
    "piqp": "piqp",
    "scs": "scs",
    "cvxopt": "cvxopt",
}
