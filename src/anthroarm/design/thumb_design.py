"""Optimal design of the bionic thumb of Fig. 2-9, book §4-5 (l. 2027–2138).

The thumb is split into a lower **RRSS spatial four-bar** (phalanx R1 driven about u0, R2 hinged
to it about u2, an S–S rod B–B0 to the frame) and an upper **planar four-bar** (R2 drives R3
through a coupler).  Each part has six design variables, a minimax objective — the largest
deviation of the mechanism's joint coupling from the human curve of Ch. 3 (f2, f3 in
:mod:`anthroarm.design.motion_curves`) at n evenly spread points — ten bound constraints and one
force-transmission constraint (angle > 35°).  Units at this boundary are the book's: mm and
degrees.

What the text fixes and what we had to choose (Fig. 2-9 is missing; ch3-4 notes E8/E9):

* RRSS: a0 = 0, u0 = (0, 0, 1), a1 = (0, 30, 0), u2 = (√3/2, √3/4, −1/4); X = (B0, B initial).
  θ1 is applied as a rotation about −u0 (with +u0 the printed optimum does not follow f2 at all;
  with −u0 it does, within 0.31° up to θ1 = 20°), and the assembly branch is the one through the
  initial pose.  The transmission angle is ``φ = asin(λ·v0)`` with λ the unit rod direction
  B0→B and v0 the unit velocity direction of B about u2 (``u_a × (b − a)``).
* planar: frame with origin A, x axis along AC; P = 45(cos x1, sin x1) (crank tip, R2 = 45),
  F = (x2, x3) the coupler–rocker joint, C = (x4, 0) the fixed pivot on R1.  f = |PF| (coupler)
  and b = |CF| (rocker) are the book's undefined f and b (g1: f < R2/3, g3: b < 2R1).  θ3 is
  the rotation of the coupler (carrying R3) relative to the crank, the crank turning by +θ2
  from x1; the transmission angle is the acute angle between coupler and rocker at F (∠PFC).
  x5 = α and x6 = β do not enter θ3 in this reading (they place R2 and the fingertip S).
* Working ranges are not printed: θ1 ∈ [0°, 30°] and θ2 ∈ [0°, 30°] by default (parameters).

Findings (tests in ``tests/design/test_thumb_design.py``): the printed RRSS optimum satisfies
g1–g10 but not g11 (φ ≈ 3° at θ1 = 0 in our reading) and its error over [0°, 30°] is ≈ 0.52°,
not the printed 0.01; the printed planar optimum satisfies g1–g10 but has ∠PFC ≈ 13° (g11
fails) and its coupler of 0.79 mm makes θ3 run opposite to f3 — the printed e = 0.01 and
ε = 0.001 cannot be reproduced from the text.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..mechanisms.fourbar import fourbar_cartesian
from ..mechanisms.rrss import RRSSGeometry, rrss_efg
from . import optimize as O
from .motion_curves import THUMB_F2, THUMB_F3

D2R = np.pi / 180.0

#: §4-5 data (l. 2037): phalanx lengths (mm), initial abduction angle (deg), points and axes
R1, R2, R3 = 60.0, 45.0, 35.0
ALPHA0_DEG = 30.0
A0 = np.zeros(3)
A1 = np.array([0.0, 30.0, 0.0])
U0 = np.array([0.0, 0.0, 1.0])
U2 = np.array([np.sqrt(3) / 2, np.sqrt(3) / 4, -0.25])

#: printed results (l. 2075–2077, 2131–2133), verbatim
BOOK_RRSS_X = np.array([-2.229, -4.316, -48.326, 15.913, 15.462, -40.15])
BOOK_RRSS_E = 0.01
BOOK_PLANAR_X = np.array([157.098, -42.132, 17.918, 14.758, 159.913, 49.365])
BOOK_PLANAR_EPS = 0.001

#: bounds g1–g10 of the RRSS part (strict in the book); x2 = y_b0 is unbounded
RRSS_BOUNDS = [(-5.0, 20.0), (None, None), (-50.0, 0.0), (0.0, 20.0), (0.0, 30.0), (-50.0, -20.0)]

FAIL_ERROR = 180.0  # deg, objective value where the mechanism cannot assemble


@dataclass
class ThumbProblem:
    """One half of the thumb design: variables, objective, the book's constraints g1…g11.

    ``book_g(x)`` returns g1…g11 in the book's sign (feasible when < 0 / ≤ 0); ``ineq(x)`` the
    same constraints as SciPy-style values ≥ 0 with g11 split per sample point (smooth);
    ``errors(x)`` the signed f − F at the sample points (deg); ``objective(x)`` their max |·|."""

    name: str
    variables: tuple
    x_book: np.ndarray
    e_book: float
    inputs: np.ndarray  # sample points of the input angle, deg
    target: object  # human curve
    min_transmission: float = 35.0
    bounds: list = field(default_factory=list)

    # filled by the factory functions
    _response = None  # x -> (output angles deg, transmission deg, ok)

    def response(self, x):
        x = np.asarray(x, dtype=float)
        key = x.tobytes()
        if getattr(self, "_cache_key", None) != key:  # objective and constraints share a call
            self._cache_key, self._cache_val = key, self._response(x)
        return self._cache_val

    def errors(self, x) -> np.ndarray:
        out, _, ok = self.response(x)
        if not np.all(ok):
            return np.full(self.inputs.shape, FAIL_ERROR)
        return self.target(self.inputs) - out

    def objective(self, x) -> float:
        """Minimax error S = max_i |f(θ_i) − F(θ_i)|, deg."""
        return float(np.max(np.abs(self.errors(x))))

    def transmission(self, x) -> np.ndarray:
        _, mu, ok = self.response(x)
        return np.where(ok, mu, -90.0)

    def book_g(self, x) -> np.ndarray:
        raise NotImplementedError

    def ineq(self, x) -> np.ndarray:
        g = -self.book_g(x)[:10]
        return np.concatenate([g[np.isfinite(g)], self.transmission(x) - self.min_transmission])

    def check(self, x) -> dict:
        """``{"g1": (value, holds), …, "S": max error}`` with the book's strict inequalities."""
        g = self.book_g(x)
        rep = {
            f"g{i + 1}": (float(v), bool(v < 0 or (i == 9 and self.name == "planar" and v <= 0)))
            for i, v in enumerate(g)
            if np.isfinite(v)
        }
        rep["S"] = self.objective(x)
        rep["min_transmission"] = float(np.min(self.transmission(x)))
        return rep


