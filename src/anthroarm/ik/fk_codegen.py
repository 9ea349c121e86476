"""Forward kinematics of ``robot.chain`` as an exact expression, in the project's one
expression graph (:mod:`anthroarm.codegen.graph`: hash-consed, constants folded, products with
0 and ±1 skipped).

The chain product of the path from the base to a frame (the joint placements, axes and the
frame's placement read from :class:`~anthroarm.chain.Chain`, the same model Pinocchio holds;
for the book's DH arms it is Eq. (6-14))

    T_0,frame(q) = O_1 Rot(a_1, q_1) O_2 Rot(a_2, q_2) … O_n Rot(a_n, q_n) O_frame

with inputs ``c{k}, s{k}`` (cos, sin of the k-th revolute joint along the path) or ``q{k}`` (a
prismatic joint).  :func:`frame_product` gives the frame's pose and every joint's frame; the
compiled attempt kernel of ``aa.ik.solve`` (:mod:`anthroarm.ik.solve.ckernel`) prints it as C
(its pose and Jacobian).
"""

from __future__ import annotations

import numpy as np

from ..codegen.graph import Graph, snap


def frame_product(chain, frame=None):
    """The pose of ``frame`` and the joints' frames along its path, in a new :class:`Graph`:
    ``(g, R, p, joints)`` with R (3 × 3 nested lists) and p (3,) the frame's rotation and
    position in the base frame, and ``joints[k]`` = (R_k, p_k) the frame of the k-th joint of
    ``chain.path(frame)`` after its placement (before its own motion: its axis in the base frame
    is R_k · axis, its origin p_k).  Inputs ``c{k}, s{k}`` (cos, sin of the k-th joint's angle)
    or ``q{k}`` (a prismatic joint's displacement), k the position along the path; a continuous
    joint is a revolute one here (its angle θ, not its (cos, sin) pair), a mimic joint reads its
    own angle θ_j = a θ_source + b (the caller supplies it)."""
    path = chain.path(frame)
    g = Graph()
    joints = []
    R, p = _product(g, chain, frame, path, [0, len(path)], [], joints)
    return g, R, p, joints


def _product(g, chain, frame, path, bounds, states, joints=None):
    """(R, p) of the chain product O_1 Rot(a_1, q_1) … O_n Rot(a_n, q_n) O_frame built in ``g``;
    appends the stage states to ``states`` and, if given, each joint's frame after its
    placement to ``joints``."""
    fr = chain.frame(frame)
    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    p = [0.0, 0.0, 0.0]

    def place(R, p, rot, tr):  # (R, p) ∘ (rot, tr), constant rot/tr
        rot = [[snap(x) for x in row] for row in np.asarray(rot, float)]
        tr = [snap(x) for x in np.asarray(tr, float)]
        p = [g.sum([p[i]] + [g.mul(tr[k], R[i][k]) for k in range(3)]) for i in range(3)]
        R = [
            [g.sum([g.mul(rot[k][c], R[i][k]) for k in range(3)]) for c in range(3)]
            for i in range(3)
        ]
        return R, p

    for pos, i in enumerate(path):
        j = chain.joints[i]
        R, p = place(R, p, j.rotation, j.translation)
        if joints is not None:
            joints.append((R, p))
        ax = [snap(x) for x in j.axis]
        if j.kind == "prismatic":
            q = g.input("q", pos)
            p = [
                g.add(p[r], g.mul(q, g.sum([g.mul(ax[k], R[r][k]) for k in range(3)])))
                for r in range(3)
            ]
        else:
            c, s = g.input("c", pos), g.input("s", pos)
            k = int(np.argmax(np.abs(ax)))
            if abs(ax[k]) == 1.0 and sum(abs(x) for x in ax) == 1.0:
                sg = ax[k]
                a, b = [(1, 2), (2, 0), (0, 1)][k]  # a rotation about e_k mixes columns a, b
                Rn = [row[:] for row in R]
                for r in range(3):
                    Rn[r][a] = g.add(g.mul(R[r][a], c), g.mul(sg, g.mul(R[r][b], s)))
                    Rn[r][b] = g.add(g.mul(R[r][b], c), g.mul(-sg, g.mul(R[r][a], s)))
                R = Rn
            else:  # Rodrigues: I + s K + (1 − c) K²
                K = np.array([[0.0, -ax[2], ax[1]], [ax[2], 0.0, -ax[0]], [-ax[1], ax[0], 0.0]])
                K2 = K @ K
                omc = g.add(1.0, g.mul(-1.0, c))
                Rq = [
                    [
                        g.sum(
                            [float(r == cc), g.mul(snap(K[r, cc]), s), g.mul(snap(K2[r, cc]), omc)]
                        )
                        for cc in range(3)
                    ]
                    for r in range(3)
                ]
                R = [
                    [g.sum([g.mul(R[r][k], Rq[k][cc]) for k in range(3)]) for cc in range(3)]
                    for r in range(3)
                ]
        if pos + 1 in bounds[1:-1]:
            states.append([v for row in R for v in row] + p)
    return place(R, p, fr.rotation, fr.translation)


__all__ = ["frame_product"]
