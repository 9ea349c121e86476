"""Closed-form IK of any 6R arm whose geometry allows it, by IK-Geo's solver classes.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, §IV (the 6-DOF solvers); the decompositions were read from
the reference implementation (github.com/rpiRobotics/ik-geo, ``matlab/+IK``); the code is our
own, batched over N poses, built on the subproblems of :mod:`anthroarm.ik.subproblems`.

The arm is read from ``robot.chain`` (:func:`anthroarm.ik.classify.classify`), never from its
name.  Conventions (IK-Geo): joint i turns about the unit axis ``h_i`` (base frame, q = 0);
``P[0]`` is the base → joint 1 offset, ``P[i]`` joint i → joint i+1, ``P[6]`` joint 6 → tool
(m); the tool orientation at q = 0 is removed first, ``R06 = R · R_tool(0)ᵀ``.  Joints may slide
along their own axes without changing the kinematics, which makes the offsets between
intersecting axes zero (the form each solver needs: :func:`ik_geo_P`).

Each class is a module of :mod:`anthroarm.ik.classes` (its condition, its decomposition into
subproblems in its docstring, its branches and, for a closed class, its kernel).

The search classes (IK-Geo ``IK_2_parallel``, ``IK_2_intersecting``; compiled in
:mod:`.search`, whose docstring has the details) sample the searched joint on
:data:`SEARCH_GRID` values, follow each root of the inner subproblem from sample to sample,
refine every sign change of the error by regula falsi (Illinois) to ``|e| ≤``
:data:`SEARCH_TOL`, minimise the dips of ``|e|`` between samples (a pair of roots closer than a
sample interval), look again more finely where roots fold or jump, and polish the roots next
to a fold by Newton steps on the whole arm's pose; ~1–3 ms a pose.  A root that lives inside
one grid interval with no root of the inner subproblem at either end is not found (4 of 9 600
random reachable poses of 96 random arms).

``gen_six_dof`` (IK-Geo ``IK_gen_6_dof``) samples (q1, q2) on a :data:`SEARCH_GRID_2D` ²
grid; every (sample, SP5 root) whose error ``‖R05 h6 − R06 h6‖`` is below 0.3 and not above
any of its 8 neighbours' seeds Newton steps on the whole pose (kept where they converge to
:data:`SEARCH_TOL`).  A branch whose basin the grid misses is not found (no completeness
claim), and it costs tens of ms a pose; a 7-joint arm is not solved this way.

A class that holds for the reversed chain (a spherical *shoulder*: the prosthetic arm) is
solved on the reversed arm: T = e^{ξ1 q1} ⋯ e^{ξ6 q6} M gives T⁻¹ = e^{ξ'1 q6} ⋯ e^{ξ'6 q1} M⁻¹
with ξ'_k the twist of joint 7 − k seen from the tool at q = 0 and its axis negated
(``h'_k = −R_toolᵀ h_{7−k}`` through ``R_toolᵀ (o_{7−k} − p_tool)``), the same angles.

Every branch returned by :func:`solve` is a candidate: its ``exact`` flag is False where a
subproblem had only a least-squares answer (the pose is out of reach on that branch).  The
closed classes (:data:`CLOSED`) are compiled per pose (:mod:`anthroarm.jit`) from the
subproblem kernels, and :func:`solve_verified` / :func:`solve_nearest` add in the same compiled
call the 2π shift into the joint limits, the FK check by the chain's product of exponentials
(in joint-local frames, :func:`anthroarm.ik.fk.local_frames`) and the removal of duplicates (used by
:func:`anthroarm.ik.closed_form.analytic`).

Layout (one concern a module): :mod:`.plan` (the plan of an arm: its class, its kinematics in
IK-Geo's form, the constants packed for the compiled calls), :mod:`.closed` (one pose of a closed
class: the class's kernel from :mod:`anthroarm.ik.classes`, then its angles), :mod:`.limits` (angles shifted by 2π into the joint limits), :mod:`.fk` (the FK
check: residuals of the branches, the Newton polish, on the one FK of :mod:`anthroarm.ik.fk`), :mod:`.verify` (one compiled call: pose →
verified branches), :mod:`.singular` (Jacobian volumes), :mod:`.drivers` (the entries over a
batch of poses), :mod:`.check` (``anthroarm check``); the searches are :mod:`anthroarm.ik.search`.
The names below are re-exported from there (what :mod:`anthroarm.ik.closed_form`, the tests
and the benchmarks read as ``geometric.NAME``).
"""

from __future__ import annotations

from .. import classify as C
from .. import subproblems as sp
from ..search import SEARCH_BRANCHES, SEARCH_GRID, SEARCH_GRID_2D, SEARCH_TOL, solve_search
from ..vec3 import mat, rows6, rows7, vec, wrap
from .check import check_rows
from .closed import BRANCH_ROW, CLOSED, COS, EXISTS, SIN, _solve_closed
from .drivers import class_pose, solve, solve_class, solve_nearest, solve_verified
from .fk import POLISH_MAX, _target_errors
from .limits import into_limit_cs, wrap_into_limits
from .plan import (
    SEARCHED,
    SOLVED,
    GeoPlan,
    _unpack,
    branch_labels,
    classification,
    ik_geo_P,
    n_branches,
    plan_for,
)
from .singular import SINGULAR_TOL, jacobian_volumes
from .verify import NO_REF, BadPoseError, blank_unsolved, mark_solutions, pose_solutions

__all__ = [
    "CLOSED",
    "GeoPlan",
    "solve_nearest",
    "solve_verified",
    "SEARCHED",
    "SOLVED",
    "branch_labels",
    "n_branches",
    "check_rows",
    "class_pose",
    "ik_geo_P",
    "plan_for",
    "solve",
    "solve_class",
]
