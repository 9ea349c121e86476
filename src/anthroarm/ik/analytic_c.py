"""Optional compiled kernel of the closed-form IK (the fastest path of ``aa.ik.analytic``).

The C99 text below is a line-by-line transcription of the scalar kernels of
:mod:`anthroarm.ik.analytic_scalar` (same formulas, branch order, limit wrap, pruning and
tolerances; the equations are cited there), plus the FK check generated from ``robot.chain`` by
:mod:`anthroarm.ik.fk_codegen` (the same expression graph, rendered as C), plus input validation
(finite, last row [0, 0, 0, 1], orthonormal rotation with det ≥ 0) and the duplicate filter of
the general path.  One shared library per robot parameterisation (lengths, limits and joint
placements are compile-time constants) is compiled with the system C compiler (``$CC``, default
``cc``; ``-O2 -fno-fast-math -ffp-contract=off``, so IEEE results equal the Python kernels' up
to the libm) on first use and kept in the one disk cache (:func:`anthroarm.cache.shared_library`:
``ik/analytic_<model>_<hash>.so`` keyed by the source, compiler and flags, verified before it is
loaded, written atomically); it is called through :mod:`ctypes`.

Nothing here is required: without a compiler, if compilation fails, or with the environment
variable ``ANTHROARM_IK_C=0``, :func:`kernel_for` returns None and ``closed_form`` uses the
pure-Python kernels.  :func:`status` says which applies.
"""

from __future__ import annotations

import ctypes
import math
import os
import threading
from pathlib import Path

import numpy as np

FLAGS = ["-O2", "-fPIC", "-shared", "-std=c99", "-fno-fast-math", "-ffp-contract=off"]
#: largest swivel grid of a single-pose call served by the kernel's persistent buffers
MAX_SINGLE_S = 64
_LOCK = threading.Lock()
_LIBS: dict[str, "CKernel"] = {}

from .. import cache  # noqa: E402
from ..cache import compiler  # noqa: E402

#: the closed-form kernels: one per plan, switched off by ANTHROARM_IK_C=0
KERNELS = cache.CompiledOnce("ANTHROARM_IK_C", "pure-Python kernels", "available (compiled on first use per robot)")
enabled = KERNELS.enabled
status = KERNELS.status


# ---------------------------------------------------------------------------- C text
_COMMON = r"""
#include <math.h>
#include <string.h>

#define OK 0
#define OUTSIDE 1
#define ELBOW 2
#define DEGENERATE 3
#define OUT_OF_PLANE 4
#define WRAP_TOL 1e-9
static const double PI_ = 3.141592653589793;
static const double HALF_PI_ = 1.5707963267948966;
static const double TWO_PI_ = 6.283185307179586;

/* q shifted by a multiple of 2 pi into [LO, HI] of joint j (clipped within WRAP_TOL); 0 if outside */
static int wrap(double q, int j, double *out) {
    if (FLO[j] <= q && q <= FHI[j]) { *out = q; return 1; }
    const double qw = q - floor((q - LOF[j] + WRAP_TOL) / TWO_PI_) * TWO_PI_;
    if (!(LO[j] - WRAP_TOL <= qw && qw <= HI[j] + WRAP_TOL)) return 0;
    *out = qw < LO[j] ? LO[j] : (qw > HI[j] ? HI[j] : qw);
    return 1;
}

static void emit(int b, const double *q, double r, double tol, double *Q, double *res,
                 unsigned char *valid, unsigned char *inside) {
    memcpy(Q + (long)b * NQ, q, NQ * sizeof(double));
    res[b] = r;
    inside[b] = 1;
    valid[b] = r <= tol;
}

/* the checks of closed_form._check_poses */
static int pose_ok(const double *T, int po, double tolo) {
    for (int i = 0; i < 16; i++) if (!isfinite(T[i])) return 0;
    if (fabs(T[12]) > 1e-12 || fabs(T[13]) > 1e-12 || fabs(T[14]) > 1e-12 || fabs(T[15] - 1.0) > 1e-12) return 0;
    if (po) return 1;
    const double a = T[0], b = T[1], c = T[2], d = T[4], e = T[5], f = T[6], g = T[8], h = T[9], i = T[10];
    const double v[6] = {fabs(a * a + d * d + g * g - 1.0), fabs(b * b + e * e + h * h - 1.0),
                         fabs(c * c + f * f + i * i - 1.0), fabs(a * b + d * e + g * h),
                         fabs(a * c + d * f + g * i), fabs(b * c + e * f + h * i)};
    double err = v[0];
    for (int k = 1; k < 6; k++) if (v[k] > err) err = v[k];
    const double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    return !(err > tolo || det < 0.0);
}

/* drop solutions within 1e-9 rad (every joint) of an earlier valid one */
static void dedup(long B, const double *Q, unsigned char *valid) {
    for (long b = 1; b < B; b++) {
        if (!valid[b]) continue;
        for (long p = 0; p < b; p++) {
            if (!valid[p]) continue;
            double m = 0.0;
            for (int j = 0; j < NQ; j++) {
                const double d = fabs(Q[p * NQ + j] - Q[b * NQ + j]);
                if (d > m) m = d;
            }
            if (m < 1e-9) { valid[b] = 0; break; }
        }
    }
}
"""

