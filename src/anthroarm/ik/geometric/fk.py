"""The chain's forward kinematics in joint-local frames (:func:`local_frames`), its Jacobian, the FK
residual of the candidate branches of one pose, and the Newton polish of a candidate on the
chain's pose equations: the compiled FK check of the geometric IK."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..search.polish import solve6
from ..vec3 import add, cross, mat, mm, mtm, mv, norm, perpendicular, sub, transpose


# ----------------------------------------------------------------------------- the chain's FK (local frames)
def local_frames(axes, points, M) -> np.ndarray:
    """The forward kinematics of a chain of revolute joints as constant rigid transforms:
    F(q) = A_0 Rz(q1) A_1 Rz(q2) ⋯ Rz(qn) A_n, returned as A (n + 1, 12) (each row: the
    rotation row by row, then the translation; base frame, m).

    ``axes`` (n, 3) unit joint axes through ``points`` (n, 3) at q = 0, ``M`` (4×4) the tool
    pose at q = 0 (base frame, m).  Joint i gets a frame F_i whose z axis is its axis, at its
    point; then e^{ξi qi} = F_i Rz(qi) F_i⁻¹, and the product of exponentials
    e^{ξ1 q1} ⋯ e^{ξn qn} M (Lynch & Park, *Modern Robotics*, 2017, §4.1.1) becomes the product
    above with A_0 = F_1, A_i = F_i⁻¹ F_{i+1}, A_n = F_n⁻¹ M.  A joint's rotation then turns
    two columns of the partial product (:func:`_joint_step`): about three quarters of the
    arithmetic of a product of exponentials, and the tool pose comes out without a last
    multiplication by M."""
    axes, points, M = (np.asarray(a, dtype=float) for a in (axes, points, M))
    frames = []
    for k, o in zip(axes, points):
        x = np.array(perpendicular(tuple(k)))
        frames.append((np.column_stack([x, np.cross(k, x), k]), o))
    A = np.empty((len(frames) + 1, 12))
    chain = [(np.eye(3), np.zeros(3))] + frames + [(M[:3, :3], M[:3, 3])]
    for i in range(len(frames) + 1):
        (Ra, pa), (Rb, pb) = chain[i], chain[i + 1]
        A[i, :9], A[i, 9:] = (Ra.T @ Rb).ravel(), Ra.T @ (pb - pa)
    return A


@kernel
def _frame(A, i):
    """Row i of A (:func:`local_frames`) as (R, t)."""
    return (
        ((A[i, 0], A[i, 1], A[i, 2]), (A[i, 3], A[i, 4], A[i, 5]), (A[i, 6], A[i, 7], A[i, 8])),
        (A[i, 9], A[i, 10], A[i, 11]),
    )


@kernel
def _joint_step(R, t, A, i, c, s):
    """(R, t) · Rz(q) · A_i, a partial product of :func:`local_frames` taken one joint further,
    from c = cos q and s = sin q: the first two columns of R turned by q, then A_i."""
    Rq = (
        (R[0][0] * c + R[0][1] * s, R[0][1] * c - R[0][0] * s, R[0][2]),
        (R[1][0] * c + R[1][1] * s, R[1][1] * c - R[1][0] * s, R[1][2]),
        (R[2][0] * c + R[2][1] * s, R[2][1] * c - R[2][0] * s, R[2][2]),
    )
    B, a = _frame(A, i)
    return mm(Rq, B), add(mv(Rq, a), t)


@kernel
def _pose_error(R, t, T):
    """max |F − T| over the 3×4 entries of the pose F = (R, t)."""
    err = 0.0
    for i in range(3):
        err = max(err, abs(t[i] - T[i, 3]))
        for j in range(3):
            err = max(err, abs(R[i][j] - T[i, j]))
    return err


@kernel
def _chain_fk(A, q, n):
    """The tool pose (R, t) = F(q) of the chain (:func:`local_frames`; q (n,) rad, path order)."""
    R, t = _frame(A, 0)
    for i in range(n):
        R, t = _joint_step(R, t, A, i + 1, math.cos(q[i]), math.sin(q[i]))
    return R, t


@kernel
def _target_errors(A, q, n, T):
    """(‖p* − p‖ m, ‖log₃(Rᵀ R*)‖ rad) of the tool pose (R, p) = F(q) (:func:`_chain_fk`)
    against T = (R*, p*) — the position and rotation errors :func:`anthroarm.ik.solve` reports
    (the angle of W = Rᵀ R* as atan2(‖vee(W − Wᵀ)‖ / 2, (tr W − 1) / 2), accurate near 0 and π)."""
    R, x = _chain_fk(A, q, n)
    W = mtm(R, mat(T))
    v = (W[2][1] - W[1][2], W[0][2] - W[2][0], W[1][0] - W[0][1])
    return (
        norm((T[0, 3] - x[0], T[1, 3] - x[1], T[2, 3] - x[2])),
        math.atan2(0.5 * norm(v), 0.5 * (W[0][0] + W[1][1] + W[2][2] - 1.0)),
    )


@kernel
def _chain_jacobian(A, q, n, J):
    """The 6×6 Jacobian J of the first six joints at ``q`` (path order, rad; a 7th held), at the
    tool point x, base frame: column i is (w × (x − o); w) with the joint's axis w, the z axis
    of the partial product (R, t) of :func:`local_frames` before the joint's rotation, through
    its point o = t.  Returns the tool pose (R, t) = F(q)."""
    R, t = _frame(A, 0)
    for i in range(n):
        if i < 6:
            J[3, i], J[4, i], J[5, i] = R[0][2], R[1][2], R[2][2]
            J[0, i], J[1, i], J[2, i] = t
        R, t = _joint_step(R, t, A, i + 1, math.cos(q[i]), math.sin(q[i]))
    for i in range(6):
        c = cross((J[3, i], J[4, i], J[5, i]), sub(t, (J[0, i], J[1, i], J[2, i])))
        J[0, i], J[1, i], J[2, i] = c
    return R, t


@kernel
def _polish_chain(A, q, n, T, lo, hi, tol, J, F):
    """Newton steps on the pose equations F(q) = T of the chain's first six joints (a 7th held),
    in place on ``q`` (n,) rad, for a candidate of an arm that is of its class only within the
    classification tolerance (its class solution is off by up to that much, ~1e-7 m).

    The Jacobian :func:`_chain_jacobian`, the error (x* − x;
    ½ vee(R* Rᵀ − R R*ᵀ)) (the same step as :func:`anthroarm.ik.search.polish`).  At most
    :data:`POLISH_STEPS` steps, fewer once the residual is ≤ 1e-3 ``tol``; a step on a singular
    Jacobian (|det| ≤ 1e-12) ends it.  A joint within 1e-9 rad outside a limit is put onto it.
    Returns the FK residual (:func:`_pose_error`) of the angles it leaves in ``q``, inf if a
    joint left its limits by more than 1e-9 rad.  ``J`` (6, 6), ``F`` (6,)
    scratch."""
    res = math.inf
    for it in range(POLISH_STEPS + 1):
        R, x = _chain_jacobian(A, q, n, J)
        res = _pose_error(R, x, T)
        if res <= 1e-3 * tol or it == POLISH_STEPS:
            break
        W = mm(mat(T), transpose(R))
        F[0], F[1], F[2] = T[0, 3] - x[0], T[1, 3] - x[1], T[2, 3] - x[2]
        F[3] = 0.5 * (W[2][1] - W[1][2])
        F[4] = 0.5 * (W[0][2] - W[2][0])
        F[5] = 0.5 * (W[1][0] - W[0][1])
        if abs(solve6(J, F)) <= 1e-12:
            break
        for i in range(6):
            q[i] += F[i]
    moved = False
    for j in range(n):
        if q[j] < lo[j] - 1e-9 or q[j] > hi[j] + 1e-9:
            return math.inf
        x = min(max(q[j], lo[j]), hi[j])
        moved = moved or x != q[j]
        q[j] = x
    if moved:  # put onto a limit: the residual of the angles returned
        R, x = _chain_fk(A, q, n)
        res = _pose_error(R, x, T)
    return res


@kernel
def _fk_residuals(A, Q, QC, QS, V, n, T, RES, S):
    """The FK residual max |F(θ) − T| over the 3×4 pose entries (:func:`_chain_fk`,
    :func:`_pose_error`) of every candidate branch b (``V[b]``) of Q (B, n) into RES (B,)
    (inf where there is none), each joint's rotation from QC, QS (B, n), the cosine and sine
    of its angle (the rotation the class solver found, whose angle Q is, whole turns added
    or not; cos and sin of Q where :func:`into_limit_cs` put it onto a limit or the polish
    moved it), the partial products shared along the branch tree:
    branches come root index innermost, so a branch repeats the leading angles of the one
    before it, and the partial products up to the first joint whose angle differs are kept
    (scratch S (n + 1, 12): rotation rows and translation after each joint) — the same
    arithmetic as one product per branch, about a third fewer joint factors for 8 branches."""
    for k in range(12):
        S[0, k] = A[0, k]
    prev = -1
    for b in range(len(V)):
        if not V[b]:
            RES[b] = math.inf
            continue
        j0 = 0
        if prev >= 0:
            while j0 < n and Q[b, j0] == Q[prev, j0]:
                j0 += 1
        prev = b
        for i in range(j0, n):
            R, t = _frame(S, i)
            R, t = _joint_step(R, t, A, i + 1, QC[b, i], QS[b, i])
            S[i + 1, 0], S[i + 1, 1], S[i + 1, 2] = R[0]
            S[i + 1, 3], S[i + 1, 4], S[i + 1, 5] = R[1]
            S[i + 1, 6], S[i + 1, 7], S[i + 1, 8] = R[2]
            S[i + 1, 9], S[i + 1, 10], S[i + 1, 11] = t
        R, t = _frame(S, n)
        RES[b] = _pose_error(R, t, T)


#: FK residual up to which a candidate inside the limits is polished (:func:`_polish_chain` in
#: the compiled call): an arm that is of its class only within the classification tolerance, a
#: least-squares root where a subproblem's two roots meet (a singular pose); what that leaves,
#: :func:`anthroarm.ik.closed_form.analytic`
POLISH_MAX = 1e-4
#: Newton steps of :func:`_polish_chain` at most (quadratic convergence from ~1e-7: two suffice)
POLISH_STEPS = 4


# ----------------------------------------------------------------------------- any chain (prismatic, mimic)
#: columns of ``PathFrames.F`` after a joint's local frame (:func:`local_frames`, 12)
PRISMATIC, COL, MUL, OFF = 12, 13, 14, 15


class PathFrames:
    """The path from the base to one frame of ``robot.chain`` as the one array ``F`` (P + 1, 16)
    of :func:`chain_fk_jacobian`: row k holds the local frame A_k (:func:`local_frames`, from
    the P joints' placements and axes at θ = 0 and the frame's placement: 12 columns); for the
    k-th joint of the path, row k also holds [``PRISMATIC``] 1 for a prismatic joint (a
    translation along its axis), 0 for a revolute or continuous one, and the map of its value
    q_k = a θ[c] + b from the independent coordinates θ (``chain.independent`` order):
    [``COL``] c, [``MUL``] a, [``OFF``] b (a mimic joint reads its source's θ, any
    other joint is its own θ with a = 1, b = 0)."""

    __slots__ = ("F", "P")

    def __init__(self, chain, frame):
        path = chain.path(frame)
        fr = chain.frame(frame)
        v_of = {j: k for k, j in enumerate(chain.independent)}
        R, p = np.eye(3), np.zeros(3)
        axes, points = [], []
        for i in path:  # each joint's placement, at θ = 0 (no joint motion)
            j = chain.joints[i]
            R, p = R @ j.rotation, p + R @ j.translation
            axes.append(R @ np.asarray(j.axis, dtype=float))
            points.append(p)
        M = np.eye(4)
        M[:3, :3], M[:3, 3] = R @ fr.rotation, p + R @ fr.translation
        self.P = len(path)
        self.F = np.zeros((self.P + 1, 16))
        self.F[:, :12] = local_frames(np.reshape(axes, (-1, 3)), np.reshape(points, (-1, 3)), M)
        for k, i in enumerate(path):
            j = chain.joints[i]
            self.F[k, PRISMATIC] = float(j.kind == "prismatic")
            self.F[k, COL] = v_of[j.mimic.source if j.is_mimic else i]
            self.F[k, MUL] = j.mimic.multiplier if j.is_mimic else 1.0
            self.F[k, OFF] = j.mimic.offset if j.is_mimic else 0.0


@kernel
def chain_fk_jacobian(F, th, J, W, n):
    """The pose (R, t) of the frame of :class:`PathFrames` (``F``) at θ (the independent
    coordinates, rad or m) and its geometric Jacobian into the first n columns of J (6, ≥ n),
    LOCAL_WORLD_ALIGNED as
    Pinocchio's ``getFrameJacobian``: rows (v; ω) of the frame's origin in base axes; column of
    a revolute joint (z × (t − o); z), of a prismatic one (z; 0), with the joint's axis z and
    point o in the base frame (the z axis and origin of the partial product before its motion,
    see :func:`local_frames`), times a for a mimic joint q = a θ + b, summed into its source's
    column (the chain rule); zero columns for the coordinates off the path (Murray, Li &
    Sastry, *A Mathematical Introduction to Robotic Manipulation*, 1994, §3.4 (3.55)).  A
    prismatic joint translates the partial product along its z: (R, t) Tz(q) A_k =
    (R B, R a + t + q z).  ``W`` (≥ P, ≥ 6) scratch: each joint's z and o."""
    for r in range(6):
        for c in range(n):
            J[r, c] = 0.0
    R, t = _frame(F, 0)
    P = len(F) - 1
    for k in range(P):
        W[k, 0], W[k, 1], W[k, 2] = R[0][2], R[1][2], R[2][2]
        W[k, 3], W[k, 4], W[k, 5] = t
        q = F[k, MUL] * th[int(F[k, COL])] + F[k, OFF]
        if F[k, PRISMATIC] != 0.0:
            B, a = _frame(F, k + 1)
            t = add(add(mv(R, a), t), (q * R[0][2], q * R[1][2], q * R[2][2]))
            R = mm(R, B)
        else:
            R, t = _joint_step(R, t, F, k + 1, math.cos(q), math.sin(q))
    for k in range(P):
        c, a = int(F[k, COL]), F[k, MUL]
        z = (W[k, 0], W[k, 1], W[k, 2])
        if F[k, PRISMATIC] != 0.0:
            J[0, c] += a * z[0]
            J[1, c] += a * z[1]
            J[2, c] += a * z[2]
        else:
            v = cross(z, sub(t, (W[k, 3], W[k, 4], W[k, 5])))
            J[0, c] += a * v[0]
            J[1, c] += a * v[1]
            J[2, c] += a * v[2]
            J[3, c] += a * z[0]
            J[4, c] += a * z[1]
            J[5, c] += a * z[2]
    return R, t
