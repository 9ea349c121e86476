"""IK-Geo's solver classes of 6R arms (A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse
kinematics using subproblem decomposition", arXiv 2211.05737, Table I), one module a class.

A class's module holds all of it (:class:`~anthroarm.ik.classes.base.GeoClass`): the condition
on the axes that admits it (read by :func:`anthroarm.ik.classify.classify`), the joints whose
axes meet (slid to their common point: :func:`anthroarm.ik.geometric.ik_geo_P`), its branch
labels and, for a closed class, the kernel that solves one pose (dispatched by
``solve_closed``, compiled into :func:`anthroarm.ik.geometric.pose_solutions` and the batch
calls); for a 1-D search class the kernels of its inner subproblem (dispatched by
``search_inner`` and ``search_assemble`` in the search of :mod:`anthroarm.ik.search`).

**Adding a closed class** is a module here defining ``CLASS`` (its ``solve`` kernel writes the 8
branches of one pose, :mod:`.branches`) and its name in :data:`ORDER`, at the rank where it is
tried: the classification, the plans, the branch labels and the compiled dispatch read the
registry (:data:`REGISTRY`), and ``anthroarm check`` runs on every arm of that class.
"""

from __future__ import annotations

from importlib import import_module

from ... import jit
from .base import CLOSED_FORM, QUARTIC, SEARCH_1D, SEARCH_2D, GeoClass, Relations

#: the classes, by the names of their modules here, in the order they are tried (the simplest
#: solution first; the first whose condition holds is the arm's class): one line a class
ORDER = (
    "spherical_two_parallel",
    "spherical_two_intersecting",
    "three_parallel_two_intersecting",
    "spherical",
    "three_parallel",
    "two_parallel",
    "two_intersecting",
    "gen_six_dof",
)

#: the :class:`GeoClass` of each name of :data:`ORDER`, in that order
REGISTRY: tuple[GeoClass, ...] = tuple(import_module(f"{__name__}.{m}").CLASS for m in ORDER)


def _named_as_modules(order, registry) -> None:
    for m, c in zip(order, registry):
        if c.name != m:
            raise ImportError(f"{__name__}.{m} defines the class {c.name!r}: name it as its module")


_named_as_modules(ORDER, REGISTRY)

#: name -> :class:`GeoClass`
BY_NAME: dict[str, GeoClass] = {c.name: c for c in REGISTRY}
#: the names of the classes solved in closed form (one kernel a pose), in :data:`ORDER`
CLOSED: tuple[str, ...] = tuple(c.name for c in REGISTRY if c.closed)
#: the names of the classes solved by a search
SEARCHED: tuple[str, ...] = tuple(c.name for c in REGISTRY if not c.closed)

#: the names of the classes solved by a 1-D search, then by the 2-D search: the index of a
#: class here is its index in the compiled search (:mod:`anthroarm.ik.search`)
SEARCHED_1D: tuple[str, ...] = tuple(c.name for c in REGISTRY if c.solution == SEARCH_1D)
SEARCHED_2D: tuple[str, ...] = tuple(c.name for c in REGISTRY if c.solution == SEARCH_2D)

#: ``solve_closed(k, h, P, R06, p, B)``: the ``solve`` kernel of the closed class ``CLOSED[k]``
#: (:func:`anthroarm.jit.switch` of the registry's kernels)
solve_closed = jit.switch(BY_NAME[n].solve for n in CLOSED)
#: ``search_inner(k, …)`` / ``search_assemble(k, …)``: the ``inner`` / ``assemble`` kernel of
#: the 1-D search class ``SEARCHED_1D[k]``
search_inner = jit.switch(BY_NAME[n].inner for n in SEARCHED_1D)
search_assemble = jit.switch(BY_NAME[n].assemble for n in SEARCHED_1D)


def get(name: str) -> GeoClass:
    """The class called ``name`` (``KeyError`` naming the classes for another)."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise KeyError(f"no IK-Geo class {name!r}; the classes are {', '.join(ORDER)}") from None


def holding(rel: Relations) -> list[str]:
    """The names of the classes whose condition holds for the relations ``rel``, in
    :data:`ORDER`."""
    return [c.name for c in REGISTRY if c.holds(rel)]


__all__ = [
    "BY_NAME",
    "CLOSED",
    "CLOSED_FORM",
    "GeoClass",
    "ORDER",
    "QUARTIC",
    "REGISTRY",
    "Relations",
    "SEARCHED",
    "SEARCHED_1D",
    "SEARCHED_2D",
    "SEARCH_1D",
    "SEARCH_2D",
    "get",
    "holding",
]
