"""One attempt of :func:`anthroarm.ik.solve`: damped Gauss–Newton (Levenberg–Marquardt) from a
seed, written once as compiled kernels (:mod:`anthroarm.jit`: the interpreter runs this same
source until the compiled code is ready)::

    Δθ = Jᵀ (J Jᵀ + λ I)⁻¹ e = (JᵀJ + λ I)⁻¹ Jᵀe,   λ = λ₀ + k ‖e‖²   (Sugihara 2011 damping),
    θ ← clip(θ + Δθ, θ_min, θ_max).

This is the book's feedback-compensation Newton step Δq = J⁻¹ e (Ch. 7 §7-5) made robust: the
damping blends toward the steepest-descent direction Jᵀe of §7-6 (A9) when the error is large
or J is singular and vanishes near the solution (quadratic convergence).  Joint ranges (the
penalty constraints g_i(Q) ≥ 0 of (7-84)–(7-85)) are enforced by an active set: a joint whose
step would cross its limit is frozen for that step (its column of J zeroed) and the step
recomputed with the others, then clipped (:func:`damped_step`; the constants and the batch form
are in :mod:`.kernel`).

The frame's pose and its Jacobian come from the chain's one compiled forward kinematics,
:func:`anthroarm.ik.fk.chain_fk_jacobian`, on the arrays of
:class:`~anthroarm.ik.fk.PathFrames` read from ``robot.chain`` (revolute, continuous,
prismatic and mimic joints).  The errors are those of :class:`.targets.Target`: a pose's body
twist e = log₆(T(θ)⁻¹ T*) with the LOCAL Jacobian, a position's e = p* − p with the
LOCAL_WORLD_ALIGNED linear rows, a rotation's e = log₃(RᵀR*) with the LOCAL angular rows;
:func:`log3` and :func:`log6` compute as Pinocchio 3 does (``pinocchio/src/spatial/log.hxx``:
the rotation renormalised, the Taylor branches below ε^(1/3), the θ ≈ π branch).  The linear
systems are solved by a Cholesky factorisation that fails as LAPACK's ``dpotrf`` does (a pivot
≤ 0 or NaN).

The time budget is thread CPU time (``kernel.clock``), which a compiled kernel cannot
read: :func:`run` pauses every 8th iteration and :func:`attempt` (the Python caller) looks at
the clock in between.  No allocation in the loop: every array lives in the calling thread's
:class:`Buffers`.
"""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..fk import chain_fk_jacobian
from .kernel import K_DAMP, LAMBDA0, MAX_ITER, STALL, clock
from .targets import ORIENTATION, POSE, POSITION, Target

EPS = float(np.finfo(float).eps)
PREC2 = EPS ** (1.0 / 3.0)  # Pinocchio's Taylor threshold (TaylorSeriesExpansion<double, 2>)
#: :func:`run`'s return codes: the attempt failed, converged, or paused for the clock
FAILED, CONVERGED, PAUSED = 0, 1, 2
#: state fields of :func:`run` (row ``ST`` of its buffer): iterations, stall count, reference
#: ‖e‖², best ‖e‖², pos_err², rot_err², last ‖e‖², resume flag
IT, STALLS, REF_E, BEST_E, PE2, RE2, LAST_E, RESUME = range(8)
NCOL = 8  # (and the number n of coordinates: no argument for it)


# ----------------------------------------------------------------------------- log₃, log₆
@kernel
def _theta_axis(i0, val, R):
    """Angle and unit axis of a rotation near π from its i0-th diagonal term (Pinocchio's
    ``log3`` π branch)."""
    i1, i2 = (i0 + 1) % 3, (i0 + 2) % 3
    s = math.sqrt(val + EPS + EPS * EPS) * (1.0 if R[i2][i1] >= R[i1][i2] else -1.0)
    a0 = s / 2.0
    a1 = 1.0 / (2.0 * s) * (R[i1][i0] + R[i0][i1])
    a2 = 1.0 / (2.0 * s) * (R[i2][i0] + R[i0][i2])
    w = 1.0 / (2.0 * s) * (R[i2][i1] - R[i1][i2])
    if i0 == 0:
        ax = (a0, a1, a2)
    elif i0 == 1:
        ax = (a2, a0, a1)
    else:
        ax = (a1, a2, a0)
    an = math.sqrt((ax[0] * ax[0] + ax[1] * ax[1]) + ax[2] * ax[2])
    return 2.0 * math.atan2(an, w), (ax[0] / an, ax[1] / an, ax[2] / an)


