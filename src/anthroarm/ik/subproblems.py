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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..jit import kernel, local, local2, local_flags, local_ints2
from .vec3 import add, atan2, cross, dot, neg, norm, rotate, rotate_cs, scale, sub, vec, wrap

#: default tolerance on the residual of an exact solution (the caller's length unit)
TOL = 1e-9
#: default tolerance on the residual of SP5/SP6 solutions (quartic roots: a little looser)
TOL_QUARTIC = 1e-7
#: |axis| may differ from 1 by this much (it is then renormalised); more raises
_UNIT_TOL = 1e-6


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Solutions:
    """Every solution of a batch of one subproblem.

    ``theta``: ``(N, S, m)`` angles in rad, in (−π, π] (S: the most solutions the subproblem
    has, m: its unknowns; NaN where the slot holds no solution); ``valid``: ``(N, S)`` which
    slots hold a solution (valid slots come first); ``exact``: ``(N, S)`` the solution satisfies
    the equations to the tolerance (False: least squares, SP1–SP4 only); ``singular``: ``(N,)``
    the problem has infinitely many solutions (one representative returned) or is outside the
    subproblem's assumptions (SP5: k2 parallel to k1 or k3).  For one problem (unbatched input)
    the leading N axis is absent."""

    theta: np.ndarray
    valid: np.ndarray
    exact: np.ndarray
    singular: np.ndarray

    @property
    def count(self) -> np.ndarray:
        """Number of solutions per problem, ``(N,)`` (an int for one problem)."""
        c = self.valid.sum(-1)
        return int(c) if np.ndim(c) == 0 else c


def _finish(theta, valid, exact, singular, batched: bool) -> Solutions:
    theta = np.where(valid[..., None], theta, np.nan)
    exact = exact & valid
    if not batched:
        theta, valid, exact, singular = theta[0], valid[0], exact[0], bool(singular[0])
    return Solutions(theta, valid, exact, np.asarray(singular) if batched else singular)


