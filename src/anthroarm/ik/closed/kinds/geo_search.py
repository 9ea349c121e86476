"""The IK-Geo classes solved by a search (:data:`anthroarm.ik.geometric.SEARCHED`,
:mod:`anthroarm.ik.search`): ``two_parallel`` and ``two_intersecting`` by a 1-D search over one
joint angle (the zeros of a scalar error e(q) of the inner subproblems, refined by regula falsi
to |e| ≤ :data:`~anthroarm.ik.search.SEARCH_TOL`; ~1–3 ms a pose), ``gen_six_dof`` by a 2-D
search over (q1, q2) with Newton steps from the grid's local minima (tens of ms a pose).  Up to
:data:`~anthroarm.ik.search.SEARCH_BRANCHES` roots a pose; each is shifted by 2π into the
joint limits and checked by the robot's FK (max |FK(q) − T| ≤ ``tol`` over the 3×4 entries).
"""

from __future__ import annotations

import numpy as np

from ... import geometric as _geo
from ...classes import SEARCHED_1D, SEARCHED_2D
from ..finish import fk_residual
from .geo import GeoKind


class GeoSearch(GeoKind):
    """A 6R arm of an IK-Geo class solved by a 1-D search."""

    name = "ik_geo_search"
    classes = SEARCHED_1D
    cost_us = 2e3

    def branches(self, robot, gp, Ts, Tr, prm, shape, single, tol, tol_orthonormal):
        th, cand, exact = (a.reshape(shape + a.shape[2:]) for a in _geo.solve(gp, Tr, prm))
        th, inside = _geo.wrap_into_limits(th, gp.lower, gp.upper)
        cand = cand & np.isfinite(th).all(-1)
        Q = gp.chain.configuration(np.where(cand[..., None], th, 0.0))
        res = np.where(cand, fk_residual(robot, Q, Ts, False), np.inf)
        return th, None, cand, exact, inside, res, None


class GeoSearch2D(GeoSearch):
    """A general 6R arm (``gen_six_dof``) solved by a 2-D search."""

    name = "ik_geo_search_2d"
    classes = SEARCHED_2D
    cost_us = 3e5
