"""Compiled form of one attempt of :func:`anthroarm.ik.solve` (:func:`.kernel.attempt`).

The Python kernel spends ~8 µs per iteration in calls to Pinocchio and LAPACK for a few hundred
floating-point operations.  Here the whole attempt loop runs in C, per (robot, frame):

* the FK of the frame and its Jacobian as functions of θ, generated from ``robot.chain`` in the
  project's one expression graph (:func:`anthroarm.ik.fk_codegen.frame_product`: the chain
  product of the path to the frame; the Jacobian's columns are the geometric ones,
  LOCAL_WORLD_ALIGNED (z_k × (p − o_k); z_k) for a revolute joint with axis z_k through o_k and
  (z_k; 0) for a prismatic one, as Pinocchio's ``computeJointJacobians``/``getFrameJacobian``;
  a mimic joint θ_j = a θ_i + b adds a times its column to its source's; joints off the path
  have zero columns; a continuous joint is a revolute one in θ);
* a transcription of :func:`.kernel.attempt`, :func:`.kernel.damped_step`,
  :func:`.kernel.solve_damped` and the residuals and Jacobians of :class:`.targets.Target`
  (pose: e = log₆(T(θ)⁻¹T*) with the LOCAL Jacobian; position: e = p* − p with the LWA linear
  rows; orientation: e = log₃(RᵀR*) with the LOCAL angular rows), with log₃/log₆ written as
  Pinocchio 3/4 computes them (``pinocchio/src/spatial/log.hxx``: the renormalised rotation, the
  Taylor branches at ε^(1/3), the θ ≈ π branch), the Cholesky factorisation of LAPACK's
  ``dpotrf`` (fails where a pivot is ≤ 0 or NaN) and the same constants (read from
  :mod:`.kernel`, not copied).

The Python kernel stays the reference: ``tests/ik_qp/test_ik_ckernel.py`` runs both from the
same seeds and asserts the same iterates, iteration counts and flags.

Build and load: one shared library per (robot, frame) (limits, placements and axes are
compile-time constants) through the one disk cache (:func:`anthroarm.cache.shared_library`:
``ik/lm_<hash>.so`` keyed by the source, compiler and flags, verified before it is loaded), the
flags :data:`FLAGS` (``-fno-fast-math -ffp-contract=off``: the same rounding as the Python
kernel).  Without a compiler, if compilation fails, or with ``ANTHROARM_IK_C=0``,
:func:`kernel_for` returns None and the Python kernel runs.  Called through :mod:`ctypes` with the per-thread buffers of
:class:`~anthroarm.ik.solve.workspace.Workspace` (no allocation per call but the returned θ).
"""

from __future__ import annotations

import ctypes
import math
import threading

import numpy as np

from ... import cache
from ...chain import PRISMATIC
from ...codegen.graph import straight_line
from ..fk_codegen import frame_product
from . import kernel
from .targets import ORIENTATION, POSE, POSITION

_LOCK = threading.Lock()
_LIBS: dict[str, "CKernel"] = {}  # source key -> loaded library (no Robot referenced)
#: compiler flags: no fast-math, no fused multiply-add contraction (the Python kernel's rounding)
FLAGS = ["-O2", "-fPIC", "-shared", "-std=c99", "-fno-fast-math", "-ffp-contract=off"]
#: the attempt kernels: one per (robot, frame), switched off by ANTHROARM_IK_C=0
KERNELS = cache.CompiledOnce(
    "ANTHROARM_IK_C", "Python kernel", "available (compiled on first use per robot and frame)"
)
enabled = KERNELS.enabled
status = KERNELS.status


def _c(x: float) -> str:
    if math.isinf(x):
        return "HUGE_VAL" if x > 0 else "-HUGE_VAL"
    r = repr(float(x))
    return r if ("e" in r or "." in r or "n" in r) else r + ".0"


