"""The FK check of the compiled closed forms on the chain's FK (:mod:`anthroarm.ik.fk`): the FK
residual of the candidate branches of one pose (:func:`_fk_residuals`), the Newton polish of a
candidate within the joint limits (:func:`_polish_chain`) and the errors reported against a
target (:func:`_target_errors`)."""

from __future__ import annotations

import math

from ...jit import kernel
from ..fk import chain_pose, frame, joint_step, newton_pose, pose_error
from ..vec3 import mat, mtm, norm


@kernel
def _target_errors(A, q, T):
    """(‖p* − p‖ m, ‖log₃(Rᵀ R*)‖ rad) of the tool pose (R, p) = F(q) (:func:`chain_pose`)
    against T = (R*, p*) — the position and rotation errors :func:`anthroarm.ik.solve` reports
    (the angle of W = Rᵀ R* as atan2(‖vee(W − Wᵀ)‖ / 2, (tr W − 1) / 2), accurate near 0 and π)."""
    R, x = chain_pose(A, q)
    W = mtm(R, mat(T))
    v = (W[2][1] - W[1][2], W[0][2] - W[2][0], W[1][0] - W[0][1])
    return (
        norm((T[0, 3] - x[0], T[1, 3] - x[1], T[2, 3] - x[2])),
        math.atan2(0.5 * norm(v), 0.5 * (W[0][0] + W[1][1] + W[2][2] - 1.0)),
    )


@kernel
def _polish_chain(A, q, n, T, lo, hi, tol, J, W, E):
    """Newton steps on the pose equations F(q) = T of the chain's first six joints (a 7th held;
    :func:`anthroarm.ik.fk.newton_pose`), in place on ``q`` (n,) rad, for a candidate of an arm
    that is of its class only within the classification tolerance (its class solution is off
    by up to that much, ~1e-7 m): at most :data:`POLISH_STEPS` steps, fewer once the residual
    is ≤ 1e-3 ``tol``.  A joint within 1e-9 rad outside a limit is put onto it.  Returns the
    FK residual (:func:`anthroarm.ik.fk.pose_error`) of the angles it leaves in ``q``, inf if a
    joint left its limits by more than 1e-9 rad.  ``J`` (6, ≥ n), ``W`` (≥ n, 6), ``E`` (6,)
    scratch."""
    RT, pT = mat(T), (T[0, 3], T[1, 3], T[2, 3])
    res = newton_pose(A, q, n, RT, pT, POLISH_STEPS, 1e-3 * tol, J, W, E)
    moved = False
    for j in range(n):
        if q[j] < lo[j] - 1e-9 or q[j] > hi[j] + 1e-9:
            return math.inf
        x = min(max(q[j], lo[j]), hi[j])
        moved = moved or x != q[j]
        q[j] = x
    if moved:  # put onto a limit: the residual of the angles returned
        R, x = chain_pose(A, q)
        res = pose_error(R, x, RT, pT)
    return res


@kernel
def _fk_residuals(A, Q, QC, QS, V, n, T, RES, S):
    """The FK residual max |F(θ) − T| over the 3×4 pose entries (the product of
    :func:`anthroarm.ik.fk.local_frames`, :func:`anthroarm.ik.fk.pose_error`) of every
    candidate branch b (``V[b]``) of Q (B, n) into RES (B,) (inf where there is none), each
    joint's rotation from QC, QS (B, n), the cosine and sine of its angle (the rotation the
    class solver found, whose angle Q is, whole turns added or not; cos and sin of Q where
    :func:`into_limit_cs` put it onto a limit or the polish moved it), the partial products
    shared along the branch tree: branches come root index innermost, so a branch repeats the
    leading angles of the one before it, and the partial products up to the first joint whose
    angle differs are kept (scratch S (n + 1, 12): rotation rows and translation after each
    joint) — the same arithmetic as one product per branch, about a third fewer joint factors
    for 8 branches.  A driver of its own beside :func:`anthroarm.ik.fk.chain_pose`: it takes
    the cosines and sines the class solver found (no cos, sin calls) and shares the partial
    products."""
    RT, pT = mat(T), (T[0, 3], T[1, 3], T[2, 3])
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
            R, t = frame(S, i)
            R, t = joint_step(R, t, A, i + 1, QC[b, i], QS[b, i])
            S[i + 1, 0], S[i + 1, 1], S[i + 1, 2] = R[0]
            S[i + 1, 3], S[i + 1, 4], S[i + 1, 5] = R[1]
            S[i + 1, 6], S[i + 1, 7], S[i + 1, 8] = R[2]
            S[i + 1, 9], S[i + 1, 10], S[i + 1, 11] = t
        R, t = frame(S, n)
        RES[b] = pose_error(R, t, RT, pT)


#: FK residual up to which a candidate inside the limits is polished (:func:`_polish_chain` in
#: the compiled call): an arm that is of its class only within the classification tolerance, a
#: least-squares root where a subproblem's two roots meet (a singular pose); what that leaves,
#: :func:`anthroarm.ik.closed_form.analytic`
POLISH_MAX = 1e-4
#: Newton steps of :func:`_polish_chain` at most (quadratic convergence from ~1e-7: two suffice)
POLISH_STEPS = 4