_SIXR = r"""
static void solve_one(const double *T, const double *sw, long S, double tol, int po, double *Q, double *res,
                      unsigned char *valid, unsigned char *inside, int *code, int *sing) {
    (void)sw; (void)S;
    const double ux = T[0], ax = T[2], px = T[3], uy = T[4], ay = T[6], py = T[7], uz = T[8], az = T[10], pz = T[11];
    const double dx = px - P_P * ax, dy = py - P_P * ay, dz = pz - P_P * az - P_s0;
    const double rxy = sqrt(dx * dx + dy * dy);
    const int ssing = rxy < 1e-12;
    int wsing = 0;
    double th1a, c1, s1;
    if (ssing) { th1a = 0.0; c1 = 1.0; s1 = 0.0; }
    else { th1a = atan2(dy, dx); c1 = cos(th1a); s1 = sin(th1a); }                  /* (7-2) */
    const double X = dx * c1 + dy * s1;
    double k = (X * X + dz * dz - P_h2 * P_h2 - P_s3 * P_s3) / (2.0 * P_h2 * P_s3);   /* (7-6) */
    if (fabs(k) > 1.0 + 1e-12) { *code = OUTSIDE; return; }
    k = k > 1.0 ? 1.0 : (k < -1.0 ? -1.0 : k);
    const double ask = asin(k), c3a = cos(ask);
    const double th3s[2] = {ask, PI_ - ask};
    const double phis[2] = {atan2(-P_s3 * c3a, P_h2 + P_s3 * k), atan2(P_s3 * c3a, P_h2 + P_s3 * k)};
    double st0[64], st1[64], q[NQ];
    for (int sh = 0; sh < 2; sh++) {
        double th1, C1, S1, Xs;
        if (sh == 0) { th1 = th1a; C1 = c1; S1 = s1; Xs = X; }
        else { th1 = th1a + PI_; C1 = -c1; S1 = -s1; Xs = -X; }
        const int ok1 = wrap(th1, 0, &q[0]);
        const double psi = atan2(dz, Xs);
        const double ha = C1 * ax + S1 * ay, hu = C1 * ux + S1 * uy;
        const double Mm = S1 * ax - C1 * ay, Mx1 = S1 * ux - C1 * uy;
        if (ok1) (po ? fkp_0 : fk_0)(0, q, st0);
        for (int el = 0; el < 2; el++) {
            const double th3 = th3s[el], th2 = psi - phis[el], th23 = th2 + th3;      /* (7-4) */
            const double c23 = cos(th23), s23 = sin(th23);
            const double L = c23 * ha + s23 * az, N = s23 * ha - c23 * az;
            const double Mx0 = c23 * hu + s23 * uz, Mx2 = s23 * hu - c23 * uz;
            const double rho = sqrt(L * L + Mm * Mm);
            double th4a, c4, s4;
            if (rho < 1e-12) { wsing = 1; th4a = 0.0; c4 = 1.0; s4 = 0.0; }
            else { th4a = atan2(Mm, L); c4 = L / rho; s4 = Mm / rho; }             /* (7-8) */
            if (!ok1) continue;
            if (!wrap(th2, 1, &q[1]) || !wrap(th3, 2, &q[2])) continue;
            (po ? fkp_1 : fk_1)(st0, q + 1, st1);
            const double a5 = c4 * L + s4 * Mm;
            const double th5 = atan2(a5, -N);                                       /* (7-12) corr. */
            const double n5 = sqrt(a5 * a5 + N * N);
            const double c5 = -N / n5, s5 = a5 / n5;
            const double y6 = s4 * Mx0 - c4 * Mx1;
            const double x6 = c4 * c5 * Mx0 + s4 * c5 * Mx1 + s5 * Mx2;
            for (int wr = 0; wr < 2; wr++) {
                double th4, th5w, th6;
                if (wr == 0) { th4 = th4a; th5w = th5; th6 = atan2(y6, x6); }           /* (7-14) */
                else { th4 = th4a + PI_; th5w = -th5; th6 = atan2(-y6, -x6); }
                if (!wrap(th4, 3, &q[3]) || !wrap(th5w, 4, &q[4]) || !wrap(th6, 5, &q[5])) continue;
                const double r = (po ? fkp_2 : fk_2)(st1, q + 3, T);
                emit(sh * 4 + el * 2 + wr, q, r, tol, Q, res, valid, inside);
            }
        }
    }
    *sing = ssing ? 2 : (wsing ? 1 : 0);
}
"""