# ---------------------------------------------------------------------------- generated part
def fk_jacobian_source(sh) -> str:
    """C text of ``static void fkj(const double *th, double *R, double *p, double *Jl, double *Ja)``:
    the frame's rotation R (row-major) and position p in the base frame and the LWA Jacobian's
    linear rows Jl and angular rows Ja (3 × N each, row-major, N = len(θ)) at θ."""
    chain, fid = sh.chain, sh.fid
    path = chain.path(fid)
    v_of = {j: k for k, j in enumerate(chain.independent)}
    g, R, p, frames = frame_product(chain, fid)
    outs = [v for row in R for v in row] + list(p)
    cols = []  # (θ index, factor, k-th output of the column)
    for pos, (i, (Rk, pk)) in enumerate(zip(path, frames)):
        j = chain.joints[i]
        ax = [float(x) for x in j.axis]
        z = [g.sum([g.mul(ax[k], Rk[r][k]) for k in range(3)]) for r in range(3)]
        if j.kind == PRISMATIC:
            lin, ang = z, [0.0, 0.0, 0.0]
        else:
            d = [g.add(p[r], g.mul(-1.0, pk[r])) for r in range(3)]
            lin = [
                g.add(g.mul(z[a], d[b]), g.mul(-1.0, g.mul(z[b], d[a])))
                for a, b in ((1, 2), (2, 0), (0, 1))
            ]
            ang = z
        src, fac = (j.mimic.source, j.mimic.multiplier) if j.is_mimic else (i, 1.0)
        cols.append((v_of[src], fac, len(outs)))
        outs += list(lin) + list(ang)
    nodes = [o for o in outs if not isinstance(o, float)]
    stmts, ref = straight_line(g, nodes, lambda inp: inp.name, lang="c", prefix="x")
    text = lambda o: _c(o) if isinstance(o, float) else ref(o)  # noqa: E731
    lines = ["static void fkj(const double *th, double *R, double *p, double *Jl, double *Ja) {"]
    for pos, i in enumerate(path):
        j = chain.joints[i]
        if j.is_mimic:
            a = f"{_c(j.mimic.multiplier)} * th[{v_of[j.mimic.source]}] + {_c(j.mimic.offset)}"
        else:
            a = f"th[{v_of[i]}]"
        if j.kind == PRISMATIC:
            lines.append(f"    const double q{pos} = {a};")
        else:
            lines.append(
                f"    const double a{pos} = {a}, c{pos} = cos(a{pos}), s{pos} = sin(a{pos});"
            )
            lines.append(f"    (void)c{pos}; (void)s{pos};")
    lines += [f"    const double {n} = {e};" for n, e in stmts]
    lines += [f"    R[{k}] = {text(outs[k])};" for k in range(9)]
    lines += [f"    p[{k}] = {text(outs[9 + k])};" for k in range(3)]
    lines.append(
        "    memset(Jl, 0, sizeof(double) * 3 * N); memset(Ja, 0, sizeof(double) * 3 * N);"
    )
    for v, fac, o in cols:
        f = "" if fac == 1.0 else f"{_c(fac)} * "
        for r in range(3):
            for dst, off in (("Jl", 0), ("Ja", 3)):
                val = outs[o + off + r]
                if isinstance(val, float) and val == 0.0:
                    continue
                lines.append(f"    {dst}[{r * sh.n + v}] += {f}{text(val)};")
    lines.append("}")
    return "\n".join(lines) + "\n"


def c_source(sh) -> str:
    """The whole C text for (robot, frame) of the Shared ``sh``."""
    arr = lambda name, xs: f"static const double {name}[N] = {{{', '.join(_c(x) for x in xs)}}};"  # noqa: E731
    head = [
        "/* anthroarm ik.solve attempt kernel; generated by anthroarm.ik.solve.ckernel */",
        "#define _POSIX_C_SOURCE 199309L",
        "#include <math.h>",
        "#include <string.h>",
        "#include <time.h>",
        f"#define N {sh.n}",
        arr("LO", sh.lo),
        arr("HI", sh.hi),
        f"#define LAMBDA0 {_c(kernel.LAMBDA0)}",
        f"#define K_DAMP {_c(kernel.K_DAMP)}",
        f"#define MAX_ITER {int(kernel.MAX_ITER)}",
        f"#define STALL {int(kernel.STALL)}",
        f"#define POSE {POSE}",
        f"#define POSITION {POSITION}",
        f"#define ORIENTATION {ORIENTATION}",
        f"static const double EPS = {_c(np.finfo(float).eps)};",
        f"static const double PREC2 = {_c(np.finfo(float).eps ** (1.0 / 3.0))};   /* eps^(1/3): Taylor degree 2 */",
        f"static const double PI_ = {_c(math.pi)};",
    ]
    return "\n".join(head) + "\n" + fk_jacobian_source(sh) + _LM


