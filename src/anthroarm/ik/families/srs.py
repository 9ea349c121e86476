"""The 7R shoulder–elbow–wrist arm by its elbow swivel angle: the compiled kernels per pose and
swivel angle, and the drivers over a batch (:func:`srs_verified`, :func:`srs_nearest`)."""

from __future__ import annotations

import math

import numpy as np

from ...jit import borrow, kernel, local, local2, local_flags, part, part2, view2, view3
from ...threads import run_rows
from ..classes.branches import BRANCH_ROW, COS, EXACT, EXISTS, SIN, angles, wrist
from ..fk import WIDTH
from ..geometric.fk import POLISH_MAX, _fk_residuals, _target_errors
from ..geometric.limits import into_limit_rows
from ..geometric.verify import NO_REF, BadPoseError, _mark_solutions, _pose_status, nearest_first
from ..qp.tasks.swivel import swivel_basis
from ..subproblems.base import TOL
from ..subproblems.circle import sp1_cs, sp2_cs, sp3_cs
from ..vec3 import (
    add,
    atan2,
    cross,
    dot,
    mat,
    mm,
    mtv,
    mv,
    neg,
    norm,
    rot_cs,
    rows7,
    scale,
    sub,
    transpose,
    vec,
)
from .plans import SRSPlan


# ----------------------------------------------------------------------------- SRS kernels
@kernel
def _swivel_basis(n):
    """(u, v) ⊥ n: u = (0, 0, −1) projected ⊥ n (fallback (0, −1, 0)), v = n × u — as
    :func:`anthroarm.ik.qp.tasks.swivel.swivel_basis`."""
    r = (0.0, 0.0, -1.0)
    u = sub(r, scale(n, dot(r, n)))
    nu = norm(u)
    if nu < 1e-9:
        r = (0.0, -1.0, 0.0)
        u = sub(r, scale(n, dot(r, n)))
        nu = norm(u)
    u = scale(u, 1.0 / nu)
    return u, cross(n, u)


@kernel
def _align(a0, b0, a1, b1):
    """The rotation R with R a0 ∥ a1 and R b0 in the half-plane of (a1, b1) (R = F1 F0ᵀ of the
    orthonormal frames of the two pairs)."""
    x0 = scale(a0, 1.0 / norm(a0))
    z0 = cross(a0, b0)
    z0 = scale(z0, 1.0 / norm(z0))
    y0 = cross(z0, x0)
    x1 = scale(a1, 1.0 / norm(a1))
    z1 = cross(a1, b1)
    z1 = scale(z1, 1.0 / norm(z1))
    y1 = cross(z1, x1)
    F0 = (x0, y0, z0)  # the rows of F0ᵀ; R = x1 x0ᵀ + y1 y0ᵀ + z1 z0ᵀ
    return (
        (
            x1[0] * F0[0][0] + y1[0] * F0[1][0] + z1[0] * F0[2][0],
            x1[0] * F0[0][1] + y1[0] * F0[1][1] + z1[0] * F0[2][1],
            x1[0] * F0[0][2] + y1[0] * F0[1][2] + z1[0] * F0[2][2],
        ),
        (
            x1[1] * F0[0][0] + y1[1] * F0[1][0] + z1[1] * F0[2][0],
            x1[1] * F0[0][1] + y1[1] * F0[1][1] + z1[1] * F0[2][1],
            x1[1] * F0[0][2] + y1[1] * F0[1][2] + z1[1] * F0[2][2],
        ),
        (
            x1[2] * F0[0][0] + y1[2] * F0[1][0] + z1[2] * F0[2][0],
            x1[2] * F0[0][1] + y1[2] * F0[1][1] + z1[2] * F0[2][1],
            x1[2] * F0[0][2] + y1[2] * F0[1][2] + z1[2] * F0[2][2],
        ),
    )


@kernel
def _rot3(h, a1, a2, a3):
    """rot(h1, q1) rot(h2, q2) rot(h3, q3) of three rotations (cos, sin)."""
    return mm(
        mm(rot_cs(h[0], a1[0], a1[1]), rot_cs(h[1], a2[0], a2[1])), rot_cs(h[2], a3[0], a3[1])
    )


