"""The sampling, tolerances and limits of the compiled searches (:mod:`anthroarm.ik.search`)."""

from __future__ import annotations

from ..classes import SEARCHED_1D, SEARCHED_2D

#: samples of the searched joint over [−π, π] (IK-Geo's reference implementation uses 200)
SEARCH_GRID = 256
#: samples of each searched joint of ``gen_six_dof`` (a grid of its square)
SEARCH_GRID_2D = 64
#: most branches a search class returns per pose (a 6R arm has at most 16 solutions)
SEARCH_BRANCHES = 16
#: |e| at which a refined root counts as exact (the error functions are in m or unitless)
SEARCH_TOL = 1e-12
#: two roots of the inner subproblem at neighbouring samples are the same branch when their
#: angles differ by less than this (rad); a branch that appears or vanishes there is not followed
_MATCH = 0.5
#: a sample interval where a root moves by more than this (rad) is sampled again more finely
_FAST = 0.2
#: a root next to a fold with |e| below this seeds a Newton polish of the whole arm
_SEED = 0.05
#: an interval of a finer look (≤ 1/16 of a sample interval wide) where a followed root moves by
#: more than this (rad) with the number of roots unchanged is looked at again the same way (a
#: rate ≥ 8× that of _FAST over a sample interval: roots the finer samples do not resolve)
_JUMP = 0.1
#: levels of finer looks (interval widths ≤ 1.5e-3, 9e-5, 5e-6 rad at levels 1-3)
_DEPTH = 3
#: points per half of a finer sampling (2 · _SUB + 1 in all) and regula-falsi steps at most
_SUB = 16
_ITERS = 60
#: Newton steps on the pose for a fold seed of a 1-D search and for a 2-D local minimum
_POLISH_1D = 12
_POLISH_2D = 20
#: Newton steps on the pose for a refined root whose error stayed above SEARCH_TOL or whose
#: pose error is above _FK_TOL
_POLISH_ROOT = 3
#: pose error (max entry of |R − R06| and |o − p|, m) above which a refined root is polished
_FK_TOL = 1e-11
#: error below which a local minimum of the 2-D grid seeds Newton
_MIN_2D = 0.3
#: most fold seeds kept per pose (more are ignored; a fold has at most a few roots)
_MAX_SEEDS = 256
#: a dip of the error along a followed root (|e| smallest at a sample, of one sign at it and
#: both neighbours) is searched for a sign change where |e| there is at most this times the
#: steeper secant slope to a neighbour times the wider gap (``_low``; 2: a safety factor over
#: a V, for a slope that steepens towards the dip)
_DIP = 2.0
#: steps of the minimisation of |e| in a dip, and the bracket width (rad) where it stops
_DIP_ITERS = 40
_DIP_TOL = 1e-10
#: a dip whose minimum stays above zero but within this of it (|e|) seeds a Newton polish
_TOUCH = 1e-9

#: the classes solved here, by their index in the compiled kernel: the 1-D search classes of
#: the registry (:mod:`anthroarm.ik.classes`), then the 2-D search class
CLASSES = SEARCHED_1D + SEARCHED_2D