# ------------------------------------------------------------------------------ RRSS part


def rrss_geometry(x) -> RRSSGeometry:
    """Geometry of the lower thumb for X = (B0, B initial), mm; θ1 about −u0 (see module doc)."""
    x = np.asarray(x, dtype=float)
    return RRSSGeometry(a0=A0, u0=-U0, a1=A1, u1=U2, b0=x[:3], b1=x[3:6])


class RRSSProblem(ThumbProblem):
    def book_g(self, x):
        x = np.asarray(x, dtype=float)
        g = [
            x[0] - 20,
            -5 - x[0],
            x[2],
            -50 - x[2],
            x[3] - 20,
            -x[3],
            x[4] - 30,
            -x[4],
            x[5] + 20,
            -50 - x[5],
        ]
        return np.array(g + [self.min_transmission - float(np.min(self.transmission(x)))])


def rrss_problem(theta1_range=(0.0, 30.0), n: int = 13, min_phi: float = 35.0) -> RRSSProblem:
    """The RRSS design problem of §4-5 (1): θ2 = F2(θ1) vs f2, g1–g10 bounds, g11: φ > 35°."""
    th1 = np.linspace(float(theta1_range[0]), float(theta1_range[1]), int(n))
    p = RRSSProblem(
        "rrss",
        ("x_b0", "y_b0", "z_b0", "x_b1", "y_b1", "z_b1"),
        BOOK_RRSS_X.copy(),
        BOOK_RRSS_E,
        th1,
        THUMB_F2,
        min_phi,
        list(RRSS_BOUNDS),
    )

    th1_all = np.concatenate([[0.0], th1]) * D2R  # the branch is fixed by the initial pose

    def response(x):
        try:
            g = rrss_geometry(x)
        except ValueError:
            return np.zeros_like(th1), np.full(th1.shape, -90.0), np.zeros(th1.shape, bool)
        # closed form (6-93)-(6-99) via the mechanisms' E, F, G; position only (fast)
        E, F, G, a, bp, ua = rrss_efg(g, th1_all)
        disc = E * E + F * F - G * G
        ok = disc >= -1e-12 * g.length_scale**4
        root = np.sqrt(np.clip(disc, 0.0, None))
        cands = [2 * np.arctan2(-F + s * root, G - E) for s in (1, -1)]
        cands = [np.mod(c + np.pi, 2 * np.pi) - np.pi for c in cands]
        t2 = min(cands, key=lambda c: abs(c[0]))  # the branch through theta2 = 0 at theta1 = 0
        e = bp - a
        c, s_ = np.cos(t2)[:, None], np.sin(t2)[:, None]
        b = (
            a + e * c + np.cross(ua, e) * s_ + ua * np.sum(ua * e, axis=1)[:, None] * (1 - c)
        )  # (6-96)
        lam = b - g.b0
        lam = lam / np.linalg.norm(lam, axis=-1, keepdims=True)
        v = np.cross(ua, b - a)
        v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)
        phi = np.arcsin(np.clip(np.sum(lam * v, axis=1), -1, 1)) / D2R
        return t2[1:] / D2R, phi[1:], ok[1:] & (abs(t2[0]) < 1e-6)

    p._response = response
    return p


