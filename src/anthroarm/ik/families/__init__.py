"""Closed-form IK of two arm families read from the chain's geometry, as compiled kernels.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, §III (the subproblems SP1–SP4 of :mod:`.subproblems`); the
redundant shoulder–elbow–wrist arm and its elbow swivel angle follow the book's §6-3 (and
Kreutz-Delgado, Long & Seraji, IJRR 11(5), 1992), with the swivel angle defined as in
:func:`anthroarm.ik.qp.tasks.swivel.swivel_angle`.  The code is our own, in the style of
:mod:`.geometric` (scalar kernels on tuples, :mod:`.vec3`, compiled by :mod:`anthroarm.jit`).

The arm is read from ``robot.chain`` (:func:`anthroarm.ik.classify.classify`), never from its
name.  Everything is in the **base frame** at q = 0, metres and radians: joint i turns about the
unit axis ``h_i`` through the point ``o_i``; the tool pose at q = 0 is (R_t, p_t).

``srs_7r`` — 7R arm, spherical shoulder (axes 1, 2, 3 meet at S), elbow joint 4, spherical
wrist (axes 5, 6, 7 meet at W), one solution family per elbow swivel angle φ:

* wrist centre W(T) = R R_tᵀ (W0 − p_t) + p (joints 5–7 do not move W0);
* q4 by SP3: ‖rot(h4, q4)(W0 − E0) − (S − E0)‖ = ‖W − S‖ (2 roots), E0 the elbow point on
  axis 4 (the elbow frame of :func:`~anthroarm.ik.qp.tasks.swivel.swivel_frames`);
* the elbow E on its circle about n = (W − S)/‖W − S‖ (the triangle S, E, W has sides
  a = ‖E0 − S‖, b = ‖W0 − E0‖, L = ‖W − S‖): E = S + c n + r (cos φ u + sin φ v),
  c = (a² − b² + L²)/(2L), r = √(a² − c²), (u, v) of
  :func:`~anthroarm.ik.qp.tasks.swivel.swivel_basis` (u: −z projected ⊥ n, fallback −y; v = n × u);
* the shoulder R03 maps E0 − S onto E − S and f = rot(h4, q4)(W0 − E0) onto W − E (a straight
  elbow, r = 0: h4 onto the elbow axis a_E with d = n × a_E, the swivel angle's convention).
  When axis 3 lies along the upper arm at q = 0 (route ``"sp2"``): (q1, q2) by SP2,
  rot(−h1, q1)(E − S) = rot(h2, q2)(E0 − S) (2 roots), q3 by SP1.  Otherwise (route
  ``"general"``) R03 is the rotation taking the pair to the pair and (q1, q2, q3) follow as a
  spherical wrist does: q2 by SP4, q1 and q3 by SP1 (2 roots);
* the wrist from R47 = R04ᵀ R R_tᵀ as :func:`anthroarm.ik.classes.branches.wrist`: q6 by
  SP4, q5 and q7 by SP1 (2 roots).

8 branches per φ, q4 root outermost, wrist root innermost: labels ``"q4=0,q1q2=0,q6=0"`` …
(``q2`` in place of ``q1q2`` for the general shoulder route), see ``SRSPlan.labels``.

``planar_2r`` — two parallel revolute axes, position only: q2 by SP3
(‖rot(h2, q2)(p_t − o2) − (o1 − o2)‖ = ‖p − o1‖), q1 by SP1; 2 branches ``"q2=0"``, ``"q2=1"``.
A target off the plane of motion (|h1ᵀ(p − p_t)| > tol) has no candidate.

Drivers (:func:`srs_verified`, :func:`planar_verified`) follow
:func:`anthroarm.ik.geometric.solve_verified`: one compiled call per batch, each branch wrapped
by 2π into the joint limits and checked by the chain's FK (product of exponentials of the
joints as read from ``robot.chain``, unsnapped; :func:`.fk.local_frames`), joint values
in ``robot.chain.independent`` order.  A branch whose subproblems had only least-squares answers is a candidate with
``exact = False`` (out of reach on that branch).

Layout: :mod:`.plans` (the plans read from the chain), :mod:`.srs` (the SRS kernels and
drivers), :mod:`.planar` (the planar 2R kernels and driver).
"""

from __future__ import annotations

from .planar import planar_pose_solutions, planar_verified
from .plans import (
    PLANAR_BRANCHES,
    PLANAR_LABELS,
    SRS_BRANCHES,
    SRS_ROUTES,
    PlanarPlan,
    SRSPlan,
    planar_plan,
    planar_reason,
    srs_branch_labels,
    srs_plan,
    srs_reason,
)
from .srs import srs_nearest, srs_points, srs_pose_solutions, srs_solutions, srs_verified

__all__ = [
    "PLANAR_BRANCHES",
    "PLANAR_LABELS",
    "PlanarPlan",
    "SRSPlan",
    "SRS_BRANCHES",
    "SRS_ROUTES",
    "planar_plan",
    "planar_reason",
    "planar_verified",
    "srs_branch_labels",
    "srs_plan",
    "srs_points",
    "srs_reason",
    "srs_verified",
]
