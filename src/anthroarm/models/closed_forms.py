"""Which catalog arms have a procedure of the book's own for their inverse kinematics.

The closed-form IK of every arm is found from its geometry (:mod:`anthroarm.ik.closed_form`:
IK-Geo classes, SRS arms by swivel angle, planar 2R), never from its name.  What stays arm
knowledge is which arm the book solves by a procedure of its own, kept beside the general
solution as ``aa.ik.analytic(robot, T, method="book")``:

``prosthetic_arm``
    Fig. 7-2 / Table 7.1, Eqs. (7-17)–(7-31) with Cramer's rule for the elbow (7-20)/(7-21):
    :func:`anthroarm.ik.closed_form.prosthetic_book_procedure`, the numbers of Table 7.2.
"""

from __future__ import annotations

#: catalog arms with a procedure of the book's own besides the general closed form
BOOK_PROCEDURES = ("prosthetic_arm",)

__all__ = ["BOOK_PROCEDURES"]