# ------------------------------------------------------------------------------ planar part


def planar_points(x):
    """P, F, C (mm) of the upper thumb in the frame A = 0, AC = +x, for X = (∠PAC, x_f, y_f, x_c, α,
    β)."""
    x = np.asarray(x, dtype=float)
    P = R2 * np.array([np.cos(x[0] * D2R), np.sin(x[0] * D2R)])
    return P, np.array([x[1], x[2]]), np.array([x[3], 0.0])


class PlanarProblem(ThumbProblem):
    def book_g(self, x):
        x = np.asarray(x, dtype=float)
        P, F, C = planar_points(x)
        f, b = np.linalg.norm(F - P), np.linalg.norm(F - C)
        g = [
            f - R2 / 3,
            -f,
            b - 2 * R1,
            -b,
            x[4] - 180,
            -x[4],
            x[5] - 180,
            -x[5],
            -x[2],
            x[1] - R2 * np.cos(x[0] * D2R),
        ]
        return np.array(g + [self.min_transmission - float(np.min(self.transmission(x)))])


def planar_problem(theta2_range=(0.0, 30.0), n: int = 13, min_mu: float = 35.0) -> PlanarProblem:
    """The planar four-bar design problem of §4-5 (2): θ3 = F3(θ2) vs f3, g1–g10, g11: ∠PFC >
    35°."""
    th2 = np.linspace(float(theta2_range[0]), float(theta2_range[1]), int(n))
    p = PlanarProblem(
        "planar",
        ("angle_PAC", "x_f", "y_f", "x_c", "alpha", "beta"),
        BOOK_PLANAR_X.copy(),
        BOOK_PLANAR_EPS,
        th2,
        THUMB_F3,
        min_mu,
        [(0.0, 360.0), (None, None), (0.0, None), (None, None), (0.0, 180.0), (0.0, 180.0)],
    )

    def response(x):
        P, F, C = planar_points(x)
        f, b = np.linalg.norm(F - P), np.linalg.norm(F - C)
        bad = (np.zeros_like(th2), np.full(th2.shape, -90.0), np.zeros(th2.shape, bool))
        if f <= 1e-9 or b <= 1e-9 or abs(x[3]) <= 1e-9:
            return bad
        ang = x[0] * D2R + th2 * D2R
        best = None
        for br in (1, -1):
            st = fourbar_cartesian(C, R2, f, b, ang, branch=br)
            th3 = np.atleast_1d(np.asarray(st.theta3, float))
            F0 = P + f * np.array([np.cos(th3[0]), np.sin(th3[0])])
            if np.linalg.norm(F0 - F) < 1e-6 * (1 + np.linalg.norm(F)):
                best = st
                break
        if best is None:
            return bad
        ok = np.atleast_1d(np.asarray(best.status) == "ok")
        rel = np.unwrap(np.atleast_1d(np.asarray(best.theta3, float)) - ang)
        t3 = (rel - rel[0]) / D2R
        mu = np.atleast_1d(np.asarray(best.transmission_angle, float)) / D2R
        mu = np.minimum(mu, 180.0 - mu)
        return t3, mu, ok

    p._response = response
    return p


# ------------------------------------------------------------------------------ re-optimisation


@dataclass
class DesignOutcome:
    """One row of the comparison table."""

    method: str
    x: np.ndarray
    S: float
    min_transmission: float
    feasible: bool
    status: str
    nfev: int
    seconds: float