_LM = r"""
/* ---- log3 / log6 as pinocchio/src/spatial/log.hxx, with Eigen's order of 3-term sums: a
   strided sum (a trace) x0 + (x1 + x2), a contiguous one (norms, dots: SIMD) (x0 + x1) + x2 ---- */
static double sum3(double a, double b, double c) { return a + (b + c); }
static double vsum3(double a, double b, double c) { return (a + b) + c; }

static void theta_axis(int i0, double val, const double *R, double *angle, double *axis) {
    const int i1 = (i0 + 1) % 3, i2 = (i0 + 2) % 3;
    const double s = sqrt(val + EPS + EPS * EPS) * (R[3 * i2 + i1] >= R[3 * i1 + i2] ? 1.0 : -1.0);
    axis[i0] = s / 2.0;
    axis[i1] = 1.0 / (2.0 * s) * (R[3 * i1 + i0] + R[3 * i0 + i1]);
    axis[i2] = 1.0 / (2.0 * s) * (R[3 * i2 + i0] + R[3 * i0 + i2]);
    const double w = 1.0 / (2.0 * s) * (R[3 * i2 + i1] - R[3 * i1 + i2]);
    const double an = sqrt(vsum3(axis[0] * axis[0], axis[1] * axis[1], axis[2] * axis[2]));
    *angle = 2.0 * atan2(an, w);
    axis[0] /= an; axis[1] /= an; axis[2] /= an;
}

static void cross(const double *a, const double *b, double *c) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* w = log3(R) (R row-major), *theta its angle */
static void log3(const double *R, double *theta, double *w) {
    double Rn[9], c0[3], c1[3], c2[3];
    const double n0 = sqrt(vsum3(R[0] * R[0], R[3] * R[3], R[6] * R[6]));
    const double n1 = sqrt(vsum3(R[1] * R[1], R[4] * R[4], R[7] * R[7]));
    c0[0] = R[0] / n0; c0[1] = R[3] / n0; c0[2] = R[6] / n0;
    c1[0] = R[1] / n1; c1[1] = R[4] / n1; c1[2] = R[7] / n1;
    cross(c0, c1, c2);
    cross(c1, c2, c0);
    for (int r = 0; r < 3; ++r) { Rn[3 * r] = c0[r]; Rn[3 * r + 1] = c1[r]; Rn[3 * r + 2] = c2[r]; }
    const double tr = sum3(Rn[0], Rn[4], Rn[8]);
    const double cv = (tr - 1.0) / 2.0;
    const double acos_exp = sqrt(2.0 * (1.0 - cv) + EPS * EPS);
    const double thn = tr <= 3.0 - PREC2 ? (tr >= -1.0 + PREC2 ? acos(cv) : PI_ - acos_exp) : acos_exp;
    if (cv >= -1.0 + PREC2) {
        const double a[3] = {0.5 * (Rn[7] - Rn[5]), 0.5 * (Rn[2] - Rn[6]), 0.5 * (Rn[3] - Rn[1])};
        const double n2 = vsum3(a[0] * a[0], a[1] * a[1], a[2] * a[2]);
        const double t = thn >= PREC2 ? thn / sin(thn) : 1.0 + n2 / 6.0 + n2 * n2 * 3.0 / 40.0;
        *theta = thn;
        w[0] = t * a[0]; w[1] = t * a[1]; w[2] = t * a[2];
        return;
    }
    double val[3], ax[3][3], th[3];
    for (int k = 0; k < 3; ++k) val[k] = 2.0 * Rn[4 * k] - tr + 1.0;
    for (int k = 0; k < 3; ++k) theta_axis(k, val[k], Rn, &th[k], ax[k]);
    const int b = val[0] >= val[1] ? (val[0] >= val[2] ? 0 : 2) : (val[1] >= val[2] ? 1 : 2);
    *theta = th[b];
    for (int k = 0; k < 3; ++k) w[k] = th[b] * ax[b][k];
}

/* e = log6(R, p) = (v, w) */
static void log6(const double *R, const double *p, double *e) {
    const double a[3] = {0.5 * (R[7] - R[5]), 0.5 * (R[2] - R[6]), 0.5 * (R[3] - R[1])};
    const double t2 = vsum3(a[0] * a[0], a[1] * a[1], a[2] * a[2]);
    const double tr = sum3(R[0], R[4], R[8]);
    double theta, w[3], wxp[3];
    log3(R, &theta, w);
    const double st = sin(theta), ct = cos(theta);
    double alpha, beta;
    if (tr >= 3.0 - PREC2) {
        alpha = 1.0 - t2 / 12.0 - t2 * t2 / 720.0;
        beta = 1.0 / 12.0 + t2 / 720.0;
    } else {
        alpha = theta * st / (2.0 * (1.0 - ct));
        beta = 1.0 / (theta * theta) - st / (2.0 * theta * (1.0 - ct));
    }
    cross(w, p, wxp);
    const double bwp = beta * vsum3(w[0] * p[0], w[1] * p[1], w[2] * p[2]);
    for (int k = 0; k < 3; ++k) { e[k] = alpha * p[k] - 0.5 * wxp[k] + bwp * w[k]; e[3 + k] = w[k]; }
}

/* ---- the target's residual and Jacobian (targets.Target.residual / .jacobian) ---- */
typedef struct {
    int kind, m;
    const double *Rs, *ps;       /* R* row-major (pose, orientation), p* (pose, position) */
    double tp2, tr2, tsum;
    double R[9], p[3], Jl[3 * N], Ja[3 * N];
} State;

/* e (m,), returns E = |e|^2; *pe2, *re2 as Target.residual (HUGE_VAL: a pose surely unconverged) */
static double residual(State *S, const double *th, double *e, double *pe2, double *re2) {
    fkj(th, S->R, S->p, S->Jl, S->Ja);
    const double *R = S->R;
    if (S->kind == POSE) {
        double Rt[9], d[3], pt[3];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                Rt[3 * r + c] = sum3(R[r] * S->Rs[c], R[3 + r] * S->Rs[3 + c], R[6 + r] * S->Rs[6 + c]);
        for (int k = 0; k < 3; ++k) d[k] = S->ps[k] - S->p[k];
        for (int r = 0; r < 3; ++r) pt[r] = sum3(R[r] * d[0], R[3 + r] * d[1], R[6 + r] * d[2]);
        log6(Rt, pt, e);
        double E = 0.0;
        for (int k = 0; k < 6; ++k) E += e[k] * e[k];
        if (E > S->tsum) { *pe2 = HUGE_VAL; *re2 = HUGE_VAL; return E; }
        *pe2 = (pt[0] * pt[0] + pt[1] * pt[1]) + pt[2] * pt[2];
        *re2 = (e[3] * e[3] + e[4] * e[4]) + e[5] * e[5];
        return E;
    }
    if (S->kind == POSITION) {
        for (int k = 0; k < 3; ++k) e[k] = S->ps[k] - S->p[k];
        const double E = (e[0] * e[0] + e[1] * e[1]) + e[2] * e[2];
        *pe2 = E; *re2 = 0.0;
        return E;
    }
    double Rt[9], theta;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            Rt[3 * r + c] = (R[r] * S->Rs[c] + R[3 + r] * S->Rs[3 + c]) + R[6 + r] * S->Rs[6 + c];
    log3(Rt, &theta, e);
    const double E = (e[0] * e[0] + e[1] * e[1]) + e[2] * e[2];
    *pe2 = 0.0; *re2 = E;
    return E;
}

/* J (m x N, row-major) of the last residual, in the frame of its error */
static void jacobian(const State *S, double *J) {
    const double *R = S->R;
    if (S->kind == POSITION) { memcpy(J, S->Jl, sizeof(double) * 3 * N); return; }
    double *Ja = S->kind == POSE ? J + 3 * N : J;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < N; ++c) {
            Ja[r * N + c] = sum3(R[r] * S->Ja[c], R[3 + r] * S->Ja[N + c], R[6 + r] * S->Ja[2 * N + c]);
            if (S->kind == POSE)
                J[r * N + c] = sum3(R[r] * S->Jl[c], R[3 + r] * S->Jl[N + c], R[6 + r] * S->Jl[2 * N + c]);
        }
}

/* ---- kernel.solve_damped: Cholesky of the m x m (or N x N when N < m) damped system ---- */
static int cholesky_solve(double *A, int k, double *x) {   /* A k x k symmetric, x: rhs -> solution */
    for (int j = 0; j < k; ++j) {
        double ajj = A[j * k + j];
        for (int l = 0; l < j; ++l) ajj -= A[j * k + l] * A[j * k + l];
        if (ajj <= 0.0 || ajj != ajj) return 0;          /* as LAPACK dpotrf: info > 0 */
        ajj = sqrt(ajj);
        A[j * k + j] = ajj;
        for (int i = j + 1; i < k; ++i) {
            double a = A[i * k + j];
            for (int l = 0; l < j; ++l) a -= A[i * k + l] * A[j * k + l];
            A[i * k + j] = a / ajj;
        }
    }
    for (int i = 0; i < k; ++i) {
        double a = x[i];
        for (int l = 0; l < i; ++l) a -= A[i * k + l] * x[l];
        x[i] = a / A[i * k + i];
    }
    for (int i = k - 1; i >= 0; --i) {
        double a = x[i];
        for (int l = i + 1; l < k; ++l) a -= A[l * k + i] * x[l];
        x[i] = a / A[i * k + i];
    }
    return 1;
}

static int solve_damped(const double *J, int m, const double *e, double lam, double *dq) {
    if (m <= N) {
        double A[36], x[6];
        for (int i = 0; i < m; ++i) {
            for (int k = 0; k <= i; ++k) {
                double s = 0.0;
                for (int c = 0; c < N; ++c) s += J[i * N + c] * J[k * N + c];
                A[i * m + k] = s; A[k * m + i] = s;
            }
            A[i * m + i] += lam;
            x[i] = e[i];
        }
        if (!cholesky_solve(A, m, x)) return 0;
        for (int c = 0; c < N; ++c) {
            double s = 0.0;
            for (int i = 0; i < m; ++i) s += x[i] * J[i * N + c];
            dq[c] = s;
        }
        return 1;
    }
    double A[N * N];
    for (int a = 0; a < N; ++a) {
        for (int b = 0; b <= a; ++b) {
            double s = 0.0;
            for (int i = 0; i < m; ++i) s += J[i * N + a] * J[i * N + b];
            A[a * N + b] = s; A[b * N + a] = s;
        }
        A[a * N + a] += lam;
        double s = 0.0;
        for (int i = 0; i < m; ++i) s += e[i] * J[i * N + a];
        dq[a] = s;
    }
    return cholesky_solve(A, N, dq);
}

static double clip(double x, int c) { return x < LO[c] ? LO[c] : (x > HI[c] ? HI[c] : x); }

/* kernel.damped_step: 0 where the system is not positive definite */
static int damped_step(const double *th, const double *J, int m, const double *e, double lam, double *out) {
    double dq[N], tn[N];
    if (!solve_damped(J, m, e, lam, dq)) return 0;
    int hit = 0;
    for (int c = 0; c < N; ++c) {
        tn[c] = th[c] + dq[c];
        out[c] = clip(tn[c], c);
        if (memcmp(&out[c], &tn[c], sizeof(double))) hit = 1;
    }
    if (hit) {   /* active set: freeze the joints the step pushes past a limit, recompute, clip */
        double Jm[6 * N];
        for (int i = 0; i < m; ++i)
            for (int c = 0; c < N; ++c) Jm[i * N + c] = out[c] == tn[c] ? J[i * N + c] : 0.0;
        if (solve_damped(Jm, m, e, lam, dq))
            for (int c = 0; c < N; ++c) out[c] = clip(th[c] + dq[c], c);
    }
    return 1;
}

static double cpu_clock(void) {
#ifdef CLOCK_THREAD_CPUTIME_ID
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0) return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return -HUGE_VAL;   /* no thread CPU clock: MAX_ITER bounds the attempt */
}

/* kernel.attempt.  T: the target, 4 x 4 row-major homogeneous; out: it, pe2, re2, best E.
   th_out: the last iterate; best: the iterate of least |e|^2.  Returns converged. */
int aa_attempt(const double *th0, int kind, const double *T, double tp2, double tr2, double tsum,
               double deadline, double *th_out, double *best, double *out) {
    State S;
    double Rs[9], ps[3];
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) Rs[3 * r + c] = T[4 * r + c];
        ps[r] = T[4 * r + 3];
    }
    S.kind = kind; S.m = kind == POSE ? 6 : 3; S.Rs = Rs; S.ps = ps;
    S.tp2 = tp2; S.tr2 = tr2; S.tsum = tsum;
    double th[N], tn[N], e[6], J[6 * N];
    double ref_E = HUGE_VAL, best_E = HUGE_VAL, pe2 = 0.0, re2 = 0.0;
    int stall = 0, it = 0, ok = 0;
    memcpy(th, th0, sizeof th);
    memcpy(best, th0, sizeof th);
    while (it < MAX_ITER) {
        it += 1;
        const double E = residual(&S, th, e, &pe2, &re2);
        if (pe2 <= tp2 && re2 <= tr2) { ok = 1; best_E = E; memcpy(best, th, sizeof th); break; }
        if (E < best_E) { best_E = E; memcpy(best, th, sizeof th); }
        if (E < 0.9 * ref_E) { ref_E = E; stall = 0; }
        else if (++stall >= STALL) break;
        if (!(it & 7) && cpu_clock() > deadline) break;
        jacobian(&S, J);
        if (!damped_step(th, J, S.m, e, LAMBDA0 + K_DAMP * E, tn)) break;
        memcpy(th, tn, sizeof th);
    }
    memcpy(th_out, th, sizeof th);
    out[0] = it; out[1] = pe2; out[2] = re2; out[3] = best_E;
    return ok;
}

/* for the tests: the frame's pose (R row-major 9, p 3) and the LWA Jacobian (6 x N) at th */
void aa_fkj(const double *th, double *Rp, double *J) {
    double R[9], p[3];
    fkj(th, R, p, J, J + 3 * N);
    memcpy(Rp, R, sizeof R); memcpy(Rp + 9, p, sizeof p);
}

/* for the tests: log3 of R (row-major), log6 of (R, p) */
void aa_log3(const double *R, double *w) { double t; log3(R, &t, w); }
void aa_log6(const double *R, const double *p, double *e) { log6(R, p, e); }
"""