# ----------------------------------------------------------------------------- input checks
def _inputs(spec: dict):
    """Validate and broadcast named inputs.  ``spec``: name -> (value, kind) with kind "vec",
    "axis" or "scalar".  Returns (list of arrays with leading N, batched?)."""
    arrays, n, batched = {}, None, False
    for name, (value, kind) in spec.items():
        try:
            a = np.asarray(value, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"{name}: not an array of numbers ({exc})") from None
        core = 0 if kind == "scalar" else 1
        if a.ndim not in (core, core + 1) or (core and a.shape[-1] != 3):
            want = "a scalar or shape (N,)" if kind == "scalar" else "shape (3,) or (N, 3)"
            raise ParameterError(f"{name}: expected {want}, got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ParameterError(f"{name}: contains NaN or inf")
        if a.ndim == core + 1:
            batched = True
            if n is not None and a.shape[0] != n:
                raise ParameterError(f"{name}: batch size {a.shape[0]} differs from {n}")
            n = a.shape[0]
        if kind == "axis":
            nrm = np.linalg.norm(a, axis=-1)
            if np.any(np.abs(nrm - 1.0) > _UNIT_TOL):
                bad = float(np.atleast_1d(nrm)[np.argmax(np.abs(np.atleast_1d(nrm) - 1.0))])
                raise ParameterError(f"{name}: the axis must be a unit vector (norm {bad:.6g})")
            a = a / nrm[..., None]
        arrays[name] = a
    n = 1 if n is None else n
    out = []
    for name, a in arrays.items():
        core = () if spec[name][1] == "scalar" else (3,)
        out.append(np.ascontiguousarray(np.broadcast_to(a, (n,) + core)))
    return out, batched


def _tol(tol) -> float:
    t = float(tol)
    if not np.isfinite(t) or t <= 0:
        raise ParameterError(f"tol must be a finite number > 0, got {tol!r}")
    return t


# ----------------------------------------------------------------------------- numpy helpers
def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _cross(a, b):
    """a × b over the last axis (broadcasting; np.cross costs ~20 µs of overhead per call)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], -1)


def _rotate(k, theta, p):
    """rot(k, θ) p for arrays (..., 3), (...), (..., 3) (Rodrigues, IK-Geo Eq. (1))."""
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    return p * c + _cross(k, p) * s + k * (_dot(k, p)[..., None] * (1.0 - c))


def rot(k, theta) -> np.ndarray:
    """Rotation matrix rot(k, θ) = I + sin θ [k]× + (1 − cos θ) [k]×² (IK-Geo Eq. (1)).

    ``k``: unit axis ``(3,)`` or ``(N, 3)``; ``theta``: rad, scalar or ``(N,)``.
    Returns ``(3, 3)`` or ``(N, 3, 3)``."""
    k = np.asarray(k, dtype=float)
    theta = np.asarray(theta, dtype=float)
    kx = np.zeros(np.broadcast_shapes(k.shape[:-1], theta.shape) + (3, 3))
    kx[..., 0, 1], kx[..., 0, 2], kx[..., 1, 2] = -k[..., 2], k[..., 1], -k[..., 0]
    kx[..., 1, 0], kx[..., 2, 0], kx[..., 2, 1] = k[..., 2], -k[..., 1], k[..., 0]
    s, c = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    return np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)


# ----------------------------------------------------------------------------- angles as (cos θ, sin θ)
@kernel
def unit_cs(y, x):
    """(cos θ, sin θ) = (x / r, y / r), r = ‖(x, y)‖, of θ = atan2(y, x): the rotation a
    subproblem finds, in the form the rotations that follow it use (no trigonometry; its angle
    is read once, by atan2 of the pair, where the caller needs it: the ``*_one`` functions,
    :func:`anthroarm.ik.geometric._angles`).  r by ``math.hypot`` where x² + y² would lose
    digits (below 1e-290 or above 1e290); cos and sin of atan2(y, x) where r is 0 or not
    finite."""
    rr = x * x + y * y
    r = math.sqrt(rr) if 1e-290 < rr < 1e290 else math.hypot(x, y)
    if 0.0 < r < math.inf:
        return x / r, y / r
    theta = atan2(y, x)
    return math.cos(theta), math.sin(theta)


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


# ----------------------------------------------------------------------------- quartics
@kernel
def _poly_d(a, n, x):
    """p(x) and p'(x) of the degree-n polynomial a[0..n] (highest first), by Horner."""
    f, g = a[0], 0.0
    for i in range(1, n + 1):
        g = g * x + f
        f = f * x + a[i]
    return f, g


@kernel
def _refine_root(a, n, lo, hi, flo):
    """The root of a[0..n] in (lo, hi) where p changes sign (p(lo) = ``flo``): Newton's
    method safeguarded by bisection (Press et al., *Numerical Recipes*, 3rd ed., §9.4
    "rtsafe"); Newton steps until the step is at rounding level."""
    x = 0.5 * (lo + hi)
    dxold = hi - lo
    dx = dxold
    neg_lo = flo < 0.0
    for _ in range(200):
        f, g = _poly_d(a, n, x)
        if f == 0.0:
            return x
        if (f < 0.0) == neg_lo:
            lo = x
        else:
            hi = x
        xn = x - f / g if g != 0.0 else lo - 1.0
        if not (lo < xn < hi) or abs(2.0 * f) > abs(dxold * g):
            xn = 0.5 * (lo + hi)  # bisection: Newton leaves the bracket or stalls
        dxold = dx
        dx = xn - x
        if xn == x or abs(dx) <= 4.4e-16 * abs(x) or hi - lo <= 4.4e-16 * max(abs(lo), abs(hi)):
            return xn
        x = xn
    return x


@kernel
def _bracket_roots(a, n, crit, cmul, m, out, omul):
    """Distinct real roots (ascending, into ``out``) and their multiplicities (``omul``) of the
    degree-n polynomial a[0..n] (a[0] ≠ 0), given the distinct real roots ``crit[:m]``
    (ascending, multiplicities ``cmul``) of its derivative; returns their number.

    p is monotone between consecutive critical points, so each interval holds at most one
    simple root (found by :func:`_refine_root` where p changes sign).  A critical point c is a
    root of multiplicity ``cmul + 1`` where: p has an extremum there (odd ``cmul``) that is 0 or
    misses zero by a pair of complex roots c ± iβ with β ≤ 1e-6 max(1, abs(c)) (β² ≈
    2 p(c) / p''(c), the tangent case; an extremum whose computed value crosses zero, however
    slightly, gives two simple roots, so close pairs are not merged); p is monotone across c
    (even ``cmul``) and vanishes there to rounding (``abs(p(c)) ≤ 4 (n + 1) ε Σ abs(aᵢ) abs(c)ⁱ``,
    a triple or higher root)."""
    a0 = a[0]
    bound = 0.0  # Fujiwara's bound on abs(root)
    for i in range(1, n + 1):
        t = abs(a[i] / a0)
        if i == n:
            t *= 0.5
        if t > 0.0:
            bound = max(bound, t ** (1.0 / i))
    bound *= 2.0
    for j in range(m):
        bound = max(bound, abs(crit[j]))
    bound = 1.5 * bound + 1e-300
    cnt = 0
    px = -bound
    pv, _ = _poly_d(a, n, px)
    for j in range(m + 1):
        last = j == m
        cx = bound if last else crit[j]
        cv, _ = _poly_d(a, n, cx)
        root = False
        if not last:
            s, ax = 0.0, abs(cx)
            for i in range(n + 1):
                s = s * ax + abs(a[i])
            if cmul[j] % 2 == 0:  # p monotone across c: a root of
                root = abs(cv) <= 4.0 * (n + 1) * 2.220446049250313e-16 * s  # odd multiplicity?
            elif cv == 0.0:
                root = True
            else:  # an extremum: tangent within 1e-6?
                p2 = 0.0
                for i in range(n - 1):
                    p2 = p2 * cx + a[i] * (n - i) * (n - i - 1)
                beta = 1e-6 * max(1.0, ax)
                if cv * p2 > 0.0 and 2.0 * cv / p2 <= beta * beta:
                    root = True
            if root:
                cv = 0.0
        if pv * cv < 0.0:
            out[cnt] = _refine_root(a, n, px, cx, pv)
            omul[cnt] = 1
            cnt += 1
        if root:
            out[cnt] = cx
            omul[cnt] = cmul[j] + 1
            cnt += 1
        px, pv = cx, cv
    return cnt


@kernel
def real_roots(c, x, real):
    """Real roots of a polynomial of degree ≤ 4 (coefficients ``c`` (5,), highest first) into
    ``x`` (4,) ascending with multiplicity (a double root twice) and ``real`` (4,) which are
    real (the real ones first; 0.0 in the other slots).  The coefficients are scaled by the largest abs(cᵢ);
    leading ones below 1e-10 (the first) or 1e-14 (the next) of it are dropped (lower degree);
    the zero polynomial and constants have no roots.

    Method: isolation by the derivatives (the real roots of p' split the line into intervals
    where p is monotone, so each holds at most one root; applied from the linear (deg−1)-th
    derivative up to p), each root found by bisection-safeguarded Newton iteration to rounding
    level (Press et al., *Numerical Recipes*, 3rd ed., §9.4; the derivative-bracketing scheme
    is e.g. that of Collins & Loos' real root isolation, see also Flocke, "Algorithm 954",
    ACM TOMS 41 (2015) for closed-form alternatives).  Double roots (tangent cases) are
    extrema of p that vanish or miss zero by a complex pair c ± iβ with β ≤ 1e-6 max(1, abs(c))
    (the tolerance of the former companion-matrix test), see :func:`_bracket_roots`."""
    big = 0.0
    for i in range(5):
        big = max(big, abs(c[i]))
    s = big if big > 0.0 else 1.0
    first = 0
    while first < 4 and abs(c[first] / s) <= (1e-10 if first == 0 else 1e-14):
        first += 1  # lower degree (rare)
    deg = 4 - first
    for i in range(4):
        x[i], real[i] = 0.0, False
    if deg == 0:
        return
    D = local2(4, 5)  # D[k]: k-th derivative, degree deg − k
    R = local2(4, 4)
    M = local_ints2(4, 4)
    for k in range(4):
        for i in range(5):
            D[k, i] = 0.0
        for i in range(4):
            R[k, i], M[k, i] = 0.0, 0
    for i in range(deg + 1):
        D[0, i] = c[first + i] / s
    for k in range(1, deg):
        mk = deg - k + 1
        for i in range(mk):
            D[k, i] = D[k - 1, i] * (mk - i)
    cnt = 1
    R[deg - 1, 0] = -D[deg - 1, 1] / D[deg - 1, 0]
    M[deg - 1, 0] = 1
    for k in range(deg - 2, -1, -1):
        cnt = _bracket_roots(D[k], deg - k, R[k + 1], M[k + 1], cnt, R[k], M[k])
    j = 0
    for r in range(cnt):
        for _ in range(M[0, r]):
            if j < 4:
                x[j] = R[0, r]
                real[j] = True
                j += 1


@kernel
def _solve3(J, F):
    """Solve the 3×3 system J x = F (J as row tuples) by Cramer's rule; (x, ok)."""
    det = dot(J[0], cross(J[1], J[2]))
    if abs(det) <= 1e-12:
        return (0.0, 0.0, 0.0), False
    c0, c1, c2 = cross(J[1], J[2]), cross(J[2], J[0]), cross(J[0], J[1])  # rows of adj(J)ᵀ
    return (
        (c0[0] * F[0] + c1[0] * F[1] + c2[0] * F[2]) / det,
        (c0[1] * F[0] + c1[1] * F[1] + c2[1] * F[2]) / det,
        (c0[2] * F[0] + c1[2] * F[1] + c2[2] * F[2]) / det,
    ), True


@kernel
def _keep_best(theta, ok, res, out_theta, m):
    """Sort candidate solutions by residual, drop the invalid and duplicates (within 1e-6 rad),
    keep the first 4 in ``out_theta`` (4, m); returns the count.  ``ok`` is consumed (the
    candidates are taken in order of residual, the first of equal ones first)."""
    cnt = 0
    while cnt < 4:
        j = -1
        for i in range(len(ok)):
            if ok[i] and (j < 0 or res[i] < res[j]):
                j = i
        if j < 0:
            break
        ok[j] = False
        dup = False
        for a in range(cnt):
            d = 0.0
            for c in range(m):
                d = max(d, abs(wrap(theta[j, c] - out_theta[a, c])))
            if d < 1e-6:
                dup = True
                break
        if not dup:
            for c in range(m):
                out_theta[cnt, c] = theta[j, c]
            cnt += 1
    return cnt


# ----------------------------------------------------------------------------- SP5
@kernel
def _circle_polynomials(o, k, p, k2, delta):
    """‖v‖² = P(z) ± √R(z) on the circle {o + rot(k, θ) p}, z = k2ᵀv: P (2 coeffs), R (3),
    and whether k ∥ k2 (IK-Geo §III-E)."""
    kxk2 = cross(k, k2)
    kkk2 = cross(k, kxk2)
    nk2 = dot(kxk2, kxk2)
    bad = nk2 <= 1e-20
    if bad:
        nk2 = 1.0
    kxp = cross(k, p)
    r2 = dot(kxp, kxp)
    alpha = dot(o, kkk2) / nk2
    beta = dot(o, kxk2) / nk2
    cen = add(o, scale(k, dot(k, p)))
    f = 4.0 * beta * beta
    return (
        (-2.0 * alpha, r2 + dot(cen, cen) + 2.0 * alpha * delta),
        (-f, 2.0 * delta * f, (-delta * delta + r2 * nk2) * f),
        bad,
    )


@kernel
def _sp5_residual(p0, p1, p2, p3, k1, k2, k3, t):
    return sub(add(p0, rotate(k1, t[0], p1)), rotate(k2, t[1], add(p2, rotate(k3, t[2], p3))))


#: Newton steps at most on an SP5 candidate (:func:`_sp5_newton`; quadratic convergence: most
#: stop after one or two)
SP5_NEWTON = 6


@kernel
def _sp5_newton(p0, p1, p2, p3, k1, k2, k3, t, stop):
    """Newton's method on the SP5 equation (3 equations, 3 angles) from ``t``: at most
    :data:`SP5_NEWTON` steps, fewer once the residual is below ``stop``; returns the wrapped
    angles and the residual norm there.  (Three steps left a candidate near a close pair of
    quartic roots at a residual of ~1e-7, accepted under ``TOL_QUARTIC`` but 1.4e-6 rad from the
    converged copy of the same solution: a duplicate root.)"""
    res = math.inf
    for it in range(SP5_NEWTON + 1):
        r1 = rotate(k1, t[0], p1)
        r3 = rotate(k3, t[2], p3)
        w = rotate(k2, t[1], add(p2, r3))
        F = sub(add(p0, r1), w)  # _sp5_residual at t
        res = norm(F)
        if it == SP5_NEWTON or res <= stop:
            break
        c3v = rotate(k2, t[1], cross(k3, r3))
        j0, j1 = cross(k1, r1), neg(cross(k2, w))
        J = ((j0[0], j1[0], -c3v[0]), (j0[1], j1[1], -c3v[1]), (j0[2], j1[2], -c3v[2]))
        step, good = _solve3(J, F)
        if good:
            t = (t[0] - step[0], t[1] - step[1], t[2] - step[2])
    return (wrap(t[0]), wrap(t[1]), wrap(t[2])), res


@kernel
def sp5_one(p0, p1, p2, p3, k1, k2, k3, tol, out_theta):
    """SP5 of one problem (tuples): writes the solutions into ``out_theta`` (4, 3) (valid rows
    first) and returns (count, singular); see :func:`sp5`."""
    c1 = add(p0, scale(k1, dot(k1, p1)))  # centre of circle 1
    c3 = add(p2, scale(k3, dot(k3, p3)))  # centre of circle 3
    d1, d3 = dot(k2, c1), dot(k2, c3)
    P1, R1, bad1 = _circle_polynomials(p0, k1, p1, k2, d1)
    P3, R3, bad3 = _circle_polynomials(p2, k3, p3, k2, d3)
    sing = bad1 or bad3
    for j in range(4):
        for c in range(3):
            out_theta[j, c] = math.nan
    if sing:
        return 0, True
    a, b = P1[0] - P3[0], P1[1] - P3[1]  # P13 = a z + b
    sq = (a * a, 2.0 * a * b, b * b)  # P13²
    rhs = (R3[0] - R1[0] - sq[0], R3[1] - R1[1] - sq[1], R3[2] - R1[2] - sq[2])
    eq = local(5)  # rhs² − 4 P13² R1
    eq[0] = rhs[0] * rhs[0] - 4.0 * sq[0] * R1[0]
    eq[1] = 2.0 * rhs[0] * rhs[1] - 4.0 * (sq[0] * R1[1] + sq[1] * R1[0])
    eq[2] = (
        rhs[1] * rhs[1]
        + 2.0 * rhs[0] * rhs[2]
        - 4.0 * (sq[0] * R1[2] + sq[1] * R1[1] + sq[2] * R1[0])
    )
    eq[3] = 2.0 * rhs[1] * rhs[2] - 4.0 * (sq[1] * R1[2] + sq[2] * R1[1])
    eq[4] = rhs[2] * rhs[2] - 4.0 * sq[2] * R1[2]
    z, real = local(4), local_flags(4)
    real_roots(eq, z, real)
    k1p1, k3p3 = cross(k1, p1), cross(k3, p3)
    kk1p1, kk3p3 = cross(k1, k1p1), cross(k3, k3p3)
    a1 = (dot(k1p1, k2), -dot(kk1p1, k2))  # A1ᵀ k2
    a3 = (dot(k3p3, k2), -dot(kk3p3, k2))
    na1 = max(a1[0] * a1[0] + a1[1] * a1[1], 1e-300)
    na3 = max(a3[0] * a3[0] + a3[1] * a3[1], 1e-300)
    theta, ok, res = local2(16, 3), local_flags(16), local(16)
    for i in range(16):
        theta[i, 0], theta[i, 1], theta[i, 2], ok[i], res[i] = 0.0, 0.0, 0.0, False, math.inf
    scl = 1.0 + norm(p0) + norm(p1) + norm(p2) + norm(p3)
    # Newton stops early below this residual (far below tol: the same exact solutions)
    stop = min(1e-13 * scl, 1e-3 * tol)
    for r in range(4):
        if not real[r] or (r > 0 and z[r] == z[r - 1]):
            continue  # a double root: the same candidates
        e1, e3 = z[r] - d1, z[r] - d3
        s1 = math.sqrt(max(na1 - e1 * e1, 0.0))
        s3 = math.sqrt(max(na3 - e3 * e3, 0.0))
        for g in range(4):
            sg1 = 1.0 if g < 2 else -1.0
            sg3 = 1.0 if g % 2 == 0 else -1.0
            if (sg1 < 0.0 and s1 == 0.0) or (sg3 < 0.0 and s3 == 0.0):
                continue  # the same point as sign +1
            # the SP4 points at height z (IK-Geo Eqs. (4)-(6)): x = (sin θ, cos θ) unnormalised
            x10, x11 = a1[0] * e1 + sg1 * a1[1] * s1, a1[1] * e1 - sg1 * a1[0] * s1
            x30, x31 = a3[0] * e3 + sg3 * a3[1] * s3, a3[1] * e3 - sg3 * a3[0] * s3
            n1, n3 = math.hypot(x10, x11), math.hypot(x30, x31)
            if n1 > 0.0:
                x10, x11 = x10 / n1, x11 / n1
            else:
                x10, x11 = 0.0, 1.0  # atan2(0, 0) = 0
            if n3 > 0.0:
                x30, x31 = x30 / n3, x31 / n3
            else:
                x30, x31 = 0.0, 1.0
            v1 = add(c1, sub(scale(k1p1, x10), scale(kk1p1, x11)))  # p0 + rot(k1, θ1) p1
            v3 = add(c3, sub(scale(k3p3, x30), scale(kk3p3, x31)))  # p2 + rot(k3, θ3) p3
            # residual after θ2 by SP1 (rot(k2, θ2) v3 nearest v1): heights h and radii ρ about
            # k2 (the spurious sign pairs of the squared quartic have ‖v1‖ ≠ ‖v3‖)
            h1, h3 = dot(k2, v1), dot(k2, v3)
            rho1 = math.sqrt(max(dot(v1, v1) - h1 * h1, 0.0))
            rho3 = math.sqrt(max(dot(v3, v3) - h3 * h3, 0.0))
            if math.hypot(h1 - h3, rho1 - rho3) > 1e-2 * scl:
                continue
            t1, t3 = math.atan2(x10, x11), math.atan2(x30, x31)
            k2v3 = cross(k2, v3)
            t2 = math.atan2(dot(k2v3, v1), -dot(cross(k2, k2v3), v1))  # SP1: rot(k2, θ2) v3 = v1
            t, rs = _sp5_newton(p0, p1, p2, p3, k1, k2, k3, (t1, t2, t3), stop)
            i = 4 * r + g
            theta[i, 0], theta[i, 1], theta[i, 2] = t
            res[i] = rs
            ok[i] = rs <= tol
    return _keep_best(theta, ok, res, out_theta, 3), False


@kernel
def _sp5_loop(p0, p1, p2, p3, k1, k2, k3, tol, theta, count, sing):
    for i in range(len(p0)):
        count[i], sing[i] = sp5_one(
            vec(p0[i]),
            vec(p1[i]),
            vec(p2[i]),
            vec(p3[i]),
            vec(k1[i]),
            vec(k2[i]),
            vec(k3[i]),
            tol,
            theta[i],
        )


def sp5(p0, p1, p2, p3, k1, k2, k3, tol: float = TOL_QUARTIC) -> Solutions:
    """Subproblem 5, three circles: (θ1, θ2, θ3) with
    p0 + rot(k1, θ1) p1 = rot(k2, θ2) (p2 + rot(k3, θ3) p3).

    IK-Geo §III-E: the height z = k2ᵀv of the common point v is the same on both sides and
    so is ‖v‖.  On circle i (i = 1: centre p0 + k1 k1ᵀp1, i = 3: centre p2 + k3 k3ᵀp3), fixing
    the height z leaves two points (the SP4 of Eqs. (4)–(6)), whose squared norm is
    Pᵢ(z) ± √Rᵢ(z) with Pᵢ linear and Rᵢ quadratic in z.  Equating the two sides and squaring
    twice gives the quartic (P1 − P3)² …::

        (R3 − R1 − (P1 − P3)²)² − 4 (P1 − P3)² R1 = 0

    whose real roots z give (θ1, θ3) by the two SP4s (4 sign pairs per root; the pairs with
    ‖v1‖ = ‖v3‖ are kept) and θ2 by SP1 (Eq. (3)).  Up to 4 solutions, each verified:
    the equation's residual (length unit) is at most ``tol``; no least-squares solution.
    ``singular``: k2 parallel to k1 or to k3, which this closed form excludes (the paper
    solves those cases with SP1–SP4); no solution returned then.

    Vectors ``(3,)``/``(N, 3)``; ``k1``, ``k2``, ``k3`` unit axes.  m = 3, S = 4."""
    tol = _tol(tol)
    (p0, p1, p2, p3, k1, k2, k3), batched = _inputs(
        {
            "p0": (p0, "vec"),
            "p1": (p1, "vec"),
            "p2": (p2, "vec"),
            "p3": (p3, "vec"),
            "k1": (k1, "axis"),
            "k2": (k2, "axis"),
            "k3": (k3, "axis"),
        }
    )
    n = len(p0)
    theta, count, sing = np.empty((n, 4, 3)), np.empty(n, np.int64), np.empty(n, bool)
    _sp5_loop(p0, p1, p2, p3, k1, k2, k3, tol, theta, count, sing)
    valid = np.arange(4)[None, :] < count[:, None]
    return _finish(theta, valid, valid.copy(), sing, batched)


# ----------------------------------------------------------------------------- SP6
@kernel
def _sp6_residual(H, K, P, d1, d2, t0, t1):
    v0 = dot(H[0], rotate(K[0], t0, P[0]))
    v1 = dot(H[1], rotate(K[1], t1, P[1]))
    v2 = dot(H[2], rotate(K[2], t0, P[2]))
    v3 = dot(H[3], rotate(K[3], t1, P[3]))
    return v0 + v1 - d1, v2 + v3 - d2


@kernel
def _conic(xm0, xm1, n00, n01, n10, n11):
    """‖xm + N ξ‖² = 1 (xm (2,), N 2×2) as a ξ1² + b ξ1ξ2 + c ξ2² + d ξ1 + e ξ2 + f = 0."""
    return (
        n00 * n00 + n10 * n10,
        2.0 * (n00 * n01 + n10 * n11),
        n01 * n01 + n11 * n11,
        2.0 * (xm0 * n00 + xm1 * n10),
        2.0 * (xm0 * n01 + xm1 * n11),
        xm0 * xm0 + xm1 * xm1 - 1.0,
    )


@kernel
def sp6_one(H, K, P, d1, d2, tol, out_theta):
    """SP6 of one problem (H, K, P: 4-tuples of vector tuples): writes the solutions into
    ``out_theta`` (4, 2) and returns (count, singular); see :func:`sp6`."""
    A, hk = local2(2, 4), local(4)
    for q in range(4):
        kxp = cross(K[q], P[q])
        row, col = q // 2, 2 * (q % 2)
        A[row, col] = dot(H[q], kxp)
        A[row, col + 1] = -dot(H[q], cross(K[q], kxp))
        hk[q] = dot(H[q], K[q]) * dot(K[q], P[q])
    b0, b1 = d1 - hk[0] - hk[1], d2 - hk[2] - hk[3]
    for j in range(4):
        out_theta[j, 0] = math.nan
        out_theta[j, 1] = math.nan
    # A = L Eᵀ: the rows of A orthonormalised (Gram–Schmidt), L lower triangular; the
    # product of A's singular values is |det L| = ‖a0‖ ‖w‖
    Vt, amax = local2(4, 4), 0.0
    n0 = 0.0
    for i in range(4):
        n0 += A[0, i] * A[0, i]
        amax = max(amax, abs(A[0, i]), abs(A[1, i]))
    n0 = math.sqrt(n0)
    if n0 <= 0.0:
        return 0, True
    l10, nw = 0.0, 0.0
    for i in range(4):
        Vt[0, i] = A[0, i] / n0
        l10 += Vt[0, i] * A[1, i]
    for i in range(4):
        Vt[1, i] = A[1, i] - l10 * Vt[0, i]
        nw += Vt[1, i] * Vt[1, i]
    nw = math.sqrt(nw)
    if n0 * nw <= 1e-12 * max(1.0, amax) ** 2:
        return 0, True  # the two equations are not independent
    for i in range(4):
        Vt[1, i] /= nw
    y0 = b0 / n0
    y1 = (b1 - l10 * y0) / nw
    xm = local(4)
    for i in range(4):
        xm[i] = Vt[0, i] * y0 + Vt[1, i] * y1  # minimum-norm solution of A x = b
    # the null space of A: the columns of I − E Eᵀ of largest norm, one after the other
    for r in (2, 3):
        best, kb = -1.0, 0
        for k in range(4):
            d = 1.0
            for m in range(r):
                d -= Vt[m, k] * Vt[m, k]
            if d > best:
                best, kb = d, k
        nn = 0.0
        for i in range(4):
            v = 1.0 if i == kb else 0.0
            for m in range(r):
                v -= Vt[m, i] * Vt[m, kb]
            Vt[r, i] = v
            nn += v * v
        nn = math.sqrt(nn)
        for i in range(4):
            Vt[r, i] /= nn
    # x = xm + N ξ with N = [Vt[2], Vt[3]]ᵀ (the null space of A)
    a, b_, c, d, e, f = _conic(xm[0], xm[1], Vt[2, 0], Vt[3, 0], Vt[2, 1], Vt[3, 1])
    a1, b1_, c1, dd1, e1, fq = _conic(xm[2], xm[3], Vt[2, 2], Vt[3, 2], Vt[2, 3], Vt[3, 3])
    b1 = b1_
    # resultant in ξ2 of the two conics (eliminating ξ1)
    z = local(5)
    z[4] = (
        f * a * dd1**2
        + a**2 * fq**2
        - d * a * dd1 * fq
        + a1**2 * f**2
        - 2 * a * fq * a1 * f
        - d * dd1 * a1 * f
        + a1 * d**2 * fq
    )
    z[3] = (
        e1 * d**2 * a1
        - fq * dd1 * a * b_
        - 2 * a * fq * a1 * e
        - f * a1 * b1 * d
        + 2 * dd1 * b1 * a * f
        + 2 * e1 * fq * a**2
        + dd1**2 * a * e
        - e1 * dd1 * a * d
        - 2 * a * e1 * a1 * f
        - f * a1 * dd1 * b_
        + 2 * f * e * a1**2
        - fq * b1 * a * d
        - e * a1 * dd1 * d
        + 2 * fq * b_ * a1 * d
    )
    z[2] = (
        e1**2 * a**2
        + 2 * c1 * fq * a**2
        - e * a1 * dd1 * b_
        + fq * a1 * b_**2
        - e * a1 * b1 * d
        - fq * b1 * a * b_
        - 2 * a * e1 * a1 * e
        + 2 * dd1 * b1 * a * e
        - c1 * dd1 * a * d
        - 2 * a * c1 * a1 * f
        + b1**2 * a * f
        + 2 * e1 * b_ * a1 * d
        + e**2 * a1**2
        - c * a1 * dd1 * d
        - e1 * b1 * a * d
        + 2 * f * c * a1**2
        - f * a1 * b1 * b_
        + c1 * d**2 * a1
        + dd1**2 * a * c
        - e1 * dd1 * a * b_
        - 2 * a * fq * a1 * c
    )
    z[1] = (
        -2 * a * a1 * c * e1
        + e1 * a1 * b_**2
        + 2 * c1 * b_ * a1 * d
        - c * a1 * b1 * d
        + b1**2 * a * e
        - e1 * b1 * a * b_
        - 2 * a * c1 * a1 * e
        - e * a1 * b1 * b_
        - c1 * b1 * a * d
        + 2 * e1 * c1 * a**2
        + 2 * e * c * a1**2
        - c * a1 * dd1 * b_
        + 2 * dd1 * b1 * a * c
        - c1 * dd1 * a * b_
    )
    z[0] = (
        a**2 * c1**2
        - 2 * a * c1 * a1 * c
        + a1**2 * c**2
        - b_ * a * b1 * c1
        - b_ * b1 * a1 * c
        + b_**2 * a1 * c1
        + c * a * b1**2
    )
    xi2s, real = local(4), local_flags(4)
    real_roots(z, xi2s, real)
    theta, ok, res = local2(4, 2), local_flags(4), local(4)
    for i in range(4):
        theta[i, 0], theta[i, 1], ok[i], res[i] = 0.0, 0.0, False, math.inf
    scl = 1.0 + norm(P[0]) + norm(P[1]) + norm(P[2]) + norm(P[3])
    for r in range(4):
        if not real[r]:
            continue
        xi2 = xi2s[r]
        den = a * b1 * xi2 + a * dd1 - a1 * b_ * xi2 - a1 * d
        if abs(den) <= 1e-300:
            continue
        xi1 = (
            -(a * fq + a * c1 * xi2**2 - a1 * c * xi2**2 + a * e1 * xi2 - a1 * e * xi2 - a1 * f)
            / den
        )
        x = local(4)
        for i in range(4):
            x[i] = xm[i] + Vt[2, i] * xi1 + Vt[3, i] * xi2
        t0, t1 = math.atan2(x[0], x[1]), math.atan2(x[2], x[3])
        if not (math.isfinite(t0) and math.isfinite(t1)):
            continue
        F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
        if max(abs(F0), abs(F1)) > 1e-2 * scl:
            continue
        for _ in range(3):  # Newton polish on the two equations
            F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
            g = local(4)
            for q in range(4):
                tq = t0 if q % 2 == 0 else t1
                g[q] = dot(H[q], cross(K[q], rotate(K[q], tq, P[q])))
            det = g[0] * g[3] - g[1] * g[2]
            if abs(det) > 1e-12:
                t0 -= (g[3] * F0 - g[1] * F1) / det
                t1 -= (-g[2] * F0 + g[0] * F1) / det
        t0, t1 = wrap(t0), wrap(t1)
        F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
        theta[r, 0], theta[r, 1] = t0, t1
        res[r] = max(abs(F0), abs(F1))
        ok[r] = res[r] <= tol
    return _keep_best(theta, ok, res, out_theta, 2), False


@kernel
def _sp6_loop(H, K, P, d1, d2, tol, theta, count, sing):
    for i in range(len(d1)):
        Hi = (vec(H[i, 0]), vec(H[i, 1]), vec(H[i, 2]), vec(H[i, 3]))
        Ki = (vec(K[i, 0]), vec(K[i, 1]), vec(K[i, 2]), vec(K[i, 3]))
        Pi = (vec(P[i, 0]), vec(P[i, 1]), vec(P[i, 2]), vec(P[i, 3]))
        count[i], sing[i] = sp6_one(Hi, Ki, Pi, d1[i], d2[i], tol, theta[i])


def sp6(h, k, p, d1, d2, tol: float = TOL_QUARTIC) -> Solutions:
    """Subproblem 6, four circles: (θ1, θ2) with::

        h1ᵀ rot(k1, θ1) p1 + h2ᵀ rot(k2, θ2) p2 = d1
        h3ᵀ rot(k3, θ1) p3 + h4ᵀ rot(k4, θ2) p4 = d2

    IK-Geo §III-F: with x = (sin θ1, cos θ1, sin θ2, cos θ2) both equations are linear,
    A x = b (A 2×4 built from Eq. (2)); x = x_min + N ξ with the minimum-norm solution and the
    null space of A (here by Gram–Schmidt on the rows of A), and the two unit-circle constraints
    ‖x[0:2]‖ = ‖x[2:4]‖ = 1 are two ellipses in ξ ∈ ℝ², whose intersection is a quartic in ξ₂
    (closed-form ellipse–ellipse elimination).  Up to 4 solutions, each verified: both
    residuals (length unit) at most ``tol``; no least-squares solution.  ``singular``: the
    two equations are not independent (rank A < 2).

    ``h``, ``k``: unit axes ``(4, 3)`` or ``(N, 4, 3)`` (rows h1…h4, k1…k4); ``p``:
    ``(4, 3)``/``(N, 4, 3)``; ``d1``, ``d2``: scalar/``(N,)``.  m = 2, S = 4."""
    tol = _tol(tol)
    arrs = {}
    for name, v in (("h", h), ("k", k), ("p", p)):
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"{name}: not an array of numbers ({exc})") from None
        if a.ndim not in (2, 3) or a.shape[-2:] != (4, 3):
            raise ParameterError(f"{name}: expected shape (4, 3) or (N, 4, 3), got {a.shape}")
        arrs[name] = a
    spec = {
        f"{name}{i + 1}": (arrs[name][..., i, :], "axis" if name != "p" else "vec")
        for name in ("h", "k", "p")
        for i in range(4)
    }
    spec.update({"d1": (d1, "scalar"), "d2": (d2, "scalar")})
    vals, batched = _inputs(spec)
    H, K, P = (
        np.ascontiguousarray(np.stack(vals[4 * j : 4 * j + 4], 1)) for j in range(3)
    )  # (N, 4, 3)
    d1, d2 = vals[12], vals[13]
    n = len(d1)
    theta, count, sing = np.empty((n, 4, 2)), np.empty(n, np.int64), np.empty(n, bool)
    _sp6_loop(H, K, P, d1, d2, tol, theta, count, sing)
    valid = np.arange(4)[None, :] < count[:, None]
    return _finish(theta, valid, valid.copy(), sing, batched)


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