def _feasible(problem, x, tol=1e-3):
    """All constraints hold within ``tol`` (mm or deg; the exterior method approaches from
    outside)."""
    return bool(np.all(problem.ineq(x) >= -tol))


def optimise(problem: ThumbProblem, method: str = "sumt_exterior", x0=None, **kw) -> DesignOutcome:
    """Re-optimise a thumb problem with the book's methods or SLSQP.

    ``method``: ``"sumt_exterior"`` (book simplex inside, any start), ``"sumt_mixed"`` /
    ``"sumt_interior"`` (need a strictly feasible start; phase 1 searches one), ``"simplex"``
    (book simplex on a fixed exterior penalty), ``"slsqp"`` (epigraph form min t s.t.
    t ≥ |f − F|_i, the bounds and the per-point transmission constraints)."""
    from scipy.optimize import minimize

    x0 = problem.x_book.copy() if x0 is None else np.asarray(x0, dtype=float)
    t0 = time.perf_counter()
    if method in ("sumt_exterior", "sumt_interior", "sumt_mixed"):
        fn = {
            "sumt_exterior": O.sumt_exterior,
            "sumt_interior": O.sumt_interior,
            "sumt_mixed": O.sumt_mixed,
        }[method]
        opts = dict(scale=10.0, max_stages=kw.pop("max_stages", 12))
        if method == "sumt_exterior":
            opts.update(eps1=1e-4)
        r = fn(problem.objective, x0, problem.ineq, **opts, **kw)
        x, status, nfev = r.x, r.status, r.nfev
    elif method == "simplex":
        M = kw.pop("M", 1e3)
        phi = lambda z: (
            problem.objective(z) + M * float(np.sum(np.minimum(0, problem.ineq(z)) ** 2))
        )  # noqa: E731
        r = O.simplex_book(
            phi, x0, step=np.maximum(0.1 * np.abs(x0), 1.0), eps1=1e-14, maxiter=4000
        )
        x, status, nfev = r.x, r.status, r.nfev
    elif method == "slsqp":
        z0 = np.append(x0, problem.objective(x0))
        cons = [
            {"type": "ineq", "fun": lambda z: z[-1] - problem.errors(z[:-1])},
            {"type": "ineq", "fun": lambda z: z[-1] + problem.errors(z[:-1])},
            {"type": "ineq", "fun": lambda z: problem.ineq(z[:-1])},
        ]
        r = minimize(
            lambda z: z[-1],
            z0,
            method="SLSQP",
            constraints=cons,
            options={"maxiter": kw.pop("maxiter", 300), "ftol": 1e-10},
        )
        x, status, nfev = r.x[:-1], ("converged" if r.success else f"scipy: {r.message}"), r.nfev
    else:
        raise ValueError(
            f"unknown method {method!r}; use sumt_exterior, sumt_interior, sumt_mixed, simplex, "
            "slsqp"
        )
    dt = time.perf_counter() - t0
    return DesignOutcome(
        method,
        np.asarray(x, float),
        problem.objective(x),
        float(np.min(problem.transmission(x))),
        _feasible(problem, x),
        status,
        int(nfev),
        dt,
    )


def comparison_table(
    problem: ThumbProblem, methods=("sumt_exterior", "sumt_mixed", "slsqp"), x0=None
) -> list:
    """The printed optimum and each method's result as rows of :class:`DesignOutcome`."""
    xb = problem.x_book
    rows = [
        DesignOutcome(
            "book (printed)",
            xb,
            problem.objective(xb),
            float(np.min(problem.transmission(xb))),
            _feasible(problem, xb),
            f"printed e = {problem.e_book:g}",
            0,
            0.0,
        )
    ]
    for m in methods:
        rows.append(optimise(problem, m, x0))
    return rows


def markdown(rows) -> str:
    """Comparison table as markdown: method, x, S (deg), min transmission (deg), feasible, nfev,
    s."""
    head = (
        "| method | x | S (deg) | min transmission (deg) | feasible | status | nfev | time (s) |\n"
        "|---|---|---|---|---|---|---|---|\n"
    )
    lines = [
        f"| {r.method} | {np.array2string(r.x, precision=3, separator=', ')} | {r.S:.4f} | "
        f"{r.min_transmission:.1f} | {r.feasible} | {r.status} | {r.nfev} | {r.seconds:.2f} |"
        for r in rows
    ]
    return head + "\n".join(lines)
