"""What an IK-Geo class is (:class:`GeoClass`): its name, the condition on the arm's axes that
admits it (a rule on :class:`Relations`), the joints whose axes meet (slid to their common
point: IK-Geo's offsets), its branches and the kernel that solves one pose — all in the one
module of the class, registered by one line in :data:`anthroarm.ik.classes.ORDER`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

#: the solutions a class gives
CLOSED_FORM, QUARTIC, SEARCH_1D, SEARCH_2D = "closed form", "quartic", "1-D search", "2-D search"


class Relations(NamedTuple):
    """The relations of consecutive axes of a 6R arm (0-based joint positions along the path,
    :func:`anthroarm.ik.classify.classify`): ``parallel[i]`` / ``intersecting[i]`` of the pair
    (i, i+1), ``spherical[i]`` / ``three_parallel[i]`` of the triple (i, i+1, i+2)."""

    parallel: np.ndarray
    intersecting: np.ndarray
    spherical: np.ndarray
    three_parallel: np.ndarray


@dataclass(frozen=True)
class GeoClass:
    """One IK-Geo solver class (Elias & Wen, arXiv 2211.05737, Table I).

    ``name``: its name; ``condition``: the condition on the axes in words (1-based joints, as
    in the paper); ``holds``: that condition on the :class:`Relations` of an arm; ``solution``:
    :data:`CLOSED_FORM`, :data:`QUARTIC`, :data:`SEARCH_1D` or :data:`SEARCH_2D`; ``meets``:
    the groups of joints (0-based) whose axes pass through one point, slid there along their
    axes (:func:`anthroarm.ik.geometric.ik_geo_P`); ``labels``: a closed class's branching
    subproblems, outermost first, as (unknowns, number of roots); ``searched``: a search
    class's searched joints (``"q1"``); ``solve``: a closed class's kernel
    ``solve(h, P, R06, p, B)`` writing the 8 branches of one pose into the rows of ``B``
    (:mod:`anthroarm.ik.classes.branches`), None for a search class; a 1-D search class's
    kernels (the search itself is :mod:`anthroarm.ik.search`'s): ``inner(h, P, R06, p16, x,
    th, e, t2)`` the roots of its inner subproblem at the searched angle ``x`` into ``th``
    (4, 3) and their errors into ``e`` (4,), returning their number, and ``assemble(h, P, R06,
    p16, x, r0, r1, r2, q)`` the branch at a root into ``q`` (6,), returning whether it is
    exact.  The 2-D search's inner subproblem is the search's own
    (:mod:`anthroarm.ik.search.grid2d`)."""

    name: str
    condition: str
    holds: Callable[[Relations], bool]
    solution: str
    meets: tuple = ()
    labels: tuple = ()
    searched: str = ""
    solve: object = None
    inner: object = None
    assemble: object = None

    def __post_init__(self):
        if (self.solve is None) == (self.solution in (CLOSED_FORM, QUARTIC)):
            raise ValueError(f"{self.name}: a {self.solution} class has a solve kernel iff closed")
        if (self.inner is None or self.assemble is None) == (self.solution == SEARCH_1D):
            raise ValueError(f"{self.name}: a 1-D search class has inner and assemble kernels")
        if self.solve is not None and int(np.prod([k for _, k in self.labels])) != 8:
            raise ValueError(f"{self.name}: the labels of a closed class make 8 branches")

    @property
    def closed(self) -> bool:
        """Solved in closed form (a kernel per pose), not by a search."""
        return self.solve is not None

    def branch_labels(self, slots: int) -> tuple[str, ...]:
        """The labels of the class's branch slots: which root of each branching subproblem
        (``"q1=0,q3=1,q5=0"``: the first root for q1, the second for q3, …) for a closed class;
        for a search class which root of the search along the searched joints, in the order
        found (``"q1root=2"``; ``slots`` of them, filled from the first)."""
        if not self.closed:
            return tuple(f"{self.searched}root={k}" for k in range(slots))
        out = [""]
        for name, k in self.labels:
            out = [f"{o},{name}={i}".lstrip(",") for o in out for i in range(k)]
        return tuple(out)