@kernel
def log3(R):
    """(ω, θ): ω = log₃(R) (rad, R a rotation as row tuples) and its angle θ = ‖ω‖, as Pinocchio
    computes it (its sums in Eigen's order: a trace x₀ + (x₁ + x₂), a norm (x₀ + x₁) + x₂)."""
    n0 = math.sqrt((R[0][0] * R[0][0] + R[1][0] * R[1][0]) + R[2][0] * R[2][0])
    n1 = math.sqrt((R[0][1] * R[0][1] + R[1][1] * R[1][1]) + R[2][1] * R[2][1])
    c0 = (R[0][0] / n0, R[1][0] / n0, R[2][0] / n0)
    c1 = (R[0][1] / n1, R[1][1] / n1, R[2][1] / n1)
    c2 = _cross(c0, c1)
    c0 = _cross(c1, c2)
    Rn = ((c0[0], c1[0], c2[0]), (c0[1], c1[1], c2[1]), (c0[2], c1[2], c2[2]))
    tr = Rn[0][0] + (Rn[1][1] + Rn[2][2])
    cv = (tr - 1.0) / 2.0
    acos_exp = math.sqrt(2.0 * (1.0 - cv) + EPS * EPS)
    if tr <= 3.0 - PREC2:
        thn = math.acos(cv) if tr >= -1.0 + PREC2 else math.pi - acos_exp
    else:
        thn = acos_exp
    if cv >= -1.0 + PREC2:
        a = (0.5 * (Rn[2][1] - Rn[1][2]), 0.5 * (Rn[0][2] - Rn[2][0]), 0.5 * (Rn[1][0] - Rn[0][1]))
        n2 = (a[0] * a[0] + a[1] * a[1]) + a[2] * a[2]
        t = thn / math.sin(thn) if thn >= PREC2 else 1.0 + n2 / 6.0 + n2 * n2 * 3.0 / 40.0
        return (t * a[0], t * a[1], t * a[2]), thn
    v0 = 2.0 * Rn[0][0] - tr + 1.0
    v1 = 2.0 * Rn[1][1] - tr + 1.0
    v2 = 2.0 * Rn[2][2] - tr + 1.0
    if v0 >= v1:
        b, v = (0, v0) if v0 >= v2 else (2, v2)
    else:
        b, v = (1, v1) if v1 >= v2 else (2, v2)
    th, ax = _theta_axis(b, v, Rn)
    return (th * ax[0], th * ax[1], th * ax[2]), th


@kernel
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@kernel
def log6(R, p):
    """The twist (v, ω) = log₆(R, p) (m, rad) of a rigid transform, as Pinocchio computes it:
    ω = log₃(R), v = V(ω)⁻¹ p = α p − ½ ω × p + β (ω·p) ω (Murray, Li & Sastry 1994, §2.4)."""
    a = (0.5 * (R[2][1] - R[1][2]), 0.5 * (R[0][2] - R[2][0]), 0.5 * (R[1][0] - R[0][1]))
    t2 = (a[0] * a[0] + a[1] * a[1]) + a[2] * a[2]
    tr = R[0][0] + (R[1][1] + R[2][2])
    w, theta = log3(R)
    st, ct = math.sin(theta), math.cos(theta)
    if tr >= 3.0 - PREC2:
        alpha = 1.0 - t2 / 12.0 - t2 * t2 / 720.0
        beta = 1.0 / 12.0 + t2 / 720.0
    else:
        alpha = theta * st / (2.0 * (1.0 - ct))
        beta = 1.0 / (theta * theta) - st / (2.0 * theta * (1.0 - ct))
    wxp = _cross(w, p)
    bwp = beta * ((w[0] * p[0] + w[1] * p[1]) + w[2] * p[2])
    return (
        alpha * p[0] - 0.5 * wxp[0] + bwp * w[0],
        alpha * p[1] - 0.5 * wxp[1] + bwp * w[1],
        alpha * p[2] - 0.5 * wxp[2] + bwp * w[2],
        w[0],
        w[1],
        w[2],
    )


