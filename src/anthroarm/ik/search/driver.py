"""The compiled search over a batch of poses (:func:`solve_search`)."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..classes import SEARCHED_1D
from ..vec3 import rows6, rows7, vec
from .constants import CLASSES, SEARCH_BRANCHES, SEARCH_GRID, SEARCH_GRID_2D
from .grid2d import _gen_six_dof_pose
from .line import _search_1d_pose
from .polish import geo_frames

#: the classes before this index in :data:`CLASSES` are 1-D searches, the others the 2-D one
N_1D = len(SEARCHED_1D)


# ----------------------------------------------------------------------------- driver
@kernel
def _search_loop(cls, H, P, A, R06, p, Q, V, E, grid):
    h, PP = rows6(H), rows7(P)
    for i in range(len(p)):
        Q[i, :, :] = math.nan
        V[i, :] = False
        E[i, :] = False
        R, pp = (vec(R06[i, 0]), vec(R06[i, 1]), vec(R06[i, 2])), vec(p[i])
        if cls >= N_1D:
            _gen_six_dof_pose(h, PP, A, R, pp, Q[i], V[i], E[i], grid)
        else:
            _search_1d_pose(cls, h, PP, A, R, pp, Q[i], V[i], E[i], grid)


def solve_search(cls: str, H, P, R06, p, grid: int | None = None, frames=None):
    """Every branch of the search class ``cls`` (``"two_parallel"``, ``"two_intersecting"``
    or ``"gen_six_dof"``; IK-Geo ``IK_2_parallel``, ``IK_2_intersecting``, ``IK_gen_6_dof``,
    arXiv 2211.05737 §IV) for N poses, in one compiled call.

    ``H`` (6, 3) unit joint axes and ``P`` (7, 3) offsets (m) in IK-Geo's form (base frame,
    q = 0), ``R06`` (N, 3, 3) = R · R_tool(0)ᵀ, ``p`` (N, 3) the tool positions (base frame, m).
    Returns q (N, 16, 6) rad in (−π, π] (NaN where a slot holds no branch), valid (N, 16),
    exact (N, 16) (False: a refined root whose error stayed above :data:`SEARCH_TOL`, or a
    subproblem with only a least-squares answer).  ``grid``: samples of the searched joint
    (default :data:`SEARCH_GRID`; :data:`SEARCH_GRID_2D` per joint for ``gen_six_dof``).
    ``frames``: the arm as :func:`.polish.geo_frames` of H, P (made here if None: a plan keeps
    them, ``GeoPlan.search_frames``), the FK of the Newton polish.
    ``anthroarm.ik.geometric.solve_class`` calls this for these classes (module docstring)."""
    if cls not in CLASSES:
        raise ValueError(f"cls must be one of {CLASSES}, got {cls!r}")
    c = CLASSES.index(cls)
    H = np.ascontiguousarray(H, dtype=float).reshape(6, 3)
    P = np.ascontiguousarray(P, dtype=float).reshape(7, 3)
    R06 = np.ascontiguousarray(R06, dtype=float).reshape(-1, 3, 3)
    p = np.ascontiguousarray(p, dtype=float).reshape(-1, 3)
    if len(R06) != len(p):
        raise ValueError(f"R06 has {len(R06)} poses, p {len(p)}")
    if grid is None:
        grid = SEARCH_GRID_2D if c >= N_1D else SEARCH_GRID
    n = len(p)
    q = np.empty((n, SEARCH_BRANCHES, 6))
    valid = np.empty((n, SEARCH_BRANCHES), bool)
    exact = np.empty((n, SEARCH_BRANCHES), bool)
    A = geo_frames(H, P) if frames is None else np.ascontiguousarray(frames, dtype=float)
    _search_loop(c, H, P, A, R06, p, q, valid, exact, int(grid))
    return q, valid, exact & valid