_PROSTHETIC = r"""
static void solve_one(const double *T, const double *sw, long S, double tol, int po, double *Q, double *res,
                      unsigned char *valid, unsigned char *inside, int *code, int *sing) {
    (void)sw; (void)S;
    const double l1_ = T[0], m1 = T[1], n1 = T[2], x = T[3], l2_ = T[4], m2 = T[5], n2 = T[6], y = T[7];
    const double l3_ = T[8], m3 = T[9], n3 = T[10], z = T[11];
    const double L1 = P_L1, L2 = P_L2, L3 = P_L3;
    const double Wx = x - L3 * n1, Wy = y - L3 * n2, Wz = z - L3 * n3;
    const double W2 = (Wx * Wx + Wz * Wz) + Wy * Wy;
    const double c4 = (W2 - L1 * L1 - L2 * L2) / (2.0 * L1 * L2);                  /* (7-24) */
    if (fabs(c4) > 1.0 + 1e-12) { *code = OUTSIDE; return; }
    const double th4p = acos(c4 > 1.0 ? 1.0 : (c4 < -1.0 ? -1.0 : c4));
    const double h = 0.5 * (L1 * L1 + W2 - L2 * L2);
    const double g = (Wx * m1 + Wz * m3) + Wy * m2;
    const double dX = Wy * m3 - Wz * m2, dY = Wz * m1 - Wx * m3, dZ = Wx * m2 - Wy * m1;
    const double dd = (dX * dX + dZ * dZ) + dY * dY;
    if (dd < 1e-14 * (W2 > 1e-30 ? W2 : 1e-30)) { *code = DEGENERATE; return; }
    const double alpha = (h - g * g) / dd, beta = (W2 * g - g * h) / dd;
    const double E0x = alpha * Wx + beta * m1, E0y = alpha * Wy + beta * m2, E0z = alpha * Wz + beta * m3;
    const double disc = (L1 * L1 - ((E0x * E0x + E0z * E0z) + E0y * E0y)) / dd;    /* (7-22) */
    if (disc < -1e-12) { *code = ELBOW; return; }
    const double t = disc > 0.0 ? sqrt(disc) : 0.0;
    const int el_sing = fabs(sin(th4p)) < 1e-12;
    const double s4p = sin(th4p), c4p = cos(th4p);
    int sh_any = 0;
    const double S4f[2] = {s4p, -s4p};
    double q4s[2];
    const int q4ok[2] = {wrap(th4p, 3, &q4s[0]), wrap(-th4p, 3, &q4s[1])};
    double st0[64], q[NQ];
    for (int root = 0; root < 2; root++) {
        const double tr = root == 0 ? t : -t;
        const double Ex = E0x + tr * dX, Ey = E0y + tr * dY, Ez = E0z + tr * dZ;
        const double zx = Ex / L1, zy = Ey / L1, zz = Ez / L1;
        double mz = -zz;
        mz = mz > 1.0 ? 1.0 : (mz < -1.0 ? -1.0 : mz);
        const double th2a = acos(mz);                                               /* (7-19) */
        const double rz = sqrt(zx * zx + zy * zy);
        double th1a, c1a, s1a;
        if (rz < 1e-12) { sh_any = 1; th1a = -HALF_PI_; c1a = 0.0; s1a = -1.0; }
        else { th1a = atan2(zy, zx); c1a = zx / rz; s1a = zy / rz; }                 /* (7-18) */
        const double c2a = mz, s2a = sqrt((1.0 - mz) * (1.0 + mz));
        const double ux = (Wx - Ex) / L2, uy = (Wy - Ey) / L2, uz = (Wz - Ez) / L2;
        for (int sh = 0; sh < 2; sh++) {
            double th1, th2, c1, s1, c2, s2;
            if (sh == 0) { th1 = th1a; th2 = th2a; c1 = c1a; s1 = s1a; c2 = c2a; s2 = s2a; }
            else { th1 = th1a + PI_; th2 = -th2a; c1 = -c1a; s1 = -s1a; c2 = c2a; s2 = -s2a; }
            if (!wrap(th1, 0, &q[0]) || !wrap(th2, 1, &q[1])) continue;
            const double a00 = c1 * c2, a01 = s1, a02 = c1 * s2;
            const double a10 = s1 * c2, a11 = -c1, a12 = s1 * s2;
            const double a20 = s2, a22 = -c2;
            const double v0 = a00 * ux + a10 * uy + a20 * uz;                       /* (7-26) */
            const double v1 = a01 * ux + a11 * uy;
            (po ? fkp_0 : fk_0)(0, q, st0);
            for (int fx = 0; fx < 2; fx++) {
                if (!q4ok[fx]) continue;
                q[3] = q4s[fx];
                const double C4 = c4p, S4 = S4f[fx];
                double th3, c3, s3;
                if (el_sing) { th3 = 0.0; c3 = 0.0; s3 = 1.0; }
                else {
                    const double sg = S4 >= 0 ? 1.0 : -1.0;
                    const double y3 = sg * v0, x3 = -sg * v1;
                    th3 = atan2(y3, x3);
                    const double r3 = sqrt(x3 * x3 + y3 * y3);
                    if (r3 > 0.0) { c3 = -y3 / r3; s3 = x3 / r3; } else { c3 = 0.0; s3 = 1.0; }
                }
                if (!wrap(th3, 2, &q[2])) continue;
                const double b00 = a00 * c3 + a01 * s3, b02 = a00 * s3 - a01 * c3;
                const double b10 = a10 * c3 + a11 * s3, b12 = a10 * s3 - a11 * c3;
                const double b20 = a20 * c3, b22 = a20 * s3;
                const double r00 = b00 * C4 + a02 * S4, r10 = b10 * C4 + a12 * S4, r20 = b20 * C4 + a22 * S4;
                const double r02 = a02 * C4 - b00 * S4, r12 = a12 * C4 - b10 * S4, r22 = a22 * C4 - b20 * S4;
                const double M01 = r00 * m1 + r10 * m2 + r20 * m3;                  /* (7-28) */
                const double M11 = -(b02 * m1 + b12 * m2 + b22 * m3);
                const double th5 = atan2(-M01, M11);
                if (!wrap(th5, 4, &q[4])) continue;
                const double n5 = sqrt(M01 * M01 + M11 * M11);
                double c5 = 1.0, s5 = 0.0;
                if (n5 > 0.0) { c5 = M11 / n5; s5 = -M01 / n5; }
                const double M00 = r00 * l1_ + r10 * l2_ + r20 * l3_;
                const double M10 = -(b02 * l1_ + b12 * l2_ + b22 * l3_);
                const double M20 = r02 * l1_ + r12 * l2_ + r22 * l3_;
                const double th6 = atan2(M20, c5 * M00 + s5 * M10);                  /* (7-30)/(7-31) */
                if (!wrap(th6, 5, &q[5])) continue;
                const double r = (po ? fkp_1 : fk_1)(st0, q + 2, T);
                emit(root * 4 + sh * 2 + fx, q, r, tol, Q, res, valid, inside);
            }
        }
    }
    *sing = sh_any ? 2 : (el_sing ? 1 : 0);
}
"""

