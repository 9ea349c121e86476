"""SP1–SP4 (IK-Geo §III-A–D): a rotation onto a point, two rotations onto each other, a
distance and a height — each the intersection of a circle with a line or a circle, ≤ 2
solutions."""

from __future__ import annotations

import math

import numpy as np

from ...errors import ParameterError
from ...jit import kernel
from ..vec3 import atan2, cross, dot, norm, rotate_cs, scale, sub, vec
from .base import TOL, Solutions, _finish, _inputs, _tol, unit_cs


# ----------------------------------------------------------------------------- SP1, SP4
@kernel
def sp1_cs(p1, p2, k, tol):
    """SP1 of one problem (tuples): (cos θ, sin θ, exact, singular) (:func:`unit_cs`); see
    :func:`sp1`."""
    kxp = cross(k, p1)
    x0 = dot(kxp, p2)
    x1 = -dot(cross(k, kxp), p2)  # x = Aᵀ p2, A = [k × p1, −k × (k × p1)]
    n1, n2 = norm(p1), norm(p2)
    sing = norm(kxp) <= 1e-12 * max(1.0, n1) or norm(cross(k, p2)) <= 1e-12 * max(1.0, n2)
    c, s = (1.0, 0.0) if sing else unit_cs(x0, x1)
    exact = abs(n1 - n2) <= tol and abs(dot(k, p1) - dot(k, p2)) <= tol
    return c, s, exact, sing


@kernel
def sp1_one(p1, p2, k, tol):
    """SP1 of one problem (tuples): (θ, exact, singular); see :func:`sp1` (:func:`sp1_cs`)."""
    c, s, exact, sing = sp1_cs(p1, p2, k, tol)
    return atan2(s, c), exact, sing


@kernel
def sp4_one(h, p, k, d, tol):
    """SP4 of one problem (tuples; h unit): (θ_a, θ_b, count, exact_a, exact_b, singular), θ_b
    NaN when count = 1; IK-Geo Eqs. (4)–(6), see :func:`sp4` (:func:`sp4_cs`)."""
    ca, sa, cb, sb, cnt, ea, eb, sing = sp4_cs(h, p, k, d, tol)
    return atan2(sa, ca), atan2(sb, cb), cnt, ea, eb, sing


@kernel
def sp4_cs(h, p, k, d, tol):
    """SP4 of one problem (tuples; h unit): (cos θ_a, sin θ_a, cos θ_b, sin θ_b, count,
    exact_a, exact_b, singular) (:func:`unit_cs`), the b root NaN when count = 1; IK-Geo
    Eqs. (4)–(6), see :func:`sp4`."""
    kxp = cross(k, p)
    a0 = dot(h, kxp)
    a1 = -dot(h, cross(k, kxp))  # hᵀA
    b = d - dot(h, k) * dot(k, p)
    na = math.sqrt(a0 * a0 + a1 * a1)
    ab = abs(b)
    margin = na - ab  # > 0: two roots; residual of the LS root
    sing = na <= 1e-12 * max(1.0, norm(p))
    # two roots wherever the plane cuts the circle (as IK-Geo's sp_4): a near-tangent pair is
    # kept as two roots, not merged into one whose error grows like √margin in the angle
    two = margin > 0.0
    xi = math.sqrt(max(na * na - b * b, 0.0))
    if sing:
        return 1.0, 0.0, math.nan, math.nan, 1, ab <= tol or two, False, True
    if two:
        ca, sa = unit_cs(a0 * b + xi * a1, a1 * b - xi * a0)
        cb, sb = unit_cs(a0 * b - xi * a1, a1 * b + xi * a0)
        return ca, sa, cb, sb, 2, True, True, False
    # one root (tangent or least squares): the direction of Aᵀb
    ca, sa = unit_cs(a0 * b, a1 * b)
    return ca, sa, math.nan, math.nan, 1, margin >= -tol, False, False


@kernel
def _sp1_loop(p1, p2, k, tol, theta, exact, sing):
    for i in range(len(p1)):
        theta[i], exact[i], sing[i] = sp1_one(vec(p1[i]), vec(p2[i]), vec(k[i]), tol)


