"""The book's printed closed forms of the catalog's arms, in one place.

Each form is defined beside the parameter table of its arm (:mod:`.book`, :mod:`.human`) and
declared by the arm's builder in ``spec.printed`` (:class:`~anthroarm.models.spec.PrintedForm`);
this index only gathers them.  ``anthroarm check`` finds them through the spec
(:func:`anthroarm.kinematics.book_fk.printed_forms`), never through an arm's name.

Forward kinematics (hand poses, Jacobians, the §6-6 length coefficients), vectorised over a batch
of configurations, corrected where recomputation proves a misprint (``docs/errata.md``):

* Fig. 6-3 6R arm, Eq. (6-16)/(6-17); the Unimate of Fig. 6-4, Eq. (6-21)–(6-23), which is the
  002 text's RRPRR arm, Eq. (4-52)–(4-54);
* the §6-3 human arm, Eq. (6-34)–(6-39) and (6-119);
* the planar 2R of Fig. 7-14, and the elbow, wrist and palm points of the Ch. 7 prosthetic arm,
  Eq. (7-16)/(7-17).

The closed-form *inverse* kinematics is :mod:`anthroarm.ik.closed_form`.
"""

from __future__ import annotations

from .book import (
    planar2r_tip,
    planar2r_tip_pose,
    prosthetic_arm_points,
    rrprr_hand_pose,
    sixr_hand_pose,
    unimate_hand_pose,
)
from .human import (
    human_arm7_hand_pose,
    human_arm7_jacobian,
    human_arm7_length_jacobian,
    human_arm7_points,
    human_arm7_rotations,
)
from .spec import PrintedForm

__all__ = [
    "PrintedForm",
    "sixr_hand_pose",
    "unimate_hand_pose",
    "rrprr_hand_pose",
    "human_arm7_rotations",
    "human_arm7_points",
    "human_arm7_hand_pose",
    "human_arm7_jacobian",
    "human_arm7_length_jacobian",
    "planar2r_tip",
    "planar2r_tip_pose",
    "prosthetic_arm_points",
]