# ----------------------------------------------------------------------------- residual, Jacobian
@kernel
def _rt(R, M):
    """Rᵀ M of 3×3 row tuples."""
    return (
        (
            R[0][0] * M[0][0] + (R[1][0] * M[1][0] + R[2][0] * M[2][0]),
            R[0][0] * M[0][1] + (R[1][0] * M[1][1] + R[2][0] * M[2][1]),
            R[0][0] * M[0][2] + (R[1][0] * M[1][2] + R[2][0] * M[2][2]),
        ),
        (
            R[0][1] * M[0][0] + (R[1][1] * M[1][0] + R[2][1] * M[2][0]),
            R[0][1] * M[0][1] + (R[1][1] * M[1][1] + R[2][1] * M[2][1]),
            R[0][1] * M[0][2] + (R[1][1] * M[1][2] + R[2][1] * M[2][2]),
        ),
        (
            R[0][2] * M[0][0] + (R[1][2] * M[1][0] + R[2][2] * M[2][0]),
            R[0][2] * M[0][1] + (R[1][2] * M[1][1] + R[2][2] * M[2][1]),
            R[0][2] * M[0][2] + (R[1][2] * M[1][2] + R[2][2] * M[2][2]),
        ),
    )


@kernel
def residual(kind, x, tsum, R, p, e):
    """The error e (m,) of the pose (R, p) against the target x (``Target.x``: a
    pose's T*.ravel(), a position's (p*, 1), a rotation's R*.ravel()) into ``e``; returns (‖e‖², pos_err², rot_err²) as
    :meth:`.targets.Target.residual` (0 for the unchecked part; a pose's both inf where
    ‖e‖² > ``tsum``: surely not converged)."""
    if kind == POSITION:
        e[0], e[1], e[2] = x[0] - p[0], x[1] - p[1], x[2] - p[2]
        E = (e[0] * e[0] + e[1] * e[1]) + e[2] * e[2]
        return E, E, 0.0
    if kind == ORIENTATION:
        Rs = ((x[0], x[1], x[2]), (x[3], x[4], x[5]), (x[6], x[7], x[8]))
        w, _ = log3(_rt(R, Rs))
        e[0], e[1], e[2] = w
        E = (e[0] * e[0] + e[1] * e[1]) + e[2] * e[2]
        return E, 0.0, E
    Rt = _rt(R, ((x[0], x[1], x[2]), (x[4], x[5], x[6]), (x[8], x[9], x[10])))
    d = (x[3] - p[0], x[7] - p[1], x[11] - p[2])
    pt = (
        R[0][0] * d[0] + (R[1][0] * d[1] + R[2][0] * d[2]),
        R[0][1] * d[0] + (R[1][1] * d[1] + R[2][1] * d[2]),
        R[0][2] * d[0] + (R[1][2] * d[1] + R[2][2] * d[2]),
    )
    v = log6(Rt, pt)
    E = 0.0
    for k in range(6):
        e[k] = v[k]
        E += v[k] * v[k]
    if E > tsum:
        return E, math.inf, math.inf
    return (
        E,
        (pt[0] * pt[0] + pt[1] * pt[1]) + pt[2] * pt[2],
        (e[3] * e[3] + e[4] * e[4]) + e[5] * e[5],
    )


@kernel
def target_jacobian(kind, R, J6, J, n):
    """J (m, n) in the frame of the target's error from the LOCAL_WORLD_ALIGNED J6 (6, n): a
    pose's LOCAL Jacobian Rᵀ J6 (both blocks), a position's linear rows, a rotation's LOCAL
    angular rows Rᵀ J6[3:] (the first n columns)."""
    if kind == POSITION:
        for r in range(3):
            for c in range(n):
                J[r, c] = J6[r, c]
        return
    ang = 3 if kind == POSE else 0  # the rows of J the angular block goes to
    for r in range(3):
        for c in range(n):
            J[ang + r, c] = R[0][r] * J6[3, c] + (R[1][r] * J6[4, c] + R[2][r] * J6[5, c])
            if kind == POSE:
                J[r, c] = R[0][r] * J6[0, c] + (R[1][r] * J6[1, c] + R[2][r] * J6[2, c])


# ----------------------------------------------------------------------------- the damped step
@kernel
def cholesky_solve(A, k, x):
    """Solve A y = x in place (x ← y) for the symmetric k × k block of A by its Cholesky factor
    L Lᵀ (written into A's lower triangle); False where A is not positive definite (a pivot ≤ 0
    or NaN, as LAPACK's ``dpotrf``)."""
    for j in range(k):
        ajj = A[j, j]
        for m in range(j):
            ajj -= A[j, m] * A[j, m]
        if not ajj > 0.0:
            return False
        ajj = math.sqrt(ajj)
        A[j, j] = ajj
        for i in range(j + 1, k):
            a = A[i, j]
            for m in range(j):
                a -= A[i, m] * A[j, m]
            A[i, j] = a / ajj
    for i in range(k):
        a = x[i]
        for m in range(i):
            a -= A[i, m] * x[m]
        x[i] = a / A[i, i]
    for i in range(k - 1, -1, -1):
        a = x[i]
        for m in range(i + 1, k):
            a -= A[m, i] * x[m]
        x[i] = a / A[i, i]
    return True


