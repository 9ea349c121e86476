"""The 2-D search of ``gen_six_dof`` (IK-Geo ``IK_gen_6_dof``): (q1, q2) on a periodic grid, the
local minima of the error polished by Newton on the pose."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..subproblems.base import TOL, TOL_QUARTIC
from ..subproblems.circle import sp1_one
from ..subproblems.quartic import sp5_one
from ..vec3 import cross, mm, mtv, mv, neg, norm, rot, rotate, scale, sub
from .constants import _MIN_2D, _POLISH_2D
from .polish import _push, polish, workspace


# ----------------------------------------------------------------------------- 2-D search
@kernel
def _r05(h, q1, q2, t):
    return mm(
        mm(mm(mm(rot(h[0], q1), rot(h[1], q2)), rot(h[2], t[0])), rot(h[3], t[1])), rot(h[4], t[2])
    )


@kernel
def _gen_six_dof_pose(h, PP, A, R06, p, Q, V, E, grid):
    """Every branch found for one pose of ``gen_six_dof`` into Q (16, 6), V, E; returns their
    number.  ``A``: the arm's frames for the Newton polish (:func:`.polish.geo_frames`)."""
    p16 = sub(sub(p, mv(R06, PP[6])), PP[0])
    h6 = h[5]
    R06h6 = mv(R06, h6)
    # a unit vector ⟂ h6 (h6 × the axis of its smallest component)
    a0, a1, a2 = abs(h6[0]), abs(h6[1]), abs(h6[2])
    ax = (
        (1.0, 0.0, 0.0)
        if a0 <= a1 and a0 <= a2
        else ((0.0, 1.0, 0.0) if a1 <= a2 else (0.0, 0.0, 1.0))
    )
    u = cross(h6, ax)
    u = scale(u, 1.0 / norm(u))
    G2 = grid * grid
    step = 2.0 * math.pi / grid
    xs = np.empty(grid)
    for i in range(grid):
        xs[i] = i * step - math.pi
    GQ, GE, GM = np.zeros((G2, 4, 3)), np.full((G2, 4), math.inf), np.full(G2, math.inf)
    t = np.empty((4, 3))
    for i in range(grid):
        for j in range(grid):
            k = i * grid + j
            q1, q2 = xs[i], xs[j]
            p63 = sub(rotate(neg(h[1]), q2, sub(rotate(neg(h[0]), q1, p16), PP[1])), PP[2])
            cnt, _ = sp5_one(neg(PP[3]), p63, PP[4], PP[5], neg(h[2]), h[3], h[4], TOL_QUARTIC, t)
            for r in range(cnt):
                GQ[k, r, 0], GQ[k, r, 1], GQ[k, r, 2] = t[r, 0], t[r, 1], t[r, 2]
                R05 = _r05(h, q1, q2, (t[r, 0], t[r, 1], t[r, 2]))
                GE[k, r] = norm(sub(mv(R05, h6), R06h6))
                GM[k] = min(GM[k], GE[k, r])
    q = np.empty(6)
    pol = workspace(A)
    n = 0
    for i in range(grid):
        for j in range(grid):
            k = i * grid + j
            nb = math.inf
            for a in range(-1, 2):
                for b in range(-1, 2):
                    if a != 0 or b != 0:
                        nb = min(nb, GM[((i + a) % grid) * grid + (j + b) % grid])
            for r in range(4):
                if GE[k, r] <= nb and GE[k, r] < _MIN_2D:
                    tr = (GQ[k, r, 0], GQ[k, r, 1], GQ[k, r, 2])
                    R05 = _r05(h, xs[i], xs[j], tr)
                    q6, _, _ = sp1_one(u, mtv(R05, mv(R06, u)), h6, TOL)
                    q[0], q[1], q[2], q[3], q[4], q[5] = xs[i], xs[j], tr[0], tr[1], tr[2], q6
                    if polish(pol, R06, p, q, _POLISH_2D):
                        n = _push(Q, V, E, n, q, True)
    return n