# ---------------------------------------------------------------------------- loading
_P = ctypes.c_void_p
_D = ctypes.c_double


class CKernel:
    """ctypes handle of one compiled attempt kernel (no reference to a Robot)."""

    def __init__(self, path, n: int):
        lib = self.lib = ctypes.CDLL(str(path))
        f = lib.aa_attempt
        f.restype = ctypes.c_int
        f.argtypes = [_P, ctypes.c_int, _P, _D, _D, _D, _D, _P, _P, _P]
        self.fn = f
        for name, args in (
            ("aa_fkj", [_P, _P, _P]),
            ("aa_log3", [_P, _P]),
            ("aa_log6", [_P, _P, _P]),
        ):
            getattr(lib, name).argtypes = args
            getattr(lib, name).restype = None
        self.n = n
        self.path = path

    def fk_jacobian(self, th):
        """(R (3, 3), p (3,), J (6, n) LOCAL_WORLD_ALIGNED) at θ (for the tests)."""
        th = np.ascontiguousarray(th, dtype=float)
        Rp, J = np.empty(12), np.empty((6, self.n))
        self.lib.aa_fkj(th.ctypes.data, Rp.ctypes.data, J.ctypes.data)
        return Rp[:9].reshape(3, 3), Rp[9:].copy(), J

    def log3(self, R):
        R = np.ascontiguousarray(R, dtype=float)
        w = np.empty(3)
        self.lib.aa_log3(R.ctypes.data, w.ctypes.data)
        return w

    def log6(self, R, p):
        R, p = np.ascontiguousarray(R, dtype=float), np.ascontiguousarray(p, dtype=float)
        e = np.empty(6)
        self.lib.aa_log6(R.ctypes.data, p.ctypes.data, e.ctypes.data)
        return e