@kernel
def _sp4_loop(h, p, k, d, tol, theta, count, exact, sing):
    for i in range(len(h)):
        theta[i, 0], theta[i, 1], count[i], exact[i, 0], exact[i, 1], sing[i] = sp4_one(
            vec(h[i]), vec(p[i]), vec(k[i]), d[i], tol
        )


def sp1(p1, p2, k, tol: float = TOL) -> Solutions:
    """Subproblem 1, circle and point: θ with rot(k, θ) p1 = p2.

    IK-Geo Eq. (3) (§III-A): with A = [k × p1, −k × (k × p1)] (Eq. (2)),
    θ = atan2(x₁, x₂) where x = Aᵀ p2.  This is also the least-squares solution
    (min over θ of ‖rot(k, θ) p1 − p2‖) when ‖p1‖ ≠ ‖p2‖ or kᵀp1 ≠ kᵀp2; it is flagged
    ``exact = False`` when either differs by more than ``tol`` (length unit).  ``singular``:
    p1 or p2 parallel to k (every θ is equally good; θ = 0 returned).

    ``p1``, ``p2``: ``(3,)`` or ``(N, 3)``; ``k``: unit axis.  One solution (m = 1, S = 1)."""
    tol = _tol(tol)
    (p1, p2, k), batched = _inputs({"p1": (p1, "vec"), "p2": (p2, "vec"), "k": (k, "axis")})
    n = len(p1)
    theta, exact, sing = np.empty(n), np.empty(n, bool), np.empty(n, bool)
    _sp1_loop(p1, p2, k, tol, theta, exact, sing)
    return _finish(theta[:, None, None], np.ones((n, 1), bool), exact[:, None], sing, batched)


def _two_roots(theta, count, exact, sing, batched) -> Solutions:
    valid = np.arange(2)[None, :] < count[:, None]
    return _finish(theta[..., None], valid, exact, sing, batched)


def sp4(h, p, k, d, tol: float = TOL) -> Solutions:
    """Subproblem 4, circle and plane: θ with hᵀ rot(k, θ) p = d ("rotate p to height d
    along h").

    IK-Geo Eqs. (4)–(6) (§III-D): with A = hᵀ[k × p, −k × (k × p)] (1×2) and
    b = d − hᵀk kᵀp, solve A x = b on the unit circle x = (sin θ, cos θ)::

        x = (Aᵀ b ± √(‖A‖² − b²) · (A₂, −A₁)ᵀ) / ‖A‖²

    Two solutions when ``‖A‖ > abs(b)``; one (the tangent point, exact) when
    ``0 ≥ ‖A‖ − abs(b) ≥ −tol``; otherwise one least-squares solution θ = atan2 of Aᵀb, which
    minimises ``abs(hᵀ rot(k, θ) p − d)`` (``exact = False``).  ``singular``: h or p parallel to k
    (the height does not depend on θ; θ = 0 returned, exact when ``abs(b) ≤ tol``).

    ``h``, ``k``: unit ``(3,)``/``(N, 3)``; ``p``: ``(3,)``/``(N, 3)``; ``d``: scalar/``(N,)``
    (length unit).  m = 1, S = 2."""
    tol = _tol(tol)
    (h, p, k, d), batched = _inputs(
        {"h": (h, "axis"), "p": (p, "vec"), "k": (k, "axis"), "d": (d, "scalar")}
    )
    n = len(h)
    theta, count, exact, sing = (
        np.empty((n, 2)),
        np.empty(n, np.int64),
        np.empty((n, 2), bool),
        np.empty(n, bool),
    )
    _sp4_loop(h, p, k, d, tol, theta, count, exact, sing)
    return _two_roots(theta, count, exact, sing, batched)


# ----------------------------------------------------------------------------- SP3
@kernel
def sp3_cs(p1, p2, k, d, tol):
    """SP3 of one problem (tuples): (cos θ_a, sin θ_a, cos θ_b, sin θ_b, count, exact_a,
    exact_b, singular) (:func:`unit_cs`); see :func:`sp3`."""
    n2 = norm(p2)
    zero = n2 <= 1e-300
    if zero:
        h, dd, safe = k, dot(k, p1), 1.0
    else:
        h, dd, safe = scale(p2, 1.0 / n2), (dot(p1, p1) + n2 * n2 - d * d) / (2.0 * n2), n2
    # a distance residual δ changes the SP4 height by ≈ δ (2d + δ) / (2‖p2‖)
    ca, sa, cb, sb, cnt, ea, eb, sing = sp4_cs(
        h, p1, k, dd, max(tol * (d + 0.5 * tol) / safe, 1e-15)
    )
    if sing or zero:
        ea = abs(norm(sub(rotate_cs(k, ca, sa, p1), p2)) - d) <= tol
        if cnt == 2:
            eb = abs(norm(sub(rotate_cs(k, cb, sb, p1), p2)) - d) <= tol
    return ca, sa, cb, sb, cnt, ea, eb, sing or zero