_PLANAR = r"""
static void solve_one(const double *T, const double *sw, long S, double tol, int po, double *Q, double *res,
                      unsigned char *valid, unsigned char *inside, int *code, int *sing) {
    (void)sw; (void)S; (void)sing;
    const double x = T[3], y = T[7], z = T[11], l1 = P_l1, l2 = P_l2;
    if (fabs(x) > 1e-9 * (l1 + l2 > 1.0 ? l1 + l2 : 1.0)) { *code = OUT_OF_PLANE; return; }
    const double c2 = (y * y + z * z - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
    if (fabs(c2) > 1.0 + 1e-12) { *code = OUTSIDE; return; }
    const double t2 = acos(c2 > 1.0 ? 1.0 : (c2 < -1.0 ? -1.0 : c2));
    const double base = atan2(z, y), s2 = sin(t2), c2c = cos(t2);
    double q[NQ];
    for (int b = 0; b < 2; b++) {
        const double th2 = b == 0 ? t2 : -t2, sn = b == 0 ? s2 : -s2;
        const double th1 = base - atan2(l2 * sn, l1 + l2 * c2c);
        if (!wrap(th1, 0, &q[0]) || !wrap(th2, 1, &q[1])) continue;
        const double r = (po ? fkp_0 : fk_0)(0, q, T);
        emit(b, q, r, tol, Q, res, valid, inside);
    }
}
"""

