"""Four-bar path synthesis by least squares (平方逼近法), book §3-3, Eq. (3-11)–(3-30).

Geometry (Fig. 3-10 is missing; reconstruction of ch3-4 notes §7, consistent with (3-11) and
(3-12)).  In the target frame, the crank pivot O is at ``origin``; a path point is
``C = O + r e^{iδ}``.  The crank O→A has length r1 and the prescribed angle α; the coupler
carries C at distance r2 from A (angle ψ) and the rocker joint B at distance r5 from C in the
direction ``C→B = −e^{iφ}`` with ``φ = ψ + γ`` (γ = 0: B on line AC, the book's case); the
rocker D→B has length r4; the second ground pivot is ``D = O + r3 e^{iβ}``::

    (3-9)   r e^{iδ} = r1 e^{iα} + r2 e^{iψ}
    (3-10)  r e^{iδ} = r3 e^{iβ} + r4 e^{iθ} + r5 e^{iφ}

Eliminating ψ and θ gives the linear-in-parameters equations::

    (3-11/13)  K1·[2r cos(δ − α)] + K2 = r²,   K1 = r1, K2 = r2² − r1²
    (3-12/14)  k1·[2r cos(β − δ)] + k2·[2r cos(φ − δ)] + k3 = r² + k4·[2 cos(β − φ)],
               k1 = r3, k2 = r5, k3 = r4² − r3² − r5², k4 = k1 k2 = λ

Stage 1 fits K by least squares (3-15)–(3-18); stage 2 writes k_p = L_p + λ m_p (3-19), fits L
and m by least squares (3-20)–(3-29) and solves k1 k2 = λ, the quadratic (3-30).  Two roots,
two linkages: we reject roots with no real solution, r4² ≤ 0, or r3 ≈ 0 (the degenerate root
that re-uses the crank dyad as the "rocker", ch3-4 notes A5), then run every surviving linkage
through the four-bar position solver (:mod:`anthroarm.mechanisms.fourbar`, both assembly
branches) and keep the one whose achieved path is closest to the target.

Units: any consistent length unit (the book's fingertip curves are in mm); angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..mechanisms.fourbar import coupler_point, fourbar_cartesian
from .optimize import simplex_book


@dataclass(frozen=True)
class FourBarDesign:
    """A path-generating four-bar in the book's §3-3 notation (see module docstring).

    ``origin`` is the crank pivot O in the target frame; ``branch`` the assembly mode (±1) of
    :func:`anthroarm.mechanisms.fourbar_cartesian` that traces the target."""

    r1: float
    r2: float
    r3: float
    r4: float
    r5: float
    beta: float
    gamma: float = 0.0
    origin: tuple = (0.0, 0.0)
    branch: int = 1

    @property
    def ground_pivot(self) -> np.ndarray:
        """D = O + r3 e^{iβ}."""
        return np.asarray(self.origin, float) + self.r3 * np.array(
            [np.cos(self.beta), np.sin(self.beta)]
        )

    @property
    def coupler_length(self) -> float:
        """|AB| = |r2 − r5 e^{iγ}| (crank-tip to rocker-joint distance on the coupler)."""
        return float(abs(self.r2 - self.r5 * np.exp(1j * self.gamma)))

    def mechanism(self):
        """``(ground_vector, crank, coupler, rocker, p, gamma_coupler)`` for
        :func:`anthroarm.mechanisms.fourbar_cartesian` and :func:`coupler_point`: C lies at
        distance p = r2 from A, at angle gamma_coupler from the coupler line A→B."""
        ground = self.ground_pivot - np.asarray(self.origin, float)
        g_c = -float(np.angle(self.r2 - self.r5 * np.exp(1j * self.gamma)))
        return ground, self.r1, self.coupler_length, self.r4, self.r2, g_c

    def trace(self, alpha, branch: int | None = None):
        """Coupler-point path for crank angles ``alpha`` (rad): ``(points (N, 2), ok (N,),
        state)``; ``ok`` is False where the linkage cannot assemble or sits at a dead point."""
        alpha = np.atleast_1d(np.asarray(alpha, dtype=float))
        ground, crank, coupler, rocker, p, g_c = self.mechanism()
        st = fourbar_cartesian(
            ground, crank, coupler, rocker, alpha, branch=self.branch if branch is None else branch
        )
        pts = coupler_point(st, p, g_c).position + np.asarray(self.origin, float)
        ok = np.atleast_1d(np.asarray(st.assembled)) & ~np.atleast_1d(np.asarray(st.dead_point))
        return pts, ok, st

    def joints(self, alpha) -> dict:
        """O, A, B, C, D positions (each (N, 2)) in the target frame, for plotting."""
        pts, _, st = self.trace(alpha)
        O = np.asarray(self.origin, float)
        th2 = np.atleast_1d(np.asarray(st.theta2, float))
        th3 = np.atleast_1d(np.asarray(st.theta3, float))
        A = O + self.r1 * np.stack([np.cos(th2), np.sin(th2)], -1)
        B = A + self.coupler_length * np.stack([np.cos(th3), np.sin(th3)], -1)
        return {
            "O": np.broadcast_to(O, A.shape),
            "A": A,
            "B": B,
            "C": pts,
            "D": np.broadcast_to(self.ground_pivot, A.shape),
        }


@dataclass
class Candidate:
    """One root of (3-30) and what became of it."""

    lam: float
    r3: float
    r4sq: float
    r5: float
    accepted: bool
    reason: str
    design: FourBarDesign | None = None
    max_error: float = float("inf")


@dataclass
class SynthesisResult:
    """Outcome of :func:`synthesize_path`.

    ``status``: ``"ok"``; ``"stage1_failed"`` (no positive r1, r2 from (3-13)); ``"no_real_root"``
    ((3-30) discriminant < 0); ``"no_valid_root"`` (every root degenerate or r4² ≤ 0);
    ``"cannot_assemble"`` (no candidate linkage assembles at every prescribed crank angle).
    ``design`` is the chosen linkage (None unless some candidate assembled); ``achieved`` its
    path at the prescribed angles; ``max_error``, ``rms_error`` the distances to the target."""

    status: str
    message: str
    design: FourBarDesign | None = None
    K: tuple = ()
    L: np.ndarray | None = None
    m: np.ndarray | None = None
    candidates: list = field(default_factory=list)
    achieved: np.ndarray | None = None
    max_error: float = float("inf")
    rms_error: float = float("inf")

    @property
    def success(self) -> bool:
        return self.status == "ok"


def _inputs(points, alpha):
    P = np.asarray(points, dtype=float)
    a = np.asarray(alpha, dtype=float)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ValueError(f"points must have shape (N, 2), got {P.shape}")
    if a.shape != (P.shape[0],):
        raise ValueError(f"alpha must have shape ({P.shape[0]},) like the points, got {a.shape}")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(a))):
        raise ValueError("points or alpha contain NaN/inf")
    if P.shape[0] < 4:
        raise ValueError(
            f"need at least 4 path points for the two least-squares stages, got {P.shape[0]}"
        )
    return P, a


def stage1(r, delta, alpha):
    """(3-15)–(3-18): normal equations for K1, K2; returns ``(K1, K2)``."""
    u = 2 * r * np.cos(delta - alpha)
    n = len(r)
    N = np.array([[u @ u, u.sum()], [u.sum(), n]])
    rhs = np.array([(r**2) @ u, (r**2).sum()])
    return tuple(np.linalg.solve(N, rhs))


def stage2(r, delta, phi, beta):
    """(3-22)–(3-29): the shared normal matrix of (3-20)/(3-21); returns ``(L, m)``."""
    a = 2 * r * np.cos(beta - delta)
    b = 2 * r * np.cos(phi - delta)
    c = 2 * np.cos(beta - phi)
    n = len(r)
    N = np.array([[a @ a, a @ b, a.sum()], [a @ b, b @ b, b.sum()], [a.sum(), b.sum(), n]])
    L = np.linalg.solve(N, np.array([(r**2) @ a, (r**2) @ b, (r**2).sum()]))
    m = np.linalg.solve(N, np.array([c @ a, c @ b, c.sum()]))
    return L, m


def lambda_roots(L, m) -> np.ndarray:
    """(3-30): real roots of ``m1 m2 λ² + (L1 m2 + L2 m1 − 1) λ + L1 L2 = 0`` (empty if none)."""
    qa, qb, qc = m[0] * m[1], L[0] * m[1] + L[1] * m[0] - 1.0, L[0] * L[1]
    scale = max(abs(qb), 1e-300)
    if abs(qa) * max(1.0, abs(qc) / scale) < 1e-14 * scale:  # degenerates to linear
        return np.array([-qc / qb]) if qb != 0 else np.array([])
    disc = qb * qb - 4 * qa * qc
    if disc < 0:
        return np.array([])
    s = np.sqrt(disc)
    return np.array([(-qb + s) / (2 * qa), (-qb - s) / (2 * qa)])


def synthesize_path(
    points, alpha, beta: float, gamma: float = 0.0, origin=(0.0, 0.0), degenerate_tol: float = 1e-6
) -> SynthesisResult:
    """Least-squares synthesis of a four-bar whose coupler point C passes through ``points``
    ((N, 2), target frame) at crank angles ``alpha`` ((N,), rad), book Eq. (3-11)–(3-30).

    ``beta`` (direction of the second ground pivot seen from O) and ``gamma`` (coupler offset of
    B from line AC; 0 in the book) are the designer's choices, as in the book; ``origin`` is the
    crank pivot.  A root with |r3| < ``degenerate_tol``·(size of the path) is the degenerate one.
    Negative r3 or r5 are normalised (β + π, γ + π).  Never raises on a linkage that cannot be
    built: the ``status`` says why (see :class:`SynthesisResult`)."""
    P, alpha = _inputs(points, alpha)
    for nm, v in (("beta", beta), ("gamma", gamma)):
        if not np.isfinite(v):
            raise ValueError(f"{nm} must be finite, got {v!r}")
    O = np.asarray(origin, dtype=float)
    if O.shape != (2,) or not np.all(np.isfinite(O)):
        raise ValueError(f"origin must be a finite 2-vector, got {origin!r}")
    z = (P[:, 0] - O[0]) + 1j * (P[:, 1] - O[1])
    r, delta = np.abs(z), np.angle(z)
    scale = float(np.max(r)) or 1.0
    try:
        K1, K2 = stage1(r, delta, alpha)
    except np.linalg.LinAlgError:
        return SynthesisResult(
            "stage1_failed",
            "stage-1 normal equations (3-17)/(3-18) are singular "
            "(crank angles or points do not vary enough)",
        )
    r2sq = K2 + K1 * K1
    if not (K1 > 0 and r2sq > 0):
        return SynthesisResult(
            "stage1_failed",
            f"(3-13) gives r1 = K1 = {K1:.6g}, r2² = {r2sq:.6g}: "
            "no crank/coupler dyad; change the crank angles or the pivot",
            K=(K1, K2),
        )
    r1, r2 = float(K1), float(np.sqrt(r2sq))
    A = r1 * np.exp(1j * alpha)
    psi = np.angle(z - A)
    phi = psi + gamma
    try:
        L, m = stage2(r, delta, phi, beta)
    except np.linalg.LinAlgError:
        return SynthesisResult(
            "no_valid_root", "stage-2 normal equations (3-23)–(3-29) are singular", K=(K1, K2)
        )
    lams = lambda_roots(L, m)
    res = SynthesisResult("no_real_root", "(3-30) has no real root", K=(K1, K2), L=L, m=m)
    if lams.size == 0:
        return res
    best = None
    for lam in lams:
        k = L + lam * m
        r3, r5 = float(k[0]), float(k[1])
        r4sq = float(k[2] + k[0] ** 2 + k[1] ** 2)
        cand = Candidate(float(lam), r3, r4sq, r5, False, "")
        res.candidates.append(cand)
        if abs(r3) < degenerate_tol * scale:
            cand.reason = (
                "degenerate: r3 ≈ 0, the rocker pivot coincides with the crank pivot "
                "(crank dyad re-used)"
            )
            continue
        if r4sq <= 0:
            cand.reason = f"r4² = {r4sq:.6g} <= 0"
            continue
        b_, g_ = beta, gamma
        if r3 < 0:
            r3, b_ = -r3, beta + np.pi
        if r5 < 0:
            r5, g_ = -r5, gamma + np.pi
        if r5 < degenerate_tol * scale and abs(r2 - r5) < degenerate_tol * scale:
            cand.reason = "degenerate: rocker joint B coincides with crank tip A"
            continue
        design_ok = None
        for br in (1, -1):
            d = FourBarDesign(
                r1, r2, r3, float(np.sqrt(r4sq)), r5, float(b_), float(g_), tuple(O), br
            )
            if d.coupler_length < 1e-12 * scale:
                break
            pts, ok, _ = d.trace(alpha)
            if not np.all(ok):
                continue
            err = np.linalg.norm(pts - P, axis=1)
            if design_ok is None or err.max() < design_ok[1].max():
                design_ok = (d, err, pts)
        if design_ok is None:
            cand.reason = "cannot assemble at every prescribed crank angle (either branch)"
            continue
        cand.accepted, cand.reason, cand.design, cand.max_error = (
            True,
            "ok",
            design_ok[0],
            float(design_ok[1].max()),
        )
        if best is None or design_ok[1].max() < best[1].max():
            best = design_ok
    if best is None:
        if any("assemble" in c.reason for c in res.candidates):
            res.status, res.message = (
                "cannot_assemble",
                "no candidate linkage assembles at every crank angle: "
                + "; ".join(c.reason for c in res.candidates),
            )
        else:
            res.status, res.message = "no_valid_root", "; ".join(c.reason for c in res.candidates)
        return res
    d, err, pts = best
    res.status, res.design, res.achieved = "ok", d, pts
    res.max_error, res.rms_error = float(err.max()), float(np.sqrt(np.mean(err**2)))
    res.message = f"max path error {res.max_error:.4g}, rms {res.rms_error:.4g}"
    return res


# ------------------------------------------------------------------ finger from a fingertip curve


@dataclass
class FingerDesign:
    """Result of :func:`design_finger_linkage`: the synthesis at the best designer choices."""

    synthesis: SynthesisResult
    params: dict
    target: np.ndarray
    alpha: np.ndarray
    outer: object = None


def curve_targets(curve, x_range, n: int = 12) -> np.ndarray:
    """``n`` equally spaced target points ``(x, curve(x))`` over ``x_range``."""
    x = np.linspace(float(x_range[0]), float(x_range[1]), int(n))
    return np.stack([x, curve(x)], axis=1)


def link_size(d: FourBarDesign) -> float:
    """Longest link or pivot offset of a design (r1 … r5, |AB|)."""
    return float(max(d.r1, d.r2, d.r3, d.r4, d.r5, d.coupler_length))


def _finger_objective(target, v, gamma_fixed):
    ox, oy, a0, da, beta = v[:5]
    gamma = v[5] if gamma_fixed is None else gamma_fixed
    alpha = a0 + da * np.linspace(0, 1, len(target))
    res = synthesize_path(target, alpha, beta, gamma, (ox, oy))
    return res, alpha


def design_finger_linkage(
    curve,
    x_range,
    x0,
    n: int = 12,
    gamma=0.0,
    maxiter: int = 600,
    span_limits=(np.deg2rad(20), np.deg2rad(150)),
    max_link: float | None = None,
) -> FingerDesign:
    """The design loop of §3-3: choose the crank pivot (ox, oy), crank start angle α0 and sweep
    Δα, and the pivot direction β (and γ if ``gamma=None``) so that the least-squares four-bar
    follows the fingertip ``curve`` over ``x_range`` with the smallest worst-case error.

    ``x0`` = (ox, oy, α0, Δα, β[, γ]) is the starting guess; the outer search is the book's
    simplex (:func:`anthroarm.design.optimize.simplex_book`) on the achieved max error (a
    linkage that fails gets a large penalty).  ``span_limits`` bounds |Δα|; ``max_link`` (same
    unit as the curve) rejects linkages with a longer link or a pivot farther from the path
    origin — a finger must fit in a finger."""
    target = curve_targets(curve, x_range, n)
    size = float(np.ptp(target, axis=0).max()) or 1.0
    x0 = np.asarray(x0, dtype=float)
    if x0.shape != ((5,) if gamma is not None else (6,)):
        raise ValueError("x0 must be (ox, oy, alpha0, dalpha, beta) [+ gamma when gamma=None]")

    def obj(v):
        if not (span_limits[0] <= abs(v[3]) <= span_limits[1]):
            return 1e3 * size
        res, _ = _finger_objective(target, v, gamma)
        if not res.success:
            return 1e3
        if max_link is not None and link_size(res.design) > max_link:
            return 1e2 + link_size(res.design) / size
        return res.max_error / size

    step = np.array([0.2 * size, 0.2 * size, 0.3, 0.2, 0.3] + ([] if gamma is not None else [0.3]))
    outer = simplex_book(obj, x0, step=step, eps1=1e-16, xtol=1e-7 * size, maxiter=maxiter)
    res, alpha = _finger_objective(target, outer.x, gamma)
    names = ["ox", "oy", "alpha0", "dalpha", "beta"] + ([] if gamma is not None else ["gamma"])
    params = dict(zip(names, map(float, outer.x)))
    if gamma is not None:
        params["gamma"] = float(gamma)
    return FingerDesign(res, params, target, alpha, outer)


def plot_path(
    result: SynthesisResult,
    target,
    alpha=None,
    ax=None,
    n_dense: int = 200,
    show_linkage: bool = True,
):
    """Target points vs the achieved coupler path (and the linkage at the first angle)."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 4))
    target = np.asarray(target, dtype=float)
    ax.plot(target[:, 0], target[:, 1], "o", mfc="none", label="target (book curve)")
    if result.design is not None and alpha is not None:
        a = np.linspace(np.min(alpha), np.max(alpha), n_dense)
        pts, ok, _ = result.design.trace(a)
        ax.plot(pts[ok, 0], pts[ok, 1], "-", label="achieved coupler path")
        ax.plot(
            result.achieved[:, 0], result.achieved[:, 1], "x", label="at prescribed crank angles"
        )
        if show_linkage:
            j = result.design.joints(np.asarray(alpha)[:1])
            chain = np.array([j["O"][0], j["A"][0], j["B"][0], j["D"][0]])
            ax.plot(chain[:, 0], chain[:, 1], "k-", lw=1.5)
            tri = np.array([j["A"][0], j["C"][0], j["B"][0]])
            ax.fill(tri[:, 0], tri[:, 1], alpha=0.2, color="k")
            ax.plot(*j["O"][0], "ks")
            ax.plot(*j["D"][0], "ks")
    ax.set_aspect("equal")
    ax.set_title(f"{result.status}: max error {result.max_error:.3g}")
    ax.legend(fontsize=8)
    return ax