@kernel
def sp3_one(p1, p2, k, d, tol):
    """SP3 of one problem (tuples): (θ_a, θ_b, count, exact_a, exact_b, singular); see :func:`sp3`
    (:func:`sp3_cs`)."""
    ca, sa, cb, sb, cnt, ea, eb, sing = sp3_cs(p1, p2, k, d, tol)
    return atan2(sa, ca), atan2(sb, cb), cnt, ea, eb, sing


@kernel
def _sp3_loop(p1, p2, k, d, tol, theta, count, exact, sing):
    for i in range(len(p1)):
        theta[i, 0], theta[i, 1], count[i], exact[i, 0], exact[i, 1], sing[i] = sp3_one(
            vec(p1[i]), vec(p2[i]), vec(k[i]), d[i], tol
        )


def sp3(p1, p2, k, d, tol: float = TOL) -> Solutions:
    """Subproblem 3, circle and sphere: θ with ‖rot(k, θ) p1 − p2‖ = d.

    IK-Geo §III-C: squaring, ‖p1‖² + ‖p2‖² − 2 p2ᵀ rot(k, θ) p1 = d², i.e. the SP4
    hᵀ rot(k, θ) p1 = (‖p1‖² + ‖p2‖² − d²) / (2‖p2‖) with h = p2 / ‖p2‖ (Eqs. (4)–(6)).
    Two, one (tangent) or one least-squares solution (minimises ``abs(‖rot(k, θ) p1 − p2‖ − d)``,
    ``exact = False``); ``tol`` bounds the distance residual (length unit).  ``singular``:
    p1 or p2 parallel to k, or p2 = 0 (the distance does not depend on θ).

    ``p1``, ``p2``: ``(3,)``/``(N, 3)``; ``k``: unit axis; ``d`` ≥ 0: scalar/``(N,)``.
    m = 1, S = 2."""
    tol = _tol(tol)
    (p1, p2, k, d), batched = _inputs(
        {"p1": (p1, "vec"), "p2": (p2, "vec"), "k": (k, "axis"), "d": (d, "scalar")}
    )
    if np.any(d < 0):
        raise ParameterError("d: the sphere radius must be >= 0")
    n = len(p1)
    theta, count, exact, sing = (
        np.empty((n, 2)),
        np.empty(n, np.int64),
        np.empty((n, 2), bool),
        np.empty(n, bool),
    )
    _sp3_loop(p1, p2, k, d, tol, theta, count, exact, sing)
    return _two_roots(theta, count, exact, sing, batched)


# ----------------------------------------------------------------------------- SP2
@kernel
def _sp2_second(k1, k2, p1, p2, u1, k2u2, k2k2u2, c1, s1, sing2, tol, sing, ex_in, n1, n2):
    """θ2 of SP2 for one root (c1, s1) of θ1 (:func:`sp2_cs`): (cos θ2, sin θ2, exact)."""
    v1 = rotate_cs(k1, c1, s1, u1)
    c2, s2 = (1.0, 0.0) if sing2 else unit_cs(dot(k2u2, v1), -dot(k2k2u2, v1))
    r = norm(sub(rotate_cs(k1, c1, s1, p1), rotate_cs(k2, c2, s2, p2)))
    return c2, s2, (r <= tol if sing else (ex_in and abs(n1 - n2) <= tol and r <= 10.0 * tol))


