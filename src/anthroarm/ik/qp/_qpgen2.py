"""quadprog's Goldfarb–Idnani routine ``qpgen2_`` called through ctypes with preallocated arrays.

``quadprog.solve_qp`` (quadprog 0.1.14) spends ~8 µs per call in its Cython wrapper (ten array
allocations and typed-memoryview conversions) around a ~1 µs solve of a 7-variable box QP.  This
module calls the same compiled routine of the installed quadprog extension directly:

    int qpgen2_(double *G, double *av, int n, double *xv, double *lagr, double *obj,
                double *C, double *bv, int q, int meq, int *iact, int *nact, int *iter,
                double *work, int factorized)

(``quadprog/solve.QP.c`` of quadprog 0.1.14; G and av are overwritten, C and bv are read only).
The signature differs between quadprog releases, so the direct path is used only for the
release it was written against (:data:`SUPPORTED`) and only after a self-test on a few QPs
reproduced ``quadprog.solve_qp`` bit for bit; otherwise :func:`make` returns ``None`` and the
caller keeps ``quadprog.solve_qp``.
"""

from __future__ import annotations

import ctypes
from importlib.metadata import version

import numpy as np

SUPPORTED = ("0.1.14",)

_FUNC = None  # the ctypes function, False when unavailable
_SELFTESTED = {}  # n -> bool


def _function():
    global _FUNC
    if _FUNC is None:
        _FUNC = False
        try:
            import quadprog

            if version("quadprog") in SUPPORTED:
                f = ctypes.CDLL(quadprog.__file__).qpgen2_
                P, I = ctypes.c_void_p, ctypes.c_int
                f.argtypes = [P, P, I, P, P, P, P, P, I, I, P, P, P, P, I]
                f.restype = I
                _FUNC = f
        except Exception:  # pragma: no cover - other builds: keep the Python wrapper
            _FUNC = False
    return _FUNC


class BoxQP:
    """min ½xᵀHx + cᵀx  s.t.  [I, −I]ᵀ x ≥ B  (B = [lo; −hi], 2n rows) by ``qpgen2_``.

    ``solve(H, c, B)`` returns ``(rc, x)``: rc 0 = solved (x is this object's buffer: copy it),
    1 = infeasible, 2 = H not positive definite (quadprog's codes).  ``B`` must stay at the same
    address between calls that pass the same array (its pointer is cached)."""

    def __init__(self, n: int, func):
        self.n = n
        m = 2 * n
        self._f = func
        self._G = np.zeros((n, n))
        self._av = np.zeros(n)
        self.x = np.zeros(n)
        self._lagr = np.zeros(m)
        self._obj = np.zeros(1)
        self._C = np.asfortranarray(np.hstack([np.eye(n), -np.eye(n)]))  # column j = constraint j
        self._iact = np.zeros(m, np.int32)
        self._nact = np.zeros(1, np.int32)
        self._iter = np.zeros(2, np.int32)
        self._work = np.zeros(2 * n + 2 * m + n * (n + 5) // 2)
        self._B = None
        self._args = None

    def solve(self, H, c, B):
        if B is not self._B:
            p = lambda a: a.ctypes.data  # noqa: E731
            if not (B.flags.c_contiguous and B.dtype == np.float64 and B.shape == (2 * self.n,)):
                raise ValueError("B must be a contiguous float64 array of shape (2n,)")
            self._args = (
                p(self._G),
                p(self._av),
                self.n,
                p(self.x),
                p(self._lagr),
                p(self._obj),
                p(self._C),
                p(B),
                2 * self.n,
                0,
                p(self._iact),
                p(self._nact),
                p(self._iter),
                p(self._work),
                0,
            )
            self._B = B
        np.copyto(self._G, H)  # H is symmetric: C or Fortran order alike
        np.negative(c, out=self._av)  # quadprog minimises ½xᵀGx − aᵀx
        return self._f(*self._args), self.x


def make(n: int):
    """A :class:`BoxQP` for ``n`` variables, or ``None`` when the direct call is not available
    or its self-test against ``quadprog.solve_qp`` did not match exactly."""
    f = _function()
    if not f:
        return None
    ok = _SELFTESTED.get(n)
    if ok is None:
        ok = _SELFTESTED[n] = _selftest(n, f)
    return BoxQP(n, f) if ok else None


def _selftest(n: int, f) -> bool:
    import quadprog

    rng = np.random.default_rng(12345)
    box = BoxQP(n, f)
    for k in range(8):
        J = rng.normal(size=(n + 2, n))
        H = J.T @ J + 1e-3 * np.eye(n)
        c = rng.normal(size=n)
        B = np.concatenate([-rng.random(n) * 0.3 - 0.01, -rng.random(n) * 0.3 - 0.01])  # 0 inside
        rc, x = box.solve(H, c, B.copy() if k % 2 else B)
        try:
            ref = quadprog.solve_qp(H, -c, box._C, B, 0)[0]
        except ValueError:
            return False
        if rc != 0 or not np.array_equal(x, ref):
            return False
    return True