@kernel
def solve_damped(J, m, n, e, lam, A, x, dq):
    """dq ← Jᵀ(JJᵀ + λI)⁻¹e (m ≤ n) or (JᵀJ + λI)⁻¹Jᵀe (n < m: JJᵀ singular), equal by the
    push-through identity; J (m, n) in the first m rows of ``J``.  False where the system is
    not positive definite.  ``A`` (k, k), ``x`` (k,) scratch, k ≥ max(m, n)."""
    if m <= n:
        for i in range(m):
            for r in range(i + 1):
                s = 0.0
                for c in range(n):
                    s += J[i, c] * J[r, c]
                A[i, r] = s
                A[r, i] = s
            A[i, i] += lam
            x[i] = e[i]
        if not cholesky_solve(A, m, x):
            return False
        for c in range(n):
            s = 0.0
            for i in range(m):
                s += x[i] * J[i, c]
            dq[c] = s
        return True
    for a in range(n):
        for b in range(a + 1):
            s = 0.0
            for i in range(m):
                s += J[i, a] * J[i, b]
            A[a, b] = s
            A[b, a] = s
        A[a, a] += lam
        s = 0.0
        for i in range(m):
            s += e[i] * J[i, a]
        dq[a] = s
    return cholesky_solve(A, n, dq)


@kernel
def damped_step(th, J, Jm, m, e, lam, lo, hi, A, x, dq, tn, n):
    """θ ← clip(θ + Δθ) in place, with the active set of the module docstring (the joints the
    step pushes past a limit frozen, the step recomputed without them and clipped); False (θ
    unchanged) where the system is not positive definite; θ, limits and scratch of length ≥ n
    (the first n used).  ``Jm`` (≥ m, n), ``tn`` scratch."""
    if not solve_damped(J, m, n, e, lam, A, x, dq):
        return False
    hit = False
    for c in range(n):
        t = th[c] + dq[c]
        tn[c] = t
        o = min(max(t, lo[c]), hi[c])
        hit = hit or (o != t and t == t)  # (a NaN step is not a limit hit)
        dq[c] = o
    if hit:
        for i in range(m):
            for c in range(n):
                Jm[i, c] = J[i, c] if min(max(tn[c], lo[c]), hi[c]) == tn[c] else 0.0
        if solve_damped(Jm, m, n, e, lam, A, x, tn):
            for c in range(n):
                th[c] = min(max(th[c] + tn[c], lo[c]), hi[c])
            return True
    for c in range(n):
        th[c] = dq[c]
    return True


# ----------------------------------------------------------------------------- the attempt
#: rows of the buffer ``B`` of :func:`run` (width k = max(16, n)): θ, best θ, the state (``IT``
#: …), the target (``Target.x``), lower and upper limits, e, x, dq, tn, then the
#: blocks J6 (6 rows), J (6), Jm (6), A (k) and W (P)
TH, BEST, ST, TGT, LO, HI, E_, X_, DQ, TN, J6_ = range(11)


