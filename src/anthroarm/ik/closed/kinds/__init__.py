"""The kinds of closed form, listed once (:data:`KINDS`): the one table
:mod:`anthroarm.ik.closed_form` reads to find the closed form of an arm (the first kind, in
this order, whose :meth:`~.base.ClosedFormKind.plan` of ``robot.chain`` is not None) and to
solve its poses.  Each kind implements :class:`~.base.ClosedFormKind` in a module of its own.

Adding a kind: a module here with a subclass of :class:`~.base.ClosedFormKind` (its plan, its
:class:`~.base.ClosedForm`, its batch solver, and what it offers beyond: a one-pose call, a held
joint, nearest seeds), and its line in :data:`KINDS`.
"""

from __future__ import annotations

from .base import ClosedForm, ClosedFormKind, OneCall
from .geo_closed import GeoClosed
from .geo_search import GeoSearch, GeoSearch2D
from .planar import PLANAR, Planar2R
from .srs import SRS, SRS7R

#: every kind of closed form, in the order an arm is tried
KINDS: tuple[ClosedFormKind, ...] = (
    Planar2R(),
    SRS7R(),
    GeoClosed(),
    GeoSearch(),
    GeoSearch2D(),
)

__all__ = ["KINDS", "PLANAR", "SRS", "ClosedForm", "ClosedFormKind", "OneCall"]