def build(sh, compile: bool = True) -> CKernel | None:
    """Compile (or load from the disk cache) the kernel of the Shared ``sh``; with
    ``compile=False`` only load it (None if the cache does not hold it).  Raises RuntimeError
    (:class:`anthroarm.cache.CompileError`) or OSError on failure."""
    cc = cache.compiler()
    if cc is None:
        raise cache.CompileError("no C compiler ($CC or cc)")
    src = c_source(sh)
    k = cache.key(src, cache.compiler_id(cc), " ".join(FLAGS))
    with _LOCK:
        kern = _LIBS.get(k)
    if kern is None:  # compiled outside the lock: a cached library loads meanwhile
        made = cache.shared_library("ik", "lm", src, FLAGS, compile=compile)
        if made is None:
            return None
        with _LOCK:
            kern = _LIBS.setdefault(k, CKernel(made[0], sh.n))
    return kern


def kernel_for(sh) -> CKernel | None:
    """The compiled kernel of the Shared ``sh`` (built once, kept on it), or None (disabled,
    no compiler, compilation failed: :func:`status` says which)."""
    return KERNELS.get(sh, "ckernel", build, "attempt kernel")


class Buffers:
    """A thread's arrays for :func:`attempt` and their addresses (one per Workspace): θ in,
    the target as a 4 × 4 row-major homogeneous matrix (a pose; a position fills its last
    column, a rotation its upper-left block), θ out, best θ, and (iterations, pos_err²,
    rot_err², best ‖e‖²)."""

    __slots__ = (
        "fn",
        "th",
        "T",
        "th_out",
        "best",
        "out",
        "p_th",
        "p_T",
        "p_out",
        "p_best",
        "p_info",
    )

    def __init__(self, kern: CKernel, n: int):
        self.fn = kern.fn
        self.th, self.th_out, self.best, self.out = (
            np.empty(n),
            np.empty(n),
            np.empty(n),
            np.empty(4),
        )
        self.T = np.eye(4)
        self.p_th, self.p_T, self.p_out, self.p_best, self.p_info = (
            a.ctypes.data for a in (self.th, self.T, self.th_out, self.best, self.out)
        )