@kernel
def run(F, B, kind, tp2, tr2, tsum, start):
    """Iterate the attempt from θ (row ``TH`` of ``B``, updated in place) until the target's
    tolerances are met, the error stops falling by 10 % for :data:`~.kernel.STALL` iterations,
    :data:`~.kernel.MAX_ITER`, a singular system — or, every 8th iteration, a pause for the caller to
    look at the clock; ``start=False`` resumes it (with the step of the error and Jacobian it
    left in ``B``).  ``F``: the chain (:class:`~anthroarm.ik.fk.PathFrames`);
    ``B``: the target and limits, the state, the iterate of least ‖e‖² (row ``BEST``) and
    the scratch arrays (see ``TH``).  Returns ``FAILED``, ``CONVERGED`` or
    ``PAUSED``."""
    n = int(B[ST, NCOL])
    m = 6 if kind == POSE else 3
    k = B.shape[1]
    th, best, st, x_t, lo, hi = B[TH], B[BEST], B[ST], B[TGT], B[LO], B[HI]
    e, x, dq, tn = B[E_], B[X_], B[DQ], B[TN]
    J6 = B[J6_ : J6_ + 6]  # (full rows: contiguous; the first n columns used)
    J = B[J6_ + 6 : J6_ + 12]
    Jm = B[J6_ + 12 : J6_ + 18]
    Am = B[J6_ + 18 : J6_ + 18 + k]
    W = B[J6_ + 18 + k :]
    if start:
        st[IT], st[STALLS], st[REF_E], st[BEST_E] = 0.0, 0.0, math.inf, math.inf
        st[PE2], st[RE2], st[LAST_E], st[RESUME] = 0.0, 0.0, 0.0, 0.0
    it, stall = int(st[IT]), int(st[STALLS])
    ref_E, best_E, pe2, re2, E = st[REF_E], st[BEST_E], st[PE2], st[RE2], st[LAST_E]
    resume = st[RESUME] != 0.0
    code = FAILED
    while True:
        if not resume:
            if it >= MAX_ITER:
                break
            it += 1
            R, p = chain_fk_jacobian(F, th, J6, W, n)
            E, pe2, re2 = residual(kind, x_t, tsum, R, p, e)
            if pe2 <= tp2 and re2 <= tr2:
                best_E = E
                for c in range(n):
                    best[c] = th[c]
                code = CONVERGED
                break
            if E < best_E:
                best_E = E
                for c in range(n):
                    best[c] = th[c]
            if E < 0.9 * ref_E:
                ref_E, stall = E, 0
            else:
                stall += 1
                if stall >= STALL:
                    break
            target_jacobian(kind, R, J6, J, n)
            if not it & 7:
                code = PAUSED
                break
        resume = False
        if not damped_step(th, J, Jm, m, e, LAMBDA0 + K_DAMP * E, lo, hi, Am, x, dq, tn, n):
            break
    st[IT], st[STALLS] = it, stall
    st[REF_E], st[BEST_E], st[PE2], st[RE2], st[LAST_E] = ref_E, best_E, pe2, re2, E
    st[RESUME] = 1.0 if code == PAUSED else 0.0
    return code


class Buffers:
    """The calling thread's arrays of :func:`run` for one (robot, frame): the chain ``F``
    (:class:`~anthroarm.ik.fk.PathFrames`) and the buffer ``B`` (see ``TH``),
    with views ``th``, ``tgt`` of its rows."""

    __slots__ = ("F", "B", "n", "th", "tgt", "warm")

    def __init__(self, path, lo, hi):
        n = len(lo)
        k = max(16, n)
        self.F, self.n = path.F, n
        self.B = np.zeros((J6_ + 18 + k + max(path.P, 1), k))
        self.B[LO, :n], self.B[HI, :n] = lo, hi
        self.B[ST, NCOL] = n
        self.th, self.tgt = self.B[TH, :n], self.B[TGT]
        self.warm = False  # :func:`warm` has run


def warm(ws) -> None:
    """One untimed attempt (the pose of the reference posture, from it), so that a first call
    in ``ANTHROARM_JIT=compile`` mode compiles :func:`run` (or loads it) before any clock
    starts: a time budget never counts compilation."""
    sh = ws.sh
    H = ws.fk(sh.ref).homogeneous
    attempt(ws, Target("pose", H, 1e-6, 1e-6), sh.ref, math.inf)
    ws.lm.warm = True


def attempt(ws, tg, th, deadline):
    """Damped Gauss–Newton from θ until the target's tolerances are met, the error stops falling
    by 10 % for :data:`~.kernel.STALL` iterations, :data:`~.kernel.MAX_ITER` or the deadline (thread CPU time,
    looked at every 8th iteration).

    Returns (θ, converged, iterations, pos_err², rot_err², best θ, best ‖e‖²): the last iterate
    with its squared errors, and the iterate of least ‖e‖² seen (fresh arrays)."""
    b = ws.lm
    F, B = b.F, b.B
    b.th[:] = th
    x = tg.x
    b.tgt[: len(x)] = x
    kind, tp2, tr2, tsum = tg.kind, tg.tp2, tg.tr2, tg.tsum
    code = run(F, B, kind, tp2, tr2, tsum, True)
    while code == PAUSED and clock() <= deadline:
        code = run(F, B, kind, tp2, tr2, tsum, False)
    it, _, _, bE, pe2, re2 = B[ST, :6].tolist()
    t = b.th.copy()
    if code == CONVERGED:
        return t, True, int(it), pe2, re2, t, bE
    return t, False, int(it), pe2, re2, B[BEST, : b.n].copy(), bE