_HUMAN = r"""
static void solve_one(const double *T, const double *sw, long S, double tol, int po, double *Q, double *res,
                      unsigned char *valid, unsigned char *inside, int *code, int *sing) {
    const double r00 = T[0], r01 = T[1], r02 = T[2], hx = T[3], r10 = T[4], r11 = T[5], r12 = T[6], hy = T[7];
    const double r20 = T[8], r21 = T[9], r22 = T[10], hz = T[11];
    const double l1 = P_l1, l2 = P_l2, l3 = P_l3;
    const double Wx = hx + l3 * r02, Wy = hy + l3 * r12, Wz = hz + l3 * r22;
    const double Wn = sqrt(Wx * Wx + Wy * Wy + Wz * Wz);
    const double c4 = (Wn * Wn - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
    if (fabs(c4) > 1.0 + 1e-12 || Wn < 1e-12) { *code = OUTSIDE; return; }
    const double q4p = acos(c4 > 1.0 ? 1.0 : (c4 < -1.0 ? -1.0 : c4));
    const double nx = Wx / Wn, ny = Wy / Wn, nz = Wz / Wn;
    double ux = nz * nx, uy = nz * ny, uz = -1.0 + nz * nz;
    double nu = sqrt(ux * ux + uy * uy + uz * uz);
    if (nu < 1e-9) { ux = ny * nx; uy = -1.0 + ny * ny; uz = ny * nz; nu = sqrt(ux * ux + uy * uy + uz * uz); }
    ux /= nu; uy /= nu; uz /= nu;
    const double vx = ny * uz - nz * uy, vy = nz * ux - nx * uz, vz = nx * uy - ny * ux;
    const double cc = (l1 * l1 - l2 * l2 + Wn * Wn) / (2.0 * Wn);
    const double r2 = l1 * l1 - cc * cc, r = r2 > 0.0 ? sqrt(r2) : 0.0;
    const double c4p = cos(q4p), s4p = sin(q4p);
    double q4w[2];
    const int q4ok[2] = {wrap(q4p, 3, &q4w[0]), wrap(-q4p, 3, &q4w[1])};
    double st0[64], q[NQ];
    for (long k = 0; k < S; k++) {
        const double cs = cos(sw[k]), ss = sin(sw[k]);
        const double dx = cs * ux + ss * vx, dy = cs * uy + ss * vy, dz = cs * uz + ss * vz;
        const double Ex = cc * nx + r * dx, Ey = cc * ny + r * dy, Ez = cc * nz + r * dz;
        const double e0x = dy * nz - dz * ny, e0y = dz * nx - dx * nz, e0z = dx * ny - dy * nx;
        const double zx = -Ex / l1, zy = -Ey / l1, zz = -Ez / l1;
        for (int el = 0; el < 2; el++) {
            if (!q4ok[el]) continue;
            const double sgn = el == 0 ? 1.0 : -1.0;
            const double C4 = c4p, S4 = sgn * s4p;
            const double xx = sgn * e0x, xy = sgn * e0y, xz = sgn * e0z;
            const double yx = zy * xz - zz * xy, yy = zz * xx - zx * xz, yz = zx * xy - zy * xx;
            const double h = sqrt(xx * xx + yx * yx);
            const double wyx = C4 * yx + S4 * zx, wyy = C4 * yy + S4 * zy, wyz = C4 * yz + S4 * zz;
            const double wzx = -S4 * yx + C4 * zx, wzy = -S4 * yy + C4 * zy, wzz = -S4 * yz + C4 * zz;
            const double X00 = xx * r00 + xy * r10 + xz * r20;
            const double X10 = wyx * r00 + wyy * r10 + wyz * r20;
            const double X20 = wzx * r00 + wzy * r10 + wzz * r20;
            const double X21 = wzx * r01 + wzy * r11 + wzz * r21;
            const double X22 = wzx * r02 + wzy * r12 + wzz * r22;
            const double h6 = sqrt(X21 * X21 + X22 * X22);
            double wr5[2], wr6[2], wr7[2];
            for (int w = 0; w < 2; w++) {
                const double wb = w == 0 ? 1.0 : -1.0;
                wr5[w] = atan2(wb * X10, wb * X00);
                wr6[w] = atan2(-X20, wb * h6);
                wr7[w] = atan2(wb * X21, wb * X22);
            }
            q[3] = q4w[el];
            for (int sh = 0; sh < 2; sh++) {
                const double sb = sh == 0 ? 1.0 : -1.0;
                const double cq2 = sb * h;
                const double q2 = atan2(zx, cq2);
                double q1, q3;
                if (fabs(cq2) < 1e-12) { q1 = 0.0; q3 = atan2(xy, yy); }
                else { q1 = atan2(-sb * zy, sb * zz); q3 = atan2(-sb * yx, sb * xx); }
                if (!wrap(q1, 0, &q[0]) || !wrap(q2, 1, &q[1]) || !wrap(q3, 2, &q[2])) continue;
                (po ? fkp_0 : fk_0)(0, q, st0);
                for (int w = 0; w < 2; w++) {
                    if (!wrap(wr5[w], 4, &q[4]) || !wrap(wr6[w], 5, &q[5]) || !wrap(wr7[w], 6, &q[6])) continue;
                    const double rr = (po ? fkp_1 : fk_1)(st0, q + 4, T);
                    emit((int)(k * 8 + el * 4 + sh * 2 + w), q, rr, tol, Q, res, valid, inside);
                }
            }
        }
    }
    *sing = fabs(s4p) < 1e-12 ? 1 : 0;
}
"""

