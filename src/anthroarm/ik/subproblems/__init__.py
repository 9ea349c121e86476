"""The six canonical geometric subproblems of IK-Geo, batched.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", *Mechanism and Machine Theory* 209 (2025), arXiv 2211.05737 (cited below as
"IK-Geo"; equation numbers are those of the arXiv version, §III "Subproblem solutions").  The
formulation was read from the authors' reference implementation (github.com/rpiRobotics/ik-geo,
``matlab/+subproblem``); the code here is our own.

Notation (IK-Geo §II): ``rot(k, θ)`` is the rotation by θ (rad) about the unit axis ``k``
(Rodrigues, Eq. (1)); every vector is expressed in one common frame (any frame; the base frame
when the subproblems are used for IK) and lengths are in the caller's unit (metres here).
For a unit axis k and a vector p, Eq. (2) writes the rotated vector as an affine function of
x = (sin θ, cos θ)::

    rot(k, θ) p = k kᵀp + A x,    A = [k × p,  −k × (k × p)]      (3×2)

which turns every subproblem into the intersection of lines, circles and ellipses in x.

=====  ==================================  =================================  ==========
 SP    solves                              closed form (IK-Geo)               solutions
=====  ==================================  =================================  ==========
 1     rot(k, θ) p1 = p2                   Eq. (3): θ = atan2 of Aᵀp2         1
 2     rot(k1, θ1) p1 = rot(k2, θ2) p2     two SP4 + SP1, §III-B              ≤ 2
 3     ‖rot(k, θ) p1 − p2‖ = d             as SP4, §III-C                     ≤ 2
 4     hᵀ rot(k, θ) p = d                  Eqs. (4)–(6), §III-D               ≤ 2
 5     p0 + rot(k1,θ1) p1 =                quartic, §III-E                    ≤ 4
       rot(k2,θ2)(p2 + rot(k3,θ3) p3)
 6     Σ hᵢᵀ rot(kᵢ, θ·) pᵢ = d (2 eqs.)    two ellipses, quartic, §III-F      ≤ 4
=====  ==================================  =================================  ==========

Every function accepts one problem (vectors of shape ``(3,)``, scalars) or ``N`` problems
(leading axis: ``(N, 3)``, ``(N,)``; single problems broadcast against a batch) and returns a
:class:`Solutions`.  SP1–SP4 return a *least-squares* solution, flagged ``exact = False``,
where there is no exact one (IK-Geo's ``is_LS``); SP5 and SP6 return only exact solutions (the
paper gives no least-squares form for them), so a problem without a solution has
``count == 0``.  A problem that is ill-posed (infinitely many solutions, e.g. p parallel to k)
is marked ``singular`` and one representative is returned (θ = 0 where θ is free).

Bad input (wrong shapes, non-finite numbers, an axis that is not a unit vector) raises
:class:`~anthroarm.errors.ParameterError`.

Implementation: each subproblem is one scalar kernel (``sp1_one`` … ``sp6_one``, vectors as
tuples, :mod:`.vec3`) compiled by Numba (:mod:`anthroarm.jit`); the public functions check
their input and run the kernel over the batch in a compiled loop.  The closed-form IK of
:mod:`.geometric` calls the same kernels, so every formula exists once.

Layout: :mod:`.base` (:class:`Solutions`, input checks, :func:`rot`, :func:`unit_cs`),
:mod:`.circle` (SP1–SP4), :mod:`.roots` (real roots of the quartics), :mod:`.quartic` (SP5,
SP6).
"""

from __future__ import annotations

from .base import TOL, TOL_QUARTIC, Solutions, rot, unit_cs
from .circle import (
    sp1,
    sp1_cs,
    sp1_one,
    sp2,
    sp2_cs,
    sp2_one,
    sp3,
    sp3_cs,
    sp3_one,
    sp4,
    sp4_cs,
    sp4_one,
)
from .quartic import sp5, sp5_one, sp6, sp6_one
from .roots import real_roots

__all__ = [
    "Solutions",
    "rot",
    "sp1",
    "sp2",
    "sp3",
    "sp4",
    "sp5",
    "sp6",
    "sp1_one",
    "sp2_one",
    "sp3_one",
    "sp4_one",
    "sp5_one",
    "sp6_one",
    "unit_cs",
    "sp1_cs",
    "sp2_cs",
    "sp3_cs",
    "sp4_cs",
    "real_roots",
    "TOL",
    "TOL_QUARTIC",
]