@kernel
def _q4(q4b, b, a4):
    """q4's rotation (cos θ, sin θ) for branches b and b + 1."""
    for k in range(2):
        q4b[b + k, 0], q4b[b + k, 1] = a4


# long: one compiled kernel per pose and swivel angle: shoulder, elbow and wrist of 8 branches
@kernel
def _srs_one(route, h, S, E0, W0, Rg, W, phi, a4a, a4b, n4, e4a, e4b, Q, QC, QS, V, E, B6, Bs, q4b):
    """The 8 branches of one pose and swivel angle φ: Q (8, 7) rad (path order, wrapped into
    (−π, π]), QC, QS (8, 7) their cosines and sines, V (the branch exists), E (every
    subproblem on it exact).  ``Rg`` = R R_tᵀ, ``W`` the wrist centre (base frame, m), ``a4a``,
    ``a4b`` the q4 roots of the SP3 (module docstring) as rotations (cos θ, sin θ); B6 (8, ·),
    Bs (2, ·) rows of branches as :mod:`.geometric`'s class solvers write them (their rotations),
    q4b (8, 2) scratch.  The angles are read from the rotations at the end (atan2)."""
    for b in range(8):
        B6[b, EXISTS] = 0.0
        B6[b, EXACT] = 0.0
    e0 = sub(E0, S)
    a = norm(e0)
    f0 = sub(W0, E0)
    bb = norm(f0)
    sw = sub(W, S)
    L = norm(sw)
    if L > 1e-12:
        n = scale(sw, 1.0 / L)
        u, v = _swivel_basis(n)
        c = (a * a - bb * bb + L * L) / (2.0 * L)
        c = min(max(c, -a), a)
        rad = math.sqrt(max(a * a - c * c, 0.0))
        d = add(scale(u, math.cos(phi)), scale(v, math.sin(phi)))
        Ep = add(S, add(scale(n, c), scale(d, rad)))
        straight = rad <= 1e-9 * (1.0 + a)
        # straight elbow: h4 goes to a_E with d = n × a_E (the swivel angle's convention)
        al = dot(h[3], e0) / a
        aE = add(scale(n, al), scale(cross(d, n), math.sqrt(max(1.0 - al * al, 0.0))))
        up = sub(Ep, S)
        fore = sub(W, Ep)
        for i4 in range(2):
            if i4 >= n4:
                continue
            a4 = a4a if i4 == 0 else a4b
            ex4 = e4a if i4 == 0 else e4b
            R34 = rot_cs(h[3], a4[0], a4[1])
            f = mv(R34, f0)
            src = h[3] if straight else f
            dst = aE if straight else fore
            if route == 0:
                c1a, s1a, c2a, s2a, c1b, s1b, c2b, s2b, n12, ea, eb, _ = sp2_cs(
                    up, e0, neg(h[0]), h[1], TOL
                )
                for j in range(2):
                    if j >= n12:
                        continue
                    a1, a2 = ((c1a, s1a), (c2a, s2a)) if j == 0 else ((c1b, s1b), (c2b, s2b))
                    R02 = mm(rot_cs(h[0], a1[0], a1[1]), rot_cs(h[1], a2[0], a2[1]))
                    c3, s3, e3, _ = sp1_cs(src, mtv(R02, dst), h[2], TOL)
                    R04 = mm(mm(R02, rot_cs(h[2], c3, s3)), R34)
                    b = 4 * i4 + 2 * j
                    _q4(q4b, b, a4)
                    wrist(
                        (h[4], h[4], h[4], h[4], h[5], h[6]),
                        R04,
                        Rg,
                        B6,
                        b,
                        a1,
                        a2,
                        (c3, s3),
                        ex4 and (ea if j == 0 else eb) and e3,
                    )
            else:
                R03 = _align(e0, src, up, dst)
                ident = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
                for j in range(2):
                    Bs[j, EXISTS] = 0.0
                zero = (1.0, 0.0)
                wrist(
                    (h[0], h[0], h[0], h[0], h[1], h[2]), ident, R03, Bs, 0, zero, zero, zero, True
                )
                for j in range(2):
                    if Bs[j, EXISTS] == 0.0:
                        continue
                    a1, a2, a3 = (
                        (Bs[j, COS + 3], Bs[j, SIN + 3]),
                        (Bs[j, COS + 4], Bs[j, SIN + 4]),
                        (Bs[j, COS + 5], Bs[j, SIN + 5]),
                    )
                    R04 = mm(_rot3(h, a1, a2, a3), R34)
                    b = 4 * i4 + 2 * j
                    _q4(q4b, b, a4)
                    wrist(
                        (h[4], h[4], h[4], h[4], h[5], h[6]),
                        R04,
                        Rg,
                        B6,
                        b,
                        a1,
                        a2,
                        a3,
                        ex4 and Bs[j, EXACT] != 0.0,
                    )
    angles(B6)  # the angles from their rotations, vectorised
    for b in range(8):
        if B6[b, EXISTS] != 0.0:
            for j in range(7):
                if j == 3:
                    Q[b, j], QC[b, j], QS[b, j] = atan2(q4b[b, 1], q4b[b, 0]), q4b[b, 0], q4b[b, 1]
                else:  # the wrist's joints are 4, 5, 6 of B6's row
                    k = j if j < 3 else j - 1
                    Q[b, j], QC[b, j], QS[b, j] = B6[b, k], B6[b, COS + k], B6[b, SIN + k]
            V[b], E[b] = True, B6[b, EXACT] != 0.0
        else:
            for j in range(7):
                Q[b, j] = math.nan
            V[b], E[b] = False, False


