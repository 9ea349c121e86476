"""Newton steps on the whole arm's pose (the one FK of :mod:`anthroarm.ik.fk` on IK-Geo's chain
as local frames, :func:`geo_frames`), and the slots of the branches a search finds."""

from __future__ import annotations

import numpy as np

from ...jit import kernel, part, part2
from ..fk import WIDTH, chain_pose, local_frames, newton_pose, pose_error
from ..vec3 import wrap
from .constants import SEARCH_BRANCHES, SEARCH_TOL


def geo_frames(H, P) -> np.ndarray:
    """IK-Geo's arm (axes ``H`` (6, 3), offsets ``P`` (7, 3), base frame, m, q = 0) as the
    local frames of :func:`anthroarm.ik.fk.local_frames` (7, 16): joint i's axis through
    o_i = P_0 + ⋯ + P_{i−1}, the tool at o_7 with the rotation I — its FK is
    (R06(q), p(q)) = (rot(h1, q1) ⋯ rot(h6, q6), o_1 + R_1 P_1 + ⋯ + R_6 P_6), the pose
    the searches solve for (Elias & Wen, IK-Geo, arXiv 2211.05737, §II)."""
    H, P = np.asarray(H, dtype=float), np.asarray(P, dtype=float)
    o = np.cumsum(P, axis=0)
    M = np.eye(4)
    M[:3, 3] = o[6]
    return local_frames(H, o[:6], M)


#: entries of a search's Newton workspace (:func:`workspace`): the arm's frames (7, 16), then
#: the scratch J (6, 6), W (6, 6), E (6,) of :func:`anthroarm.ik.fk.newton_pose`
WORKSPACE = 7 * WIDTH + 36 + 36 + 6


@kernel
def workspace(A):
    """The Newton workspace of a search, one array (:data:`WORKSPACE`) threaded through its
    kernels: the arm's frames ``A`` (7, 16) (:func:`geo_frames`) and the polish's scratch."""
    pol = np.empty(WORKSPACE)
    for i in range(7):
        for j in range(WIDTH):
            pol[i * WIDTH + j] = A[i, j]
    return pol


@kernel(inline=True)
def _parts(pol):
    """The arm's frames (7, 16), J (6, 6), W (6, 6), E (6,) of a workspace (borrowed views)."""
    o = 7 * WIDTH
    return (
        part2(pol, 0, 7, WIDTH),
        part2(pol, o, 6, 6),
        part2(pol, o + 36, 6, 6),
        part(pol, o + 72, 6),
    )


@kernel
def polish(pol, R06, p, q, iters):
    """At most ``iters`` Newton steps on the whole arm's pose equations from ``q`` (6,) rad, in
    place (:func:`anthroarm.ik.fk.newton_pose` on the arm of the workspace ``pol``,
    :func:`workspace`; pose (``R06``, ``p``) in IK-Geo's form); ``q`` is wrapped into
    (−π, π] at the end; returns whether it converged (max entry of |R − R06| and |o − p|
    ≤ :data:`SEARCH_TOL`)."""
    A, J, W, E = _parts(pol)
    err = newton_pose(A, q, 6, R06, p, iters, 1e-3 * SEARCH_TOL, J, W, E)
    for i in range(6):
        q[i] = wrap(q[i])
    return err <= SEARCH_TOL


@kernel
def fk_error(pol, R06, p, q):
    """The pose error of joint angles ``q`` (6,) rad: the max entry of |R − R06| and |o − p|
    (m) at their FK (:func:`anthroarm.ik.fk.chain_pose` of the arm of the workspace ``pol``)."""
    R, o = chain_pose(part2(pol, 0, 7, WIDTH), q)
    return pose_error(R, o, R06, p)


@kernel
def _push(Q, V, E, n, q, ex):
    """Append branch ``q`` (6,) to the slots Q (16, 6), V, E holding ``n`` branches, unless
    it is within 1e-8 rad of one of them (every joint, mod 2π) or the slots are full; returns
    the new count."""
    if n >= SEARCH_BRANCHES:
        return n
    for a in range(n):
        d = 0.0
        for j in range(6):
            d = max(d, abs(wrap(q[j] - Q[a, j])))
        if d < 1e-8:
            return n
    for j in range(6):
        Q[n, j] = wrap(q[j])
    V[n], E[n] = True, ex
    return n + 1
