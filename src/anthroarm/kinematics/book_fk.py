"""Which of the book's printed closed forms apply to a robot.

The forms themselves are arm knowledge and live with the arms' parameter tables in
:mod:`anthroarm.models` (gathered in :mod:`anthroarm.models.printed`); each catalog builder
declares its arm's forms in ``spec.printed``.  :func:`printed_forms` reads them from the spec
of a robot that is a book model as generated (``anthroarm check`` compares them with Pinocchio).
The forms stay importable from here under their old names.  The closed-form *inverse*
kinematics is :mod:`anthroarm.ik.closed_form`.
"""

from __future__ import annotations

from ..models import printed as _printed
from ..models.printed import *  # noqa: F403 - the forms' old home: their names stay importable
from ..models.spec import PrintedForm


def book_spec(robot):
    """The parameter table of ``robot`` when it is a book model as generated (any parameters),
    with its own tool frame and every joint (the chain the closed forms describe); else None."""
    spec = getattr(robot, "spec", None)
    if spec is None or robot.tool != spec.tool_name or robot.locked or robot.nq != spec.nq:
        return None
    return spec


def printed_forms(robot) -> tuple[PrintedForm, ...]:
    """The printed forms that apply to ``robot`` (see :func:`book_spec`): those its spec
    declares (``spec.printed``); call them with ``book_spec(robot).params``."""
    spec = book_spec(robot)
    return tuple(spec.printed) if spec is not None else ()


__all__ = [*_printed.__all__, "book_spec", "printed_forms"]