@kernel(inline=True)
def _srs_unpack(cf, ci):
    """The constants of :attr:`SRSPlan.packed`: (route, H (7, 3), S, E0, W0 (3,), R_tool
    (3, 3), p_tool (3,), the FK frames A (8, 16), lo, hi (7,), order (7,)) — views of ``cf``,
    ``ci``, compiled into each caller (:func:`anthroarm.jit.kernel`)."""
    return (
        ci[0],
        part2(cf, 0, 7, 3),
        part(cf, 21, 3),
        part(cf, 24, 3),
        part(cf, 27, 3),
        part2(cf, 30, 3, 3),
        part(cf, 39, 3),
        part2(cf, 42, 8, WIDTH),
        part(cf, 42 + 8 * WIDTH, 7),
        part(cf, 49 + 8 * WIDTH, 7),
        part(ci, 1, 7),
    )


@kernel
def _srs_verified(cf, ci, T, swivel, tol, tol_orthonormal, Q, V, E, IN, RES, OK):
    """Every branch of poses T (N, 4, 4) for swivel angles (N, S): writes Q (N, S·8, 7) (path
    order, shifted by 2π into the limits, :func:`.geometric.into_limit`), V, E, IN, RES (the
    FK residual of :func:`.geometric._fk_residuals`: inf where there is no candidate, and for
    an exact candidate outside the limits, which is never returned and so not checked, as in
    :func:`.geometric._verified`), OK (the solutions: residual ≤ ``tol``, duplicates at one
    angle dropped, :func:`.geometric._mark_solutions`); returns the index of the first
    malformed pose (−1 if none; N + i: swivel row i not finite).  ``cf``, ``ci``:
    :attr:`SRSPlan.packed`.  Compiled without reference counts (:func:`anthroarm.jit.kernel`):
    its scratch is local."""
    route, H, S, E0, W0, R_tool, p_tool, A, lo, hi, _ = _srs_unpack(cf, ci)
    h = rows7(H)
    Sv, E0v, W0v = vec(S), vec(E0), vec(W0)
    Rt, pt = mat(R_tool), vec(p_tool)
    B6, Bs, q4b = local2(8, BRANCH_ROW), local2(2, BRANCH_ROW), local2(8, 2)
    QC, QS, CHK = local2(8, 7), local2(8, 7), local_flags(8)
    Sfk = local2(8, 12)
    ns = swivel.shape[1]
    for i in range(len(T)):
        Ti, Qi, Vi, Ei, INi, RESi, OKi = T[i], Q[i], V[i], E[i], IN[i], RES[i], OK[i]
        if _pose_status(Ti, tol_orthonormal) != 0:
            return i
        for k in range(ns):
            if not math.isfinite(swivel[i, k]):
                return len(T) + i
        R, p = mat(Ti), (Ti[0, 3], Ti[1, 3], Ti[2, 3])
        Rg = mm(R, transpose(Rt))
        W = add(mv(Rg, sub(W0v, pt)), p)
        c4a, s4a, c4b, s4b, n4, e4a, e4b, _ = sp3_cs(
            sub(W0v, E0v), sub(Sv, E0v), h[3], norm(sub(W, Sv)), TOL
        )
        for k in range(ns):
            rows = slice(8 * k, 8 * k + 8)
            _srs_one(
                route,
                h,
                Sv,
                E0v,
                W0v,
                Rg,
                W,
                swivel[i, k],
                (c4a, s4a),
                (c4b, s4b),
                n4,
                e4a,
                e4b,
                Qi[rows],
                QC,
                QS,
                Vi[rows],
                Ei[rows],
                B6,
                Bs,
                q4b,
            )
            into_limit_rows(Qi[rows], QC, QS, Vi[rows], Ei[rows], 7, lo, hi, INi[rows], CHK)
            _fk_residuals(A, Qi[rows], QC, QS, CHK, 7, Ti, RESi[rows], Sfk)
            _mark_solutions(Qi[rows], Vi[rows], INi[rows], RESi[rows], tol, 8, OKi[rows])
    return -1


