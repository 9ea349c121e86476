"""Compiled kernel of :mod:`anthroarm.motion.osim_ik` (:mod:`anthroarm.jit`): the marker-IK
normal equations of one iteration, from the bodies' world Jacobians, without forming the
3M × nq marker Jacobian."""

from __future__ import annotations

from ..jit import kernel


@kernel
def marker_normal_equations(T, body_of, local, JB, target, w, p, H, g):
    """Gauss–Newton normal equations of Σ_k w_k ‖p_k − m_k‖² in q.

    ``T`` (B, 4, 4) world placements of the B bodies that carry markers, ``body_of`` (M,) the
    body of each marker, ``local`` (M, 3) its position in that body (m), ``JB`` (B, 6, nq)
    each body's world Jacobian in q (rows (v_O; ω): the velocity of the point at the world
    origin moving with the body, and the angular velocity), ``target`` (M, 3), ``w`` (M,)
    weights (0: missing).  Writes ``p`` (M, 3) the marker positions, ``H`` = Σ w_k J_kᵀ J_k and
    ``g`` = Σ w_k J_kᵀ (p_k − m_k) with J_k = v_O + ω × p_k (the point's velocity in world
    axes); returns Σ w_k ‖p_k − m_k‖².
    """
    M = local.shape[0]
    nq = JB.shape[2]
    for a in range(nq):
        g[a] = 0.0
        for c in range(nq):
            H[a, c] = 0.0
    cost = 0.0
    for k in range(M):
        b = body_of[k]
        lx, ly, lz = local[k, 0], local[k, 1], local[k, 2]
        px = T[b, 0, 0] * lx + T[b, 0, 1] * ly + T[b, 0, 2] * lz + T[b, 0, 3]
        py = T[b, 1, 0] * lx + T[b, 1, 1] * ly + T[b, 1, 2] * lz + T[b, 1, 3]
        pz = T[b, 2, 0] * lx + T[b, 2, 1] * ly + T[b, 2, 2] * lz + T[b, 2, 3]
        p[k, 0], p[k, 1], p[k, 2] = px, py, pz
        wk = w[k]
        if wk == 0.0:
            continue
        ex, ey, ez = px - target[k, 0], py - target[k, 1], pz - target[k, 2]
        cost += wk * (ex * ex + ey * ey + ez * ez)
        for a in range(nq):
            # column a of J_k: v + ω × p
            ja_x = JB[b, 0, a] + JB[b, 4, a] * pz - JB[b, 5, a] * py
            ja_y = JB[b, 1, a] + JB[b, 5, a] * px - JB[b, 3, a] * pz
            ja_z = JB[b, 2, a] + JB[b, 3, a] * py - JB[b, 4, a] * px
            if ja_x == 0.0 and ja_y == 0.0 and ja_z == 0.0:
                continue
            g[a] += wk * (ja_x * ex + ja_y * ey + ja_z * ez)
            for c in range(a, nq):
                jc_x = JB[b, 0, c] + JB[b, 4, c] * pz - JB[b, 5, c] * py
                jc_y = JB[b, 1, c] + JB[b, 5, c] * px - JB[b, 3, c] * pz
                jc_z = JB[b, 2, c] + JB[b, 3, c] * py - JB[b, 4, c] * px
                H[a, c] += wk * (ja_x * jc_x + ja_y * jc_y + ja_z * jc_z)
    for a in range(nq):
        for c in range(a + 1, nq):
            H[c, a] = H[a, c]
    return cost