def ready(ws) -> bool:
    """True where the compiled kernel serves the workspace ``ws`` (its buffers made on first
    use); False where the Python kernel runs (``ANTHROARM_IK_C=0``, no compiler, build failed)."""
    if ws.cbuf is not None:
        return enabled()
    kern = kernel_for(ws.sh)
    if kern is None:
        return False
    ws.cbuf = Buffers(kern, ws.n)
    return True


def attempt(ws, tg, th, deadline):
    """:func:`.kernel.attempt` in C: the same arguments and the same tuple (θ, converged,
    iterations, pos_err², rot_err², best θ, best ‖e‖²); θ and best θ are fresh arrays."""
    b = ws.cbuf
    b.th[:] = th
    kind = tg.kind
    if kind == POSE:
        b.T[:] = tg.H
    elif kind == POSITION:
        b.T[:3, 3] = tg.ps
    else:
        b.T[:3, :3] = tg.Rs
    ok = b.fn(b.p_th, kind, b.p_T, tg.tp2, tg.tr2, tg.tsum, deadline, b.p_out, b.p_best, b.p_info)
    it, pe2, re2, bE = b.out.tolist()
    t = b.th_out.copy()
    if ok:
        return t, True, int(it), pe2, re2, t, bE
    return t, False, int(it), pe2, re2, b.best.copy(), bE