@kernel
def _srs_nearest(cf, ci, T, swivel, first, tol, tol_orthonormal, ref, out):
    """One pose T (4, 4): the solutions (a candidate inside the limits, FK residual ≤ ``tol``,
    duplicates at one angle dropped: :func:`.geometric._mark_solutions`) at the swivel angles
    ``swivel`` (S,) in turn — only at the first angle that has any where ``first`` — into the
    rows of ``out`` (8 S, 12): θ in independent-joint order (``order``: the path position of
    each), the FK residual (column 9), the branch (column 10: 8 k + b, swivel angle k, branch
    b) and its swivel angle (column 11), in that order — with a reference ``ref`` (7,) (an
    empty array: none) the nearest it first, and its position and rotation errors
    (:func:`.geometric._target_errors`) in columns 7, 8 of row 0.  Returns their number K; −1:
    a malformed pose; −2: a candidate to polish (the caller's general path answers).  ``cf``,
    ``ci``: :attr:`SRSPlan.packed`.  Scratch local (:func:`anthroarm.jit.local`)."""
    _, _, _, _, _, _, _, A, _, _, order = _srs_unpack(cf, ci)
    Tb = view3(T, 1, 4, 4)
    sw = local2(1, 1)
    q = local(7)
    Q1, RES1 = view3(local(56), 1, 8, 7), local2(1, 8)
    V1, E1 = view2(local_flags(8), 1, 8), view2(local_flags(8), 1, 8)
    IN1, OK1 = view2(local_flags(8), 1, 8), view2(local_flags(8), 1, 8)
    Q, V, E, IN, RES, OK = Q1[0], V1[0], E1[0], IN1[0], RES1[0], OK1[0]
    K = 0
    for k in range(len(swivel)):
        sw[0, 0] = swivel[k]
        if _srs_verified(cf, ci, Tb, sw, tol, tol_orthonormal, Q1, V1, E1, IN1, RES1, OK1) >= 0:
            return -1  # a malformed pose, or an angle not finite
        for b in range(8):
            if V[b] and E[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
                return -2
        for b in range(8):
            if OK[b]:
                for j in range(7):
                    out[K, j] = Q[b, order[j]]
                out[K, 9], out[K, 10], out[K, 11] = RES[b], 8 * k + b, swivel[k]
                K += 1
        if first and K > 0:
            break
    if K > 0 and len(ref) == 7:
        nearest_first(out, K, 7, ref, 12)
        for j in range(7):
            q[order[j]] = out[0, j]
        out[0, 7], out[0, 8] = _target_errors(A, q, T)
    return K


@kernel
def srs_pose_solutions(cf, ci, T, swivel, tol, tol_orthonormal, out):
    """:func:`_srs_nearest` of one pose T (4, 4) at one swivel angle ``swivel`` (rad, finite)
    without a reference: the solutions into the rows of ``out`` (8, 12); returns the bit mask
    of their branches (bit b: branch b; ≤ 0: none, a malformed pose or a candidate to polish —
    the general path answers).  What :func:`anthroarm.ik.closed_form.analytic` calls for one
    pose at one swivel angle (:func:`anthroarm.jit.entry_point`).  Its arrays are passed on
    borrowed (``anthroarm.jit.borrow``: no reference counts taken and given back below it)."""
    cf, ci, T, out = borrow(cf), borrow(ci), borrow(T), borrow(out)
    sw = local(1)
    sw[0] = swivel
    K = _srs_nearest(cf, ci, T, sw, False, tol, tol_orthonormal, sw[:0], out)
    mask = 0
    for k in range(K):
        mask |= 1 << int(out[k, 10])
    return mask if K >= 0 else K


def srs_nearest(plan: SRSPlan, T, ref, swivel, first: bool):
    """The solutions θ (K, 7) (independent-joint order, rad) of one pose ``T`` (4, 4) of the SRS
    arm of ``plan`` at the swivel angles ``swivel`` (S,) (rad, finite) — only at the first that
    has any where ``first`` — with the one nearest ``ref`` (7,) first and its position and
    rotation errors (m, rad), in one compiled call; None where the pose has no solution there,
    is malformed or has a candidate to polish (the general path answers).  The seeds of
    :func:`anthroarm.ik.solve` (:func:`anthroarm.ik.closed_form.nearest_swivel_solver`)."""
    K, out = _one_pose(plan, T, swivel, first, 1e-9, 1e-6, ref)
    if K <= 0:
        return None
    return out[:K, :7], float(out[0, 7]), float(out[0, 8])


def _one_pose(plan: SRSPlan, T, swivel, first: bool, tol: float, tol_orthonormal: float, ref):
    """:func:`_srs_nearest` of ``plan``: (K, its rows (8 S, 12)).  ``T``: a C-order float 4×4
    array (ValueError otherwise: the kernel reads 16 entries)."""
    if not (
        isinstance(T, np.ndarray)
        and T.shape == (4, 4)
        and T.dtype == np.float64
        and T.flags.c_contiguous
    ):
        raise ValueError("T must be a C-order float64 4x4 array")
    out = np.empty((8 * len(swivel), 12))
    cf, ci = plan.packed
    return _srs_nearest(cf, ci, T, swivel, first, tol, tol_orthonormal, ref, out), out


def srs_solutions(plan: SRSPlan, T, swivel, tol: float, tol_orthonormal: float):
    """Every solution of one pose ``T`` (4, 4) (a C-order float array) at the swivel angles
    ``swivel`` (S,) (rad, finite), in the order of :func:`srs_verified`'s rows, in one compiled
    call: (θ (K, 7) in independent-joint order, FK residuals (K,), row indices (a list of K
    ints) into the 8 S branches, swivel angles (K,)) — or None where there is none, the pose is
    malformed or a candidate is to be polished (:func:`anthroarm.ik.closed_form.analytic_batch`
    answers, with the reasons)."""
    K, out = _one_pose(plan, T, swivel, False, tol, tol_orthonormal, NO_REF)
    if K <= 0:
        return None
    return out[:K, :7], out[:K, 9], [int(r) for r in out[:K, 10].tolist()], out[:K, 11]


def _swivel_array(swivel, N, check=True):
    """(N, S) swivel angles from a scalar (every pose), (N,) (one per pose) or (N, S)."""
    sw = np.asarray(swivel, dtype=float)
    if sw.ndim == 0:
        sw = np.full((N, 1), float(sw))
    elif sw.ndim == 1:
        if len(sw) != N:
            raise ValueError(
                f"swivel: a 1-D array gives one angle per pose and must have length N = {N}, "
                f"got {len(sw)}"
            )
        sw = sw.reshape(N, 1)
    elif sw.ndim != 2 or sw.shape[0] != N:
        raise ValueError(
            f"swivel must be a scalar, (N,) or (N, S) with N = {N}, got shape {sw.shape}"
        )
    if check and not np.all(np.isfinite(sw)):
        raise ValueError("swivel must be finite angles (rad)")
    return sw if sw.flags.c_contiguous else np.ascontiguousarray(sw)


def srs_verified(plan: SRSPlan, T, swivel, tol: float = 1e-9, tol_orthonormal: float = 1e-6):
    """Every branch of the SRS arm of ``plan`` for tool poses ``T`` (N, 4, 4) (base frame, m)
    and elbow swivel angles ``swivel`` (N, S) rad (a scalar or (N,) means S = 1), in one
    compiled call: rows ``8 k + b`` hold swivel angle k and branch b (``SRSPlan.labels``).
    Returns θ (N, 8S, 7) in ``robot.chain.independent`` order (rad, wrapped by 2π into the
    limits, NaN where the branch does not exist), candidate (N, 8S), exact (N, 8S), inside the
    limits (N, 8S), FK residual (N, 8S) (max entry of the 3×4 pose by the chain's product of
    exponentials; inf where there is no candidate or an exact one outside the limits) and
    solution (N, 8S) (residual ≤ ``tol``, duplicates at one angle dropped).
    Raises ``ValueError`` naming the first malformed pose (not finite, last row, not a rotation
    to ``tol_orthonormal``)."""
    T = np.ascontiguousarray(T, dtype=float)
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise ValueError(f"T must have shape (N, 4, 4), got {T.shape}")
    N = len(T)
    sw = _swivel_array(swivel, N, check=False)  # finiteness: checked by the kernel
    B = 8 * sw.shape[1]
    Q, V, E = np.empty((N, B, 7)), np.empty((N, B), bool), np.empty((N, B), bool)
    IN, RES, OK = np.empty((N, B), bool), np.empty((N, B)), np.empty((N, B), bool)
    bad_pose, bad_swivel = [], []

    cf, ci = plan.packed

    def rows(a, b):  # a slice of poses, on one core
        k = _srs_verified(
            cf,
            ci,
            T[a:b],
            sw[a:b],
            tol,
            tol_orthonormal,
            Q[a:b],
            V[a:b],
            E[a:b],
            IN[a:b],
            RES[a:b],
            OK[a:b],
        )
        if k >= b - a:
            bad_swivel.append(a + k - (b - a))
        elif k >= 0:
            bad_pose.append(a + k)

    run_rows(rows, N)
    if bad_swivel:
        raise ValueError(f"swivel[{min(bad_swivel)}] is not finite (rad)")
    if bad_pose:
        raise BadPoseError(
            min(bad_pose),
            f"T[{min(bad_pose)}] is not a valid pose (finite, last row [0, 0, 0, 1], "
            f"rotation part a rotation to {tol_orthonormal:g})",
        )
    # E is already False wherever V is (the kernel's rule)
    return (Q if plan.in_order else Q[..., plan.order]), V, E, IN, RES, OK


def srs_points(plan: SRSPlan, T, swivel):
    """The shoulder centre S (3,), the wrist centre W(T) (N, 3) and the elbow E(φ) (N, S, 3)
    the kernel places for poses ``T`` and swivel angles (N, S) (base frame, m); numpy, for
    tests and plots."""
    T = np.asarray(T, dtype=float)
    sw = _swivel_array(swivel, len(T))
    Rg = T[:, :3, :3] @ plan.R_tool.T
    W = np.einsum("nij,j->ni", Rg, plan.W0 - plan.p_tool) + T[:, :3, 3]
    a, b = np.linalg.norm(plan.E0 - plan.S), np.linalg.norm(plan.W0 - plan.E0)
    L = np.linalg.norm(W - plan.S, axis=1)
    n = (W - plan.S) / L[:, None]
    u, v = swivel_basis(n)
    c = np.clip((a * a - b * b + L * L) / (2 * L), -a, a)
    r = np.sqrt(np.maximum(a * a - c * c, 0))
    d = np.cos(sw)[..., None] * u[:, None] + np.sin(sw)[..., None] * v[:, None]
    E = plan.S + c[:, None, None] * n[:, None] + r[:, None, None] * d
    return plan.S.copy(), W, E