_ENTRY = r"""
/* n poses T (n x 16, row-major 4x4); swivel (n x S) or NULL; outputs per pose: Q (B x NQ, NaN where
   no candidate), res (B, +inf where none), valid/inside (B), code, sing.  check: validate the poses
   (returns -1 - i at the first invalid pose i).  Qc/rc/bc (may be NULL; n = 1): the valid
   solutions compacted, their residuals and branch indices; returns the number of valid ones (n = 1)
   or n. */
long aa_solve(long n, const double *T, const double *sw, long S, double tol, int po, double tolo, int check,
              double *Q, double *res, unsigned char *valid, unsigned char *inside, int *code, int *sing,
              double *Qc, double *rc, int *bc) {
    const long B = NB * S;
    long K = 0;
    for (long i = 0; i < n; i++) {
        const double *Ti = T + 16 * i;
        if (check && !pose_ok(Ti, po, tolo)) return -1 - i;
        double *Qi = Q + i * B * NQ, *ri = res + i * B;
        unsigned char *vi = valid + i * B, *ii = inside + i * B;
        for (long b = 0; b < B * NQ; b++) Qi[b] = NAN;
        for (long b = 0; b < B; b++) { ri[b] = HUGE_VAL; vi[b] = 0; ii[b] = 0; }
        code[i] = OK;
        sing[i] = 0;
        solve_one(Ti, sw ? sw + i * S : 0, S, tol, po, Qi, ri, vi, ii, code + i, sing + i);
        dedup(B, Qi, vi);
        if (Qc) {
            for (long b = 0; b < B; b++) {
                if (!vi[b]) continue;
                memcpy(Qc + K * NQ, Qi + b * NQ, NQ * sizeof(double));
                rc[K] = ri[b];
                bc[K] = (int)b;
                K++;
            }
        }
    }
    return Qc ? K : n;
}
"""

