"""``gen_six_dof``: any 6R arm.  A 2-D search over (q1, q2) (:mod:`anthroarm.ik.search`): at
each sample, (q3, q4, q5) by SP5, the error ‖R05 h6 − R06 h6‖; the grid's local minima polished
by Newton steps on the whole pose, q6 by SP1; ≤ 16 branches, no completeness claim.  IK-Geo
``IK_gen_6_dof`` (arXiv 2211.05737, Table I)."""

from __future__ import annotations

from .base import SEARCH_2D, GeoClass

CLASS = GeoClass("gen_six_dof", "none of the above", lambda r: True, SEARCH_2D, searched="q1q2")
