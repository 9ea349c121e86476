"""The optimisers of book Ch. 4, written as the book writes them.

1-D: :func:`golden_section` (4-9)–(4-14) with :func:`golden_points_needed` (4-13);
:func:`quadratic_interpolation` with the corrected closed form (4-20) (:func:`quadratic_step`).
n-D: :func:`fletcher_reeves` (4-26)–(4-47), :func:`steepest_descent`, :func:`simplex_book`
(4-48)–(4-64).  Constrained: :func:`sumt_interior` (4-65)–(4-68), :func:`sumt_exterior`
(4-69)–(4-75), :func:`sumt_mixed` (4-76)–(4-78).  All return an :class:`OptimizeResult` whose
``status`` says what went wrong when something did.
"""

from .conjugate_gradient import fletcher_reeves, numerical_gradient, steepest_descent
from .golden import (
    GOLDEN,
    bracket_minimum,
    golden_points_needed,
    golden_section,
    unimodality_violation,
)
from .quadratic import (
    line_minimize,
    quadratic_coefficients,
    quadratic_interpolation,
    quadratic_step,
    quadratic_step_equal,
)
from .result import OptimizeResult
from .simplex import simplex_book
from .sumt import bounds_to_ineq, find_feasible, sumt_exterior, sumt_interior, sumt_mixed, violation

__all__ = [
    "GOLDEN",
    "OptimizeResult",
    "bounds_to_ineq",
    "bracket_minimum",
    "find_feasible",
    "fletcher_reeves",
    "golden_points_needed",
    "golden_section",
    "line_minimize",
    "numerical_gradient",
    "quadratic_coefficients",
    "quadratic_interpolation",
    "quadratic_step",
    "quadratic_step_equal",
    "simplex_book",
    "steepest_descent",
    "sumt_exterior",
    "sumt_interior",
    "sumt_mixed",
    "unimodality_violation",
    "violation",
]
