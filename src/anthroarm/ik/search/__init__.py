"""The search classes of the geometric IK, compiled: one Numba kernel call for a batch of poses.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, §IV (the 6-DOF solvers ``IK_2_parallel``,
``IK_2_intersecting``, ``IK_gen_6_dof``); the decompositions were read from the reference
implementation (github.com/rpiRobotics/ik-geo, ``matlab/+IK``); the code is our own, built on
the scalar subproblem kernels of :mod:`anthroarm.ik.subproblems` (``sp1_one``, ``sp5_one``,
``sp6_one``) and the tuple algebra of :mod:`anthroarm.ik.vec3`.

Conventions (IK-Geo): joint i turns about the unit axis ``H[i]`` (base frame, q = 0); ``P[0]``
is the base → joint 1 offset, ``P[i]`` joint i → joint i + 1, ``P[6]`` joint 6 → tool (m);
the pose is ``R06`` (the tool orientation with its value at q = 0 removed) and ``p`` the tool
position (base frame, m); angles in rad.

=====================  ============================================================  =========
class                  search (IK-Geo)                                               branches
=====================  ============================================================  =========
``two_parallel``       ``IK_2_parallel`` (h2 ∥ h3): 1-D over q1; (q4, q6) SP6,        ≤ 16
                       θ23 SP1, error ‖span‖ − ‖p23‖; at a root q2, q5 SP1
``two_intersecting``   ``IK_2_intersecting`` (p56 = 0): 1-D over q4; (q1, q2, q3)     ≤ 16
                       SP5, error h5ᵀ R04ᵀ R06 h6 − h5ᵀ h6; at a root q5, q6 SP1
``gen_six_dof``        ``IK_gen_6_dof``: 2-D over (q1, q2); (q3, q4, q5) SP5, error   ≤ 16
                       ‖R05 h6 − R06 h6‖; local minima polished by Newton; q6 SP1
=====================  ============================================================  =========

The 1-D search (per pose, in the kernel): the searched joint is sampled on :data:`SEARCH_GRID`
+ 1 values over [−π, π]; each root of the inner subproblem is followed to the next sample by
the nearest root there (a match closer than :data:`_MATCH` rad in every unknown); a sign change
of the error along a followed root is a bracket, refined by the Illinois variant of regula
falsi (the root followed by the one nearest its interpolation between the bracket's ends) until
``|e| ≤ SEARCH_TOL / 100`` or 60 steps; a refined root with ``|e| ≤`` :data:`SEARCH_TOL` whose
pose error (FK) is above :data:`_FK_TOL` gets a few Newton steps on the pose (|e| pins the
angle loosely where e is flat); it is ``exact`` where the pose is met to SEARCH_TOL.  A sample
interval where the number of roots changes (a fold: a pair of roots appears or vanishes there,
moving like a square root), a root moves by more than :data:`_FAST` rad, or two roots at an
end are closer than _FAST (a near fold: the error along them turns fast) is sampled again on
33 points crowded quadratically towards both ends, and its brackets come from that finer
sampling.  An interval of a finer look where the number of roots is the same at both ends
but a followed root still moves by more than :data:`_JUMP` (two folds of the inner
subproblem inside it — the root runs back on an arc between them, and a solution on that arc
is seen by no sample — or a root turning fast past a near singularity) is looked at again
the same way, down to :data:`_DEPTH` levels; where the number of roots changes inside a finer
look, a sign change is bracketed only between mutually nearest roots (a root vanishing at the
fold is nearest to another root beyond it, with no root between them).  A pair of roots
inside one sample interval (two IK solutions closer than it — near a singular pose, a few %
of random poses) is no sign change at the samples: at every *dip*
(|e| along a followed root smallest at a sample, of one sign there and at both neighbours, grid
or finer samples) low enough that a zero may hide next to it (|e| ≤ :data:`_DIP` × the steeper
secant slope × the wider gap), |e| is minimised along the root by safeguarded parabolic
interpolation until it changes sign (two brackets, refined as above), the bound proves no zero
can hide, or the bracket is narrower than :data:`_DIP_TOL` (a minimum within :data:`_TOUCH` of
zero — the error touching zero — seeds Newton on the pose).  Next to a fold of the finer
sampling, the roots with ``|e| <`` :data:`_SEED`, and the pair that meets at the fold where
their errors differ in sign, seed Newton steps on the whole arm's pose (a root on the arc
through a fold is a sign change along neither root), kept where they converge to
:data:`SEARCH_TOL`.

The 2-D search: (q1, q2) on a :data:`SEARCH_GRID_2D` ² periodic grid; every (sample, SP5 root)
whose error is below 0.3 and not above the best root of any of its 8 neighbours gives q6 by
SP1 and seeds 20 Newton steps on the pose; the converged ones (pose error ≤ SEARCH_TOL) are
kept.  A branch whose basin the grid misses is not found (no completeness claim).

Each pose gets up to :data:`SEARCH_BRANCHES` slots, filled in the order the branches are
found (the refined brackets along the grid, the dips of the grid, the brackets and dips of
finer samplings, each followed by those of its own finer looks, then the polished fold seeds);
a branch within 1e-8 rad (every joint, mod 2π) of an earlier one is dropped.

Layout: :mod:`.constants` (grid sizes, tolerances), :mod:`.polish` (Newton on the pose by the one
FK of :mod:`anthroarm.ik.fk`, the arm as :func:`geo_frames`; branch slots), :mod:`.brackets`
(sampling, following roots, regula falsi), :mod:`.dips` (pairs of roots inside one sample
interval), :mod:`.line` (the 1-D search of one pose), :mod:`.grid2d` (the 2-D search of
``gen_six_dof``), :mod:`.driver` (:func:`solve_search` over a batch).
The inner subproblems of the 1-D classes are their own kernels (``inner``, ``assemble``) in
their modules of :mod:`anthroarm.ik.classes`, called by class index through the registry's
``search_inner`` / ``search_assemble``.
"""

from __future__ import annotations

from .constants import CLASSES, SEARCH_BRANCHES, SEARCH_GRID, SEARCH_GRID_2D, SEARCH_TOL
from .driver import solve_search
from .polish import geo_frames, polish

__all__ = [
    "CLASSES",
    "SEARCH_BRANCHES",
    "SEARCH_GRID",
    "SEARCH_GRID_2D",
    "SEARCH_TOL",
    "geo_frames",
    "polish",
    "solve_search",
]