#: the C text of each closed-form family (models.closed_forms names the arms and their parameters)
_KERNELS = {"spherical_wrist_6r": _SIXR, "prosthetic_6r": _PROSTHETIC, "planar_2r": _PLANAR, "srs_7r": _HUMAN}


def _c_double(x: float) -> str:
    if math.isinf(x):
        return "HUGE_VAL" if x > 0 else "-HUGE_VAL"
    return repr(float(x))


def c_source(plan) -> str:
    """The C text of one robot (constants of ``plan``, the generated FK, the kernel)."""
    arr = lambda name, xs: f"static const double {name}[NQ] = {{{', '.join(_c_double(x) for x in xs)}}};"  # noqa: E731
    head = [f"/* anthroarm closed-form IK kernel: {plan.name}; generated by anthroarm.ik.analytic_c */",
            "#include <math.h>", f"#define NQ {plan.nq}", f"#define NB {plan.form.branches}",
            arr("LO", plan.lower), arr("HI", plan.upper), arr("LOF", plan.lo_f),
            arr("FLO", plan.fast_lo), arr("FHI", plan.fast_hi)]
    head += [f"static const double P_{k} = {_c_double(plan.params[k])};" for k in plan.form.params]
    return "\n".join([*head, _COMMON, plan.fk.c_source("fk_"), plan.fk_pos.c_source("fkp_"),
                      _KERNELS[plan.family], _ENTRY, _fk_entry(plan)])


def _fk_entry(plan) -> str:
    """``double aa_fk_residual(const double *q, const double *T, int po)``: the FK check of one
    configuration through the generated stages (for the tests: the C FK against Pinocchio)."""
    bounds = [0, *plan.fk.splits, plan.nq]
    n = plan.fk.n_stages
    lines = ["double aa_fk_residual(const double *q, const double *T, int po) {",
             "    double a[64], b[64];", "    (void)a; (void)b;"]
    src = "0"
    for k in range(n):
        if k == n - 1:
            lines.append(f"    return po ? fkp_{k}({src}, q + {bounds[k]}, T) : fk_{k}({src}, q + {bounds[k]}, T);")
        else:
            dst = "a" if k % 2 == 0 else "b"
            lines.append(f"    if (po) fkp_{k}({src}, q + {bounds[k]}, {dst}); else fk_{k}({src}, q + {bounds[k]}, {dst});")
            src = dst
    return "\n".join(lines + ["}", ""])


# ---------------------------------------------------------------------------- loading
_P = ctypes.c_void_p


