"""The inner subproblems of the 1-D search classes: ``_inner(cls, h, PP, R06, p16, x, th, e,
t2)`` writes the roots of class ``cls``'s inner subproblem at the searched angle ``x`` into
``th`` (4, 3) and their errors into ``e`` (4,) and returns their number (valid rows first);
``_assemble(cls, h, PP, R06, p16, x, r0, r1, r2, q)`` writes the branch at a root into ``q``
(6,) and returns whether every subproblem on it was exact.  ``cls`` is the class's index in
:data:`anthroarm.ik.classes.SEARCHED_1D`; the kernels are the class's own (its module in
:mod:`anthroarm.ik.classes`: ``two_parallel``, SP6 in (q6, q4); ``two_intersecting``, SP5 in
(q1, q2, q3))."""

from __future__ import annotations

from ..classes import search_assemble as _assemble
from ..classes import search_inner as _inner

__all__ = ["_assemble", "_inner"]
