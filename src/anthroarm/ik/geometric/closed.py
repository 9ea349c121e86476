"""The closed IK-Geo classes in one compiled call: the class's kernel
(``anthroarm.ik.classes.solve_closed``, by its index in :data:`CLOSED`) writes the 8
branches of a pose as rotations and flags (:mod:`anthroarm.ik.classes.branches`), the angles are
read from them at the end."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..classes import CLOSED, solve_closed
from ..classes.branches import BRANCH_ROW, COS, EXACT, EXISTS, SIN, angles
from ..vec3 import mat, rows6, rows7, vec

__all__ = ["BRANCH_ROW", "CLOSED", "COS", "EXACT", "EXISTS", "SIN"]


@kernel
def _solve_closed(cls, h, P, R06, p, B):
    """The 8 branches of one pose of class ``cls`` (index in :data:`CLOSED`) into B: the
    class solver writes their rotations and flags, :func:`~anthroarm.ik.classes.branches.angles`
    reads the angles; a branch that does not exist is NaN."""
    for b in range(8):
        B[b, EXISTS], B[b, EXACT] = 0.0, 0.0
    solve_closed(cls, h, P, R06, p, B)
    angles(B)
    for b in range(8):
        if B[b, EXISTS] == 0.0:
            for j in range(6):
                B[b, j] = math.nan
            B[b, EXACT] = 0.0


@kernel
def _closed_loop(cls, H, P, R06, p, Q, V, E):
    h, PP = rows6(H), rows7(P)
    B = np.empty((8, BRANCH_ROW))
    for i in range(len(p)):
        _solve_closed(cls, h, PP, mat(R06[i]), vec(p[i]), B)
        for b in range(8):
            for j in range(6):
                Q[i, b, j] = B[b, j]
            V[i, b], E[i, b] = B[b, EXISTS] != 0.0, B[b, EXACT] != 0.0