class CKernel:
    """ctypes handle of one compiled kernel, with per-thread buffers for single poses."""

    def __init__(self, path: Path, plan):
        self.lib = ctypes.CDLL(str(path))
        f = self.lib.aa_solve
        f.restype = ctypes.c_long
        f.argtypes = [ctypes.c_long, _P, _P, ctypes.c_long, ctypes.c_double, ctypes.c_int, ctypes.c_double,
                      ctypes.c_int, _P, _P, _P, _P, _P, _P, _P, _P, _P]
        self.fn = f
        g = self.lib.aa_fk_residual
        g.restype = ctypes.c_double
        g.argtypes = [_P, _P, ctypes.c_int]
        self._fk = g
        self.nq = plan.nq
        self.nb = plan.form.branches
        self.path = path
        self._local = threading.local()

    def _buffers(self):
        b = getattr(self._local, "b", None)
        if b is None:
            B, nq = self.nb * MAX_SINGLE_S, self.nq
            arrs = dict(T=np.zeros(16), sw=np.zeros(MAX_SINGLE_S), Q=np.zeros(B * nq), res=np.zeros(B),
                        valid=np.zeros(B, np.uint8), inside=np.zeros(B, np.uint8), code=np.zeros(1, np.int32),
                        sing=np.zeros(1, np.int32), Qc=np.zeros(B * nq), rc=np.zeros(B), bc=np.zeros(B, np.int32))
            ptr = {k: a.ctypes.data for k, a in arrs.items()}
            b = self._local.b = (arrs, ptr)
        return b

    def fk_residual(self, q, T, position_only=False) -> float:
        """max |FK(q) − T| (3×4 entries, or the position) by the compiled FK check."""
        q = np.ascontiguousarray(q, dtype=float)
        T = np.ascontiguousarray(T, dtype=float)
        return float(self._fk(q.ctypes.data, T.ctypes.data, int(position_only)))

    def single(self, T, swivel, tol, po, tolo):
        """One pose (4×4 float64); ``swivel`` None or a sequence of S ≤ MAX_SINGLE_S angles.
        Returns (code, sing, branch indices, solutions (K, nq), residuals (K,), arrays) or None if
        the pose fails validation.  ``arrays`` holds the full per-branch outputs (for reasons)."""
        arrs, ptr = self._buffers()
        arrs["T"][:] = T.reshape(16)
        if swivel is None:
            S, psw = 1, None
        else:
            S = len(swivel)
            arrs["sw"][:S] = swivel
            psw = ptr["sw"]
        K = self.fn(1, ptr["T"], psw, S, tol, po, tolo, 1, ptr["Q"], ptr["res"], ptr["valid"], ptr["inside"],
                    ptr["code"], ptr["sing"], ptr["Qc"], ptr["rc"], ptr["bc"])
        if K < 0:
            return None
        nq = self.nq
        return (int(arrs["code"][0]), int(arrs["sing"][0]), arrs["bc"][:K].tolist(),
                arrs["Qc"][:K * nq].reshape(K, nq).copy(), arrs["rc"][:K].copy(), (arrs, S))

    def batch(self, T, swivel, tol, po, tolo, check=True):
        """N poses (N, 4, 4) float64 C-contiguous; ``swivel`` (N, S) or None.  Returns
        (Q (N, B, nq), valid (N, B), inside (N, B), res (N, B), code (N,), sing (N,)) or None if a
        pose fails validation."""
        N = T.shape[0]
        S = 1 if swivel is None else swivel.shape[1]
        B = self.nb * S
        Tc = np.ascontiguousarray(T, dtype=float)
        swc = None if swivel is None else np.ascontiguousarray(swivel, dtype=float)
        Q = np.empty((N, B, self.nq))
        res = np.empty((N, B))
        valid = np.empty((N, B), np.uint8)
        inside = np.empty((N, B), np.uint8)
        code = np.empty(N, np.int32)
        sing = np.empty(N, np.int32)
        r = self.fn(N, Tc.ctypes.data, None if swc is None else swc.ctypes.data, S, tol, po, tolo, int(check),
                    Q.ctypes.data, res.ctypes.data, valid.ctypes.data, inside.ctypes.data, code.ctypes.data,
                    sing.ctypes.data, None, None, None)
        if r < 0:
            return None
        return Q, valid.view(bool), inside.view(bool), res, code, sing


def build(plan) -> CKernel:
    """Compile (or load from the cache) the kernel of ``plan``.  Raises RuntimeError on failure."""
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler ($CC or cc)")
    src = c_source(plan)
    key = cache.key(src, cache.compiler_id(cc), " ".join(FLAGS))
    with _LOCK:
        if key in _LIBS:
            return _LIBS[key]
        so, _ = cache.shared_library("ik", f"analytic_{plan.name}", src, FLAGS)   # CompileError is a RuntimeError
        kern = CKernel(so, plan)
        _LIBS[key] = kern
        return kern


def kernel_for(plan) -> CKernel | None:
    """The compiled kernel of ``plan`` (cached on the plan), or None (disabled, no compiler,
    compilation failed — see :func:`status`)."""
    return KERNELS.get(plan, "c_kernel", build, f"kernel for {plan.name}")
