"""The six canonical geometric subproblems of IK-Geo, batched.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", *Mechanism and Machine Theory* 209 (2025), arXiv 2211.05737 (cited below as
"IK-Geo"; equation numbers are those of the arXiv version, §III "Subproblem solutions").  The
formulation was read from the authors' reference implementation (github.com/rpiRobotics/ik-geo,
``matlab/+subproblem``); the code here is our own, vectorised over a leading batch axis.

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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

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
            norm = np.linalg.norm(a, axis=-1)
            if np.any(np.abs(norm - 1.0) > _UNIT_TOL):
                bad = float(np.atleast_1d(norm)[np.argmax(np.abs(np.atleast_1d(norm) - 1.0))])
                raise ParameterError(f"{name}: the axis must be a unit vector (norm {bad:.6g})")
            a = a / norm[..., None]
        arrays[name] = a
    n = 1 if n is None else n
    out = []
    for name, a in arrays.items():
        core = () if spec[name][1] == "scalar" else (3,)
        out.append(np.array(np.broadcast_to(a, (n,) + core)))
    return out, batched


def _tol(tol) -> float:
    t = float(tol)
    if not np.isfinite(t) or t <= 0:
        raise ParameterError(f"tol must be a finite number > 0, got {tol!r}")
    return t


# ----------------------------------------------------------------------------- helpers
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


def _basis(k, p):
    """A = [k × p, −k × (k × p)] (IK-Geo Eq. (2)), ``(N, 3, 2)``."""
    kxp = _cross(k, p)
    return np.stack([kxp, -_cross(k, kxp)], axis=-1)


def _compact(theta, valid, exact, size):
    """Move valid slots to the front (stable) and keep ``size`` slots."""
    order = np.argsort(~valid, axis=1, kind="stable")[:, :size]
    take = np.take_along_axis
    return (take(theta, order[..., None], axis=1), take(valid, order, axis=1),
            take(exact, order, axis=1))


def _dedupe(theta, valid, atol=1e-6):
    """Mark a valid slot invalid when an earlier valid slot holds the same angles."""
    n, s, _ = theta.shape
    valid = valid.copy()
    for j in range(1, s):
        d = np.abs(np.angle(np.exp(1j * (theta[:, :j] - theta[:, j:j + 1])))).max(-1)   # (N, j)
        dup = ((d < atol) & valid[:, :j]).any(1)
        valid[:, j] &= ~dup
    return valid


def _newton(residual, jacobian, theta, iters=3):
    """Polish candidate roots: Newton steps on the subproblem's own equations (batched over
    leading axes; square Jacobian).  A step is skipped where the Jacobian is singular."""
    for _ in range(iters):
        F, J = residual(theta), jacobian(theta)
        det = np.linalg.det(J)
        ok = np.abs(det) > 1e-12
        Js = np.where(ok[..., None, None], J, np.eye(J.shape[-1]))
        step = np.linalg.solve(Js, F[..., None])[..., 0]
        theta = theta - np.where(ok[..., None], step, 0.0)
    return theta


# ----------------------------------------------------------------------------- SP4 core
def _sp4_core(h, p, k, d, tol):
    """hᵀ rot(k, θ) p = d for unit h (batched).  Returns theta (N, 2), valid (N, 2),
    exact (N, 2), singular (N,).  IK-Geo Eqs. (4)–(6)."""
    A = np.einsum("ni,nij->nj", h, _basis(k, p))                       # (N, 2) = hᵀA
    b = d - _dot(h, k) * _dot(k, p)
    nA = np.linalg.norm(A, axis=-1)
    ab = np.abs(b)
    margin = nA - ab                                   # > 0: two roots; residual of the LS root
    # two roots wherever the plane cuts the circle (as IK-Geo's sp_4): a near-tangent pair is
    # kept as two roots, not merged into one whose error grows like √margin in the angle
    two = margin > 0.0
    xi = np.sqrt(np.maximum(nA * nA - b * b, 0.0))
    x_ls = A * b[:, None]                               # Aᵀb (a multiple of the LS point)
    jA = np.stack([A[:, 1], -A[:, 0]], -1)              # the null direction of A
    x1 = x_ls + xi[:, None] * jA
    x2 = x_ls - xi[:, None] * jA
    th = np.stack([np.arctan2(x1[:, 0], x1[:, 1]), np.arctan2(x2[:, 0], x2[:, 1])], -1)
    # one root (tangent or least squares): atan2 of Aᵀb (θ = 0 when A = 0)
    th[:, 0] = np.where(two, th[:, 0], np.arctan2(x_ls[:, 0], x_ls[:, 1]))
    scale = 1e-12 * np.maximum(1.0, np.linalg.norm(p, axis=-1))
    singular = nA <= scale
    th[:, 0] = np.where(singular, 0.0, th[:, 0])
    valid = np.stack([np.ones_like(two), two & ~singular], -1)
    exact1 = np.where(singular, ab <= tol, margin >= -tol)
    exact = np.stack([exact1 | two, two], -1) & valid
    return th, valid, exact, singular


# ----------------------------------------------------------------------------- SP1 … SP4
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
    x = np.einsum("nij,ni->nj", _basis(k, p1), p2)
    theta = np.arctan2(x[:, 0], x[:, 1])
    sing = (np.linalg.norm(_cross(k, p1), axis=-1) <= 1e-12 * np.maximum(1, np.linalg.norm(p1, axis=-1))) | \
           (np.linalg.norm(_cross(k, p2), axis=-1) <= 1e-12 * np.maximum(1, np.linalg.norm(p2, axis=-1)))
    theta = np.where(sing, 0.0, theta)
    exact = (np.abs(np.linalg.norm(p1, axis=-1) - np.linalg.norm(p2, axis=-1)) <= tol) & \
            (np.abs(_dot(k, p1) - _dot(k, p2)) <= tol)
    return _finish(theta[:, None, None], np.ones((len(theta), 1), bool), exact[:, None], sing, batched)


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
    (h, p, k, d), batched = _inputs({"h": (h, "axis"), "p": (p, "vec"), "k": (k, "axis"),
                                     "d": (d, "scalar")})
    th, valid, exact, sing = _sp4_core(h, p, k, d, tol)
    return _finish(th[..., None], valid, exact, sing, batched)


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
    (p1, p2, k, d), batched = _inputs({"p1": (p1, "vec"), "p2": (p2, "vec"), "k": (k, "axis"),
                                       "d": (d, "scalar")})
    if np.any(d < 0):
        raise ParameterError("d: the sphere radius must be >= 0")
    n2 = np.linalg.norm(p2, axis=-1)
    zero = n2 <= 1e-300
    h = np.where(zero[:, None], k, p2 / np.where(zero, 1.0, n2)[:, None])
    safe = np.where(zero, 1.0, n2)
    dd = np.where(zero, _dot(k, p1), (_dot(p1, p1) + n2 * n2 - d * d) / (2.0 * safe))
    # a distance residual δ changes the SP4 height by ≈ δ (2d + δ) / (2‖p2‖)
    tol4 = tol * (d + 0.5 * tol) / safe
    th, valid, exact, sing = _sp4_core(h, p1, k, dd, np.maximum(tol4, 1e-15))
    r = np.linalg.norm(_rotate(k[:, None], th, p1[:, None]) - p2[:, None], axis=-1)
    exact = np.where(sing[:, None] | zero[:, None], np.abs(r - d[:, None]) <= tol, exact)
    sing = sing | zero
    return _finish(th[..., None], valid, exact, sing, batched)


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
    (p1, p2, k1, k2), batched = _inputs({"p1": (p1, "vec"), "p2": (p2, "vec"), "k1": (k1, "axis"),
                                         "k2": (k2, "axis")})
    n1, n2 = np.linalg.norm(p1, axis=-1), np.linalg.norm(p2, axis=-1)
    zero = (n1 <= 1e-300) | (n2 <= 1e-300)
    u1 = p1 / np.where(n1 > 1e-300, n1, 1.0)[:, None]
    u2 = p2 / np.where(n2 > 1e-300, n2, 1.0)[:, None]
    scale = np.maximum(np.maximum(n1, n2), 1e-300)
    th1, valid, ex1, sing1 = _sp4_core(k2, u1, k1, _dot(k2, u2), tol / scale)
    v1 = _rotate(k1[:, None], th1, u1[:, None])                       # (N, 2, 3)
    x = np.einsum("nij,nsi->nsj", _basis(k2, u2), v1)
    th2 = np.arctan2(x[..., 0], x[..., 1])
    sing2 = np.linalg.norm(_cross(k2, u2), axis=-1) <= 1e-12
    th2 = np.where(sing2[:, None], 0.0, th2)
    r = np.linalg.norm(_rotate(k1[:, None], th1, p1[:, None]) - _rotate(k2[:, None], th2, p2[:, None]), axis=-1)
    exact = ex1 & (np.abs(n1 - n2) <= tol)[:, None] & (r <= 10 * tol)
    exact = np.where((sing1 | sing2 | zero)[:, None], r <= tol, exact)
    theta = np.stack([th1, th2], -1)
    return _finish(theta, valid, exact, sing1 | sing2 | zero, batched)


# ----------------------------------------------------------------------------- quartics
def _polymul(a, b):
    """Batched polynomial product, coefficients highest power first: (N, na), (N, nb)."""
    n, na = a.shape
    nb = b.shape[1]
    out = np.zeros((n, na + nb - 1))
    for i in range(na):
        out[:, i:i + nb] += a[:, i:i + 1] * b
    return out


def _real_roots(c):
    """Real roots of N polynomials of degree ≤ 4 (coefficients (N, 5), highest first).
    Returns roots (N, 4) and a mask (N, 4) of real ones.  Eigenvalues of the companion matrix,
    polished by two Newton steps on the original polynomial."""
    n = c.shape[0]
    roots = np.full((n, 4), np.nan + 0j)
    big = np.abs(c).max(1)
    big = np.where(big > 0, big, 1.0)
    cn = c / big[:, None]
    lead = np.abs(cn[:, 0]) > 1e-10
    if np.any(lead):
        m = cn[lead]
        comp = np.zeros((len(m), 4, 4))
        comp[:, 0, :] = -m[:, 1:] / m[:, :1]
        comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1.0
        roots[lead] = np.linalg.eigvals(comp)
    for i in np.flatnonzero(~lead):                   # lower degree (rare): one row at a time
        r = np.roots(np.trim_zeros(np.where(np.abs(cn[i]) > 1e-14, cn[i], 0.0), "f"))
        roots[i, :len(r)] = r
    is_real = np.isfinite(roots) & (np.abs(roots.imag) <= 1e-6 * np.maximum(1.0, np.abs(roots.real)))
    x = np.where(is_real, roots.real, 0.0)
    dc = cn[:, :4] * np.array([4.0, 3.0, 2.0, 1.0])
    for _ in range(2):
        f = ((((cn[:, 0:1] * x + cn[:, 1:2]) * x + cn[:, 2:3]) * x + cn[:, 3:4]) * x + cn[:, 4:5])
        g = (((dc[:, 0:1] * x + dc[:, 1:2]) * x + dc[:, 2:3]) * x + dc[:, 3:4])
        step = np.where(np.abs(g) > 1e-300, f / np.where(g == 0, 1.0, g), 0.0)
        x = np.where(np.abs(step) < 1e-3 * np.maximum(1.0, np.abs(x)), x - step, x)
    return x, is_real


# ----------------------------------------------------------------------------- SP5
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
    (p0, p1, p2, p3, k1, k2, k3), batched = _inputs({
        "p0": (p0, "vec"), "p1": (p1, "vec"), "p2": (p2, "vec"), "p3": (p3, "vec"),
        "k1": (k1, "axis"), "k2": (k2, "axis"), "k3": (k3, "axis")})
    n = len(p0)
    c1 = p0 + k1 * _dot(k1, p1)[:, None]                 # centre of circle 1
    c3 = p2 + k3 * _dot(k3, p3)[:, None]                 # centre of circle 3
    d1, d3 = _dot(k2, c1), _dot(k2, c3)

    def circle_polynomials(o, k, p, delta):
        # ‖v‖² = P(z) ± √R(z) on circle {o + k kᵀp + A x}, z = k2ᵀv (P: 2 coeffs, R: 3)
        kxk2 = _cross(k, k2)
        kkk2 = _cross(k, kxk2)
        nk2 = _dot(kxk2, kxk2)
        bad = nk2 <= 1e-20
        nk2 = np.where(bad, 1.0, nk2)
        kxp = _cross(k, p)
        r2 = _dot(kxp, kxp)
        alpha = _dot(o, kkk2) / nk2
        beta = _dot(o, kxk2) / nk2
        cen = o + k * _dot(k, p)[:, None]
        P = np.stack([-2 * alpha, r2 + _dot(cen, cen) + 2 * alpha * delta], -1)
        R = np.stack([-np.ones(n), 2 * delta, -delta ** 2 + r2 * nk2], -1) * (4 * beta ** 2)[:, None]
        return P, R, bad

    P1, R1, bad1 = circle_polynomials(p0, k1, p1, d1)
    P3, R3, bad3 = circle_polynomials(p2, k3, p3, d3)
    P13 = P1 - P3
    P13sq = _polymul(P13, P13)
    rhs = R3 - R1 - P13sq
    eqn = _polymul(rhs, rhs) - 4 * _polymul(P13sq, R1)
    z, real = _real_roots(eqn)                            # (N, 4)

    A1, A3 = _basis(k1, p1), _basis(k3, p3)
    a1 = np.einsum("nij,ni->nj", A1, k2)                  # A1ᵀk2 (N, 2)
    a3 = np.einsum("nij,ni->nj", A3, k2)
    na1, na3 = _dot(a1, a1), _dot(a3, a3)
    J = lambda a: np.stack([a[..., 1], -a[..., 0]], -1)   # noqa: E731

    cand_t, cand_ok = [], []
    for sgn1 in (1.0, -1.0):
        for sgn3 in (1.0, -1.0):
            e1 = (z - d1[:, None])
            e3 = (z - d3[:, None])
            s1 = np.sqrt(np.maximum(na1[:, None] - e1 ** 2, 0.0))
            s3 = np.sqrt(np.maximum(na3[:, None] - e3 ** 2, 0.0))
            x1 = (a1[:, None] * e1[..., None] + sgn1 * J(a1)[:, None] * s1[..., None]) / np.maximum(na1, 1e-300)[:, None, None]
            x3 = (a3[:, None] * e3[..., None] + sgn3 * J(a3)[:, None] * s3[..., None]) / np.maximum(na3, 1e-300)[:, None, None]
            t1 = np.arctan2(x1[..., 0], x1[..., 1])
            t3 = np.arctan2(x3[..., 0], x3[..., 1])
            v1 = p0[:, None] + _rotate(k1[:, None], t1, p1[:, None])
            v3 = p2[:, None] + _rotate(k3[:, None], t3, p3[:, None])
            xb = np.einsum("nsij,nsi->nsj", _basis(k2[:, None], v3), v1)   # SP1: rot(k2, θ2) v3 = v1
            t2 = np.arctan2(xb[..., 0], xb[..., 1])
            cand_t.append(np.stack([t1, t2, t3], -1))
            cand_ok.append(real)
    theta = np.concatenate(cand_t, 1)                     # (N, 16, 3)
    ok = np.concatenate(cand_ok, 1)
    K1, K2, K3 = k1[:, None], k2[:, None], k3[:, None]
    P0, P1, P2, P3 = p0[:, None], p1[:, None], p2[:, None], p3[:, None]

    def residual(t):
        return P0 + _rotate(K1, t[..., 0], P1) - _rotate(K2, t[..., 1], P2 + _rotate(K3, t[..., 2], P3))

    def jacobian(t):
        r1 = _rotate(K1, t[..., 0], P1)
        r3 = _rotate(K3, t[..., 2], P3)
        w = _rotate(K2, t[..., 1], P2 + r3)
        c3 = _rotate(K2, t[..., 1], _cross(np.broadcast_to(K3, r3.shape), r3))
        return np.stack([_cross(np.broadcast_to(K1, r1.shape), r1),
                         -_cross(np.broadcast_to(K2, w.shape), w), -c3], -1)

    scale = 1.0 + sum(np.linalg.norm(v, axis=-1) for v in (p0, p1, p2, p3))[:, None]
    near = ok & (np.linalg.norm(residual(theta), axis=-1) <= 1e-2 * scale)
    theta = _newton(residual, jacobian, theta)            # polish (the quartic's roots cluster)
    theta = np.angle(np.exp(1j * theta))
    res = np.linalg.norm(residual(theta), axis=-1)
    sing = bad1 | bad3
    ok = near & (res <= tol) & ~sing[:, None]
    order = np.argsort(np.where(ok, res, np.inf), axis=1, kind="stable")
    theta = np.take_along_axis(theta, order[..., None], 1)
    ok = np.take_along_axis(ok, order, 1)
    ok = _dedupe(theta, ok)
    theta, valid, exact = _compact(theta, ok, ok.copy(), 4)
    return _finish(theta, valid, exact, sing, batched)


# ----------------------------------------------------------------------------- SP6
def sp6(h, k, p, d1, d2, tol: float = TOL_QUARTIC) -> Solutions:
    """Subproblem 6, four circles: (θ1, θ2) with::

        h1ᵀ rot(k1, θ1) p1 + h2ᵀ rot(k2, θ2) p2 = d1
        h3ᵀ rot(k3, θ1) p3 + h4ᵀ rot(k4, θ2) p4 = d2

    IK-Geo §III-F: with x = (sin θ1, cos θ1, sin θ2, cos θ2) both equations are linear,
    A x = b (A 2×4 built from Eq. (2)); x = x_min + N ξ with the minimum-norm solution and the
    null space from a QR factorisation of Aᵀ, and the two unit-circle constraints
    ‖x[0:2]‖ = ‖x[2:4]‖ = 1 are two ellipses in ξ ∈ ℝ², whose intersection is a quartic in ξ₂
    (closed-form ellipse–ellipse elimination).  Up to 4 solutions, each verified: both
    residuals (length unit) at most ``tol``; no least-squares solution.

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
    spec = {f"{name}{i + 1}": (arrs[name][..., i, :], "axis" if name != "p" else "vec")
            for name in ("h", "k", "p") for i in range(4)}
    spec.update({"d1": (d1, "scalar"), "d2": (d2, "scalar")})
    vals, batched = _inputs(spec)
    H, K, P = (np.stack(vals[4 * j:4 * j + 4], 1) for j in range(3))    # (N, 4, 3)
    d1, d2 = vals[12], vals[13]
    n = len(d1)
    Ai = _basis(K.reshape(-1, 3), P.reshape(-1, 3)).reshape(n, 4, 3, 2)
    hA = np.einsum("nqi,nqij->nqj", H, Ai)                # (N, 4, 2) = hᵢᵀAᵢ
    A = np.zeros((n, 2, 4))
    A[:, 0, 0:2], A[:, 0, 2:4] = hA[:, 0], hA[:, 1]
    A[:, 1, 0:2], A[:, 1, 2:4] = hA[:, 2], hA[:, 3]
    hk = _dot(H, K) * _dot(K, P)                          # hᵢᵀkᵢ kᵢᵀpᵢ (N, 4)
    b = np.stack([d1 - hk[:, 0] - hk[:, 1], d2 - hk[:, 2] - hk[:, 3]], -1)
    Q, R = np.linalg.qr(np.swapaxes(A, 1, 2), mode="complete")          # Aᵀ = Q R
    R2 = R[:, :2, :2]
    det = R2[:, 0, 0] * R2[:, 1, 1]
    rank_ok = np.abs(det) > 1e-12 * np.maximum(1.0, np.abs(A).max((1, 2))) ** 2
    R2 = np.where(rank_ok[:, None, None], R2, np.eye(2))
    y = np.linalg.solve(np.swapaxes(R2, 1, 2), b[..., None])[..., 0]    # R2ᵀ y = b
    xm = np.einsum("nij,nj->ni", Q[:, :, :2], y)                         # (N, 4)
    xn = Q[:, :, 2:]                                                      # (N, 4, 2)

    def conic(xm_, xn_):
        # ‖xm + xn ξ‖² = 1  →  a ξ1² + b ξ1ξ2 + c ξ2² + d ξ1 + e ξ2 + f = 0
        M = np.einsum("nki,nkj->nij", xn_, xn_)
        B = 2 * np.einsum("nk,nkj->nj", xm_, xn_)
        return M[:, 0, 0], 2 * M[:, 1, 0], M[:, 1, 1], B[:, 0], B[:, 1], _dot(xm_, xm_) - 1
    a, b_, c, d, e, f = conic(xm[:, 0:2], xn[:, 0:2])
    a1, b1, c1, dd1, e1, fq = conic(xm[:, 2:4], xn[:, 2:4])
    # resultant in ξ2 of the two conics (eliminating ξ1)
    z0 = (f * a * dd1 ** 2 + a ** 2 * fq ** 2 - d * a * dd1 * fq + a1 ** 2 * f ** 2 - 2 * a * fq * a1 * f
          - d * dd1 * a1 * f + a1 * d ** 2 * fq)
    z1 = (e1 * d ** 2 * a1 - fq * dd1 * a * b_ - 2 * a * fq * a1 * e - f * a1 * b1 * d + 2 * dd1 * b1 * a * f
          + 2 * e1 * fq * a ** 2 + dd1 ** 2 * a * e - e1 * dd1 * a * d - 2 * a * e1 * a1 * f - f * a1 * dd1 * b_
          + 2 * f * e * a1 ** 2 - fq * b1 * a * d - e * a1 * dd1 * d + 2 * fq * b_ * a1 * d)
    z2 = (e1 ** 2 * a ** 2 + 2 * c1 * fq * a ** 2 - e * a1 * dd1 * b_ + fq * a1 * b_ ** 2 - e * a1 * b1 * d
          - fq * b1 * a * b_ - 2 * a * e1 * a1 * e + 2 * dd1 * b1 * a * e - c1 * dd1 * a * d - 2 * a * c1 * a1 * f
          + b1 ** 2 * a * f + 2 * e1 * b_ * a1 * d + e ** 2 * a1 ** 2 - c * a1 * dd1 * d - e1 * b1 * a * d
          + 2 * f * c * a1 ** 2 - f * a1 * b1 * b_ + c1 * d ** 2 * a1 + dd1 ** 2 * a * c - e1 * dd1 * a * b_
          - 2 * a * fq * a1 * c)
    z3 = (-2 * a * a1 * c * e1 + e1 * a1 * b_ ** 2 + 2 * c1 * b_ * a1 * d - c * a1 * b1 * d + b1 ** 2 * a * e
          - e1 * b1 * a * b_ - 2 * a * c1 * a1 * e - e * a1 * b1 * b_ - c1 * b1 * a * d + 2 * e1 * c1 * a ** 2
          + 2 * e * c * a1 ** 2 - c * a1 * dd1 * b_ + 2 * dd1 * b1 * a * c - c1 * dd1 * a * b_)
    z4 = (a ** 2 * c1 ** 2 - 2 * a * c1 * a1 * c + a1 ** 2 * c ** 2 - b_ * a * b1 * c1 - b_ * b1 * a1 * c
          + b_ ** 2 * a1 * c1 + c * a * b1 ** 2)
    xi2, real = _real_roots(np.stack([z4, z3, z2, z1, z0], -1))
    den = a[:, None] * b1[:, None] * xi2 + (a * dd1)[:, None] - a1[:, None] * b_[:, None] * xi2 - (a1 * d)[:, None]
    num = ((a * fq)[:, None] + (a * c1)[:, None] * xi2 ** 2 - (a1 * c)[:, None] * xi2 ** 2
           + (a * e1)[:, None] * xi2 - (a1 * e)[:, None] * xi2 - (a1 * f)[:, None])
    xi1 = -num / np.where(np.abs(den) > 1e-300, den, 1.0)
    x = xm[:, None] + xn[:, None, :, 0] * xi1[..., None] + xn[:, None, :, 1] * xi2[..., None]   # (N, 4, 4)
    theta = np.stack([np.arctan2(x[..., 0], x[..., 1]), np.arctan2(x[..., 2], x[..., 3])], -1)
    Hs, Ks, Ps = H[:, None], K[:, None], P[:, None]        # (N, 1, 4, 3)

    def residual(t):
        tt = t[..., [0, 1, 0, 1]]                          # θ of each term (N, S, 4)
        v = _dot(Hs, _rotate(Ks, tt, Ps))
        return np.stack([v[..., 0] + v[..., 1] - d1[:, None], v[..., 2] + v[..., 3] - d2[:, None]], -1)

    def jacobian(t):
        tt = t[..., [0, 1, 0, 1]]
        rp = _rotate(Ks, tt, Ps)
        g = _dot(Hs, _cross(np.broadcast_to(Ks, rp.shape), rp))   # d(hᵀ rot p)/dθ (N, S, 4)
        return np.stack([g[..., 0:2], g[..., 2:4]], -2)

    scale = 1.0 + np.linalg.norm(P, axis=-1).sum(-1)[:, None]
    fin = real & np.isfinite(theta).all(-1) & (np.abs(den) > 1e-300) & rank_ok[:, None]
    theta = np.where(fin[..., None], theta, 0.0)
    near = fin & (np.abs(residual(theta)).max(-1) <= 1e-2 * scale)
    theta = np.angle(np.exp(1j * _newton(residual, jacobian, theta)))   # polish
    res = np.abs(residual(theta)).max(-1)
    ok = near & (res <= tol)
    order = np.argsort(np.where(ok, res, np.inf), axis=1, kind="stable")
    theta = np.take_along_axis(theta, order[..., None], 1)
    ok = np.take_along_axis(ok, order, 1)
    ok = _dedupe(theta, ok)
    theta, valid, exact = _compact(theta, ok, ok.copy(), 4)
    return _finish(theta, valid, exact, ~rank_ok, batched)


__all__ = ["Solutions", "rot", "sp1", "sp2", "sp3", "sp4", "sp5", "sp6", "TOL", "TOL_QUARTIC"]