@kernel
def sp2_cs(p1, p2, k1, k2, tol):
    """SP2 of one problem (tuples): the roots a and b, each as cos θ1, sin θ1, cos θ2, sin θ2
    (8 numbers, root a first; NaN for a root that does not exist; :func:`unit_cs`), then count,
    exact_a, exact_b, singular; see :func:`sp2`."""
    n1, n2 = norm(p1), norm(p2)
    zero = n1 <= 1e-300 or n2 <= 1e-300
    u1 = scale(p1, 1.0 / n1) if n1 > 1e-300 else p1
    u2 = scale(p2, 1.0 / n2) if n2 > 1e-300 else p2
    ca, sa, cb, sb, cnt, ea, eb, sing1 = sp4_cs(
        k2, u1, k1, dot(k2, u2), tol / max(max(n1, n2), 1e-300)
    )
    k2u2 = cross(k2, u2)
    k2k2u2 = cross(k2, k2u2)
    sing2 = norm(k2u2) <= 1e-12
    sing = sing1 or sing2 or zero
    c2a, s2a, xa = _sp2_second(
        k1, k2, p1, p2, u1, k2u2, k2k2u2, ca, sa, sing2, tol, sing, ea, n1, n2
    )
    c2b, s2b, xb = math.nan, math.nan, False
    if cnt == 2:
        c2b, s2b, xb = _sp2_second(
            k1, k2, p1, p2, u1, k2u2, k2k2u2, cb, sb, sing2, tol, sing, eb, n1, n2
        )
    return ca, sa, c2a, s2a, cb, sb, c2b, s2b, cnt, xa, xb, sing


@kernel
def sp2_one(p1, p2, k1, k2, tol):
    """SP2 of one problem (tuples): (θ1_a, θ2_a, θ1_b, θ2_b, count, exact_a, exact_b,
    singular); see :func:`sp2` (:func:`sp2_cs`)."""
    ca, sa, c2a, s2a, cb, sb, c2b, s2b, cnt, xa, xb, sing = sp2_cs(p1, p2, k1, k2, tol)
    return atan2(sa, ca), atan2(s2a, c2a), atan2(sb, cb), atan2(s2b, c2b), cnt, xa, xb, sing


@kernel
def _sp2_loop(p1, p2, k1, k2, tol, theta, count, exact, sing):
    for i in range(len(p1)):
        (
            theta[i, 0, 0],
            theta[i, 0, 1],
            theta[i, 1, 0],
            theta[i, 1, 1],
            count[i],
            exact[i, 0],
            exact[i, 1],
            sing[i],
        ) = sp2_one(vec(p1[i]), vec(p2[i]), vec(k1[i]), vec(k2[i]), tol)


def sp2(p1, p2, k1, k2, tol: float = TOL) -> Solutions:
    """Subproblem 2, two circles: (θ1, θ2) with rot(k1, θ1) p1 = rot(k2, θ2) p2.

    IK-Geo §III-B: both sides have the same height along k2 and along k1, so with unit
    p̂ᵢ = pᵢ / ‖pᵢ‖, θ1 solves the SP4 k2ᵀ rot(k1, θ1) p̂1 = k2ᵀ p̂2 (Eqs. (4)–(6)) and, for
    each θ1, θ2 is the SP1 (Eq. (3)) rotating p̂2 onto rot(k1, θ1) p̂1 about k2.  Up to two
    solutions; where the circles do not meet (or ‖p1‖ ≠ ‖p2‖ beyond ``tol``) one
    least-squares solution of ‖rot(k1, θ1) p1 − rot(k2, θ2) p2‖, flagged ``exact = False``.
    ``singular``: k1 ∥ k2, or p1 ∥ k1, or p2 ∥ k2, or a zero vector (a family of
    solutions).

    ``p1``, ``p2``: ``(3,)``/``(N, 3)``; ``k1``, ``k2``: unit axes.  m = 2 (θ1, θ2), S = 2."""
    tol = _tol(tol)
    (p1, p2, k1, k2), batched = _inputs(
        {"p1": (p1, "vec"), "p2": (p2, "vec"), "k1": (k1, "axis"), "k2": (k2, "axis")}
    )
    n = len(p1)
    theta, count, exact, sing = (
        np.empty((n, 2, 2)),
        np.empty(n, np.int64),
        np.empty((n, 2), bool),
        np.empty(n, bool),
    )
    _sp2_loop(p1, p2, k1, k2, tol, theta, count, exact, sing)
    valid = np.arange(2)[None, :] < count[:, None]
    return _finish(theta, valid, exact, sing, batched)
