"""Human motion curves and curve fitting, book Ch. 3 (§3-2).

* The fitted curves the book prints (l. 1077–1089) as a reference-motion library:
  fingertip path of the power grasp (握取, cubic) and of the three-finger pinch (抓取,
  quadratic), in mm in the finger's plane; thumb joint coupling θ2 = f2(θ1) and θ3 = f3(θ2),
  in degrees.  The measured points (Fig. 3-3 … 3-6) were not preserved, only the coefficients.
* The difference-table degree test (表差法, l. 991–1049): for equally spaced x the k-th
  differences of a degree-k polynomial are constant (Δ^k y = k! a_k Δx^k).
* Least-squares polynomial fitting (曲线拟合法) through the normal equations (3-2)–(3-6), with
  the book's error measures: residuals V_i = φ(x_i) − y_i (3-2), S = Σ V_i² (3-4) and the
  "mean error" (平均误差) of Fig. 3-6, read as the mean absolute residual (the book does not
  define it).
* Piecewise-linear joint coordination (Fig. 3-9, l. 1109–1114): each joint angle against the
  elbow angle θ1 over three straight segments A–B, B–C, C–D, fitted continuously by least squares.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import Polynomial


@dataclass(frozen=True)
class ReferenceCurve:
    """A fitted human-motion curve ``y = Σ c_k x^k`` (``coeffs`` ascending), as printed."""

    name: str
    coeffs: tuple[float, ...]
    x_name: str
    y_name: str
    unit: str
    source: str
    mean_error: float | None = None

    @property
    def poly(self) -> Polynomial:
        return Polynomial(self.coeffs)

    def __call__(self, x):
        return self.poly(np.asarray(x, dtype=float))

    def derivative(self, x):
        return self.poly.deriv()(np.asarray(x, dtype=float))

    def stationary_points(self) -> np.ndarray:
        """Real roots of dy/dx, sorted."""
        r = self.poly.deriv().roots()
        return np.sort(r[np.abs(r.imag) < 1e-12].real)


#: l. 1077: power-grasp (握取) fingertip path, y = f(x), mm.
FINGERTIP_POWER_GRASP = ReferenceCurve(
    "fingertip power grasp f(x)", (55.61, 1.133, -1.707e-2, 0.22e-4), "x", "y", "mm", "000 l.1077"
)
#: l. 1081: three-finger pinch (抓取) fingertip path, y = g(x), mm.
FINGERTIP_PINCH = ReferenceCurve(
    "fingertip pinch g(x)", (18.7688, 1.35, -0.0584), "x", "y", "mm", "000 l.1081"
)
#: l. 1089: thumb MP angle against CM angle during the power grasp, degrees; mean error 0.271.
THUMB_F2 = ReferenceCurve(
    "thumb theta2 = f2(theta1)",
    (-37.030e-3, 366.517e-3, -8.373e-3, 0.1297e-3),
    "theta1",
    "theta2",
    "deg",
    "000 l.1089, Fig. 3-6(a)",
    mean_error=0.271,
)
#: l. 1089: thumb IP angle against MP angle, degrees; mean error 0.744.
THUMB_F3 = ReferenceCurve(
    "thumb theta3 = f3(theta2)",
    (27.533e-2, 92.657e-2, 10.027e-2, -0.232e-2),
    "theta2",
    "theta3",
    "deg",
    "000 l.1089, Fig. 3-6(b)",
    mean_error=0.744,
)

LIBRARY = {
    "power_grasp": FINGERTIP_POWER_GRASP,
    "pinch": FINGERTIP_PINCH,
    "thumb_f2": THUMB_F2,
    "thumb_f3": THUMB_F3,
}


def _xy(x, y):
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.ndim != 1 or y.shape != x.shape:
        raise ValueError(f"x and y must be 1-D of equal length, got shapes {x.shape} and {y.shape}")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("x or y contains NaN/inf")
    return x, y


# ----------------------------------------------------------------- difference table


def difference_table(y, max_order: int | None = None) -> list[np.ndarray]:
    """``[y, Δy, Δ²y, …]`` with ``Δ^{k+1} y_i = Δ^k y_{i+1} − Δ^k y_i`` (l. 1001–1013)."""
    y = np.asarray(y, dtype=float)
    if y.ndim != 1 or not np.all(np.isfinite(y)):
        raise ValueError("y must be a finite 1-D array")
    top = len(y) - 1 if max_order is None else min(int(max_order), len(y) - 1)
    out = [y]
    for _ in range(top):
        out.append(np.diff(out[-1]))
    return out


def detect_degree(
    x, y, rtol: float = 1e-6, atol: float | None = None, max_degree: int | None = None
) -> int:
    """Difference-table degree test (表差法): the smallest k whose k-th differences are
    constant, i.e. ``ptp(Δ^k y) <= max(rtol·|mean Δ^k y|, atol)`` with at least two of them.

    ``x`` must be equally spaced (the method needs a fixed Δx).  ``atol`` defaults to
    ``1e-9·max|y|``.  Raises ``ValueError`` if no order up to ``max_degree`` (default n − 2)
    qualifies — the data are too noisy for the tolerance, or not polynomial."""
    x, y = _xy(x, y)
    if len(x) < 3:
        raise ValueError("need at least 3 samples")
    dx = np.diff(x)
    if np.any(dx <= 0) or np.ptp(dx) > 1e-9 * abs(dx.mean()):
        raise ValueError(
            "x must be strictly increasing with a constant step (difference-table method)"
        )
    atol = 1e-9 * max(np.max(np.abs(y)), 1e-300) if atol is None else float(atol)
    top = len(y) - 2 if max_degree is None else min(int(max_degree), len(y) - 2)
    for k, d in enumerate(difference_table(y, top)):
        if np.ptp(d) <= max(rtol * abs(d.mean()), atol):
            return k
    raise ValueError(
        f"no difference order <= {top} is constant within rtol={rtol:g}, atol={atol:g}; "
        "raise the tolerance (noisy data) or fit a chosen degree"
    )


# ----------------------------------------------------------------- least squares


@dataclass(frozen=True)
class PolyFit:
    """Least-squares polynomial: ``coeffs`` ascending; ``residuals`` V_i (3-2); ``S`` (3-4);
    ``mean_error`` = mean |V_i| (the book's 平均误差); ``max_error``; ``rms``."""

    coeffs: np.ndarray
    residuals: np.ndarray
    S: float
    mean_error: float
    max_error: float
    rms: float

    @property
    def degree(self) -> int:
        return len(self.coeffs) - 1

    def __call__(self, x):
        return Polynomial(self.coeffs)(np.asarray(x, dtype=float))


def error_metrics(pred, y) -> dict:
    """Book error measures of a fit: V = pred − y (3-2), S (3-4), mean |V|, max |V|, rms."""
    v = np.asarray(pred, dtype=float) - np.asarray(y, dtype=float)
    return dict(
        residuals=v,
        S=float(v @ v),
        mean_error=float(np.mean(np.abs(v))),
        max_error=float(np.max(np.abs(v))),
        rms=float(np.sqrt(np.mean(v**2))),
    )


def normal_equations(x, y, degree: int):
    """The normal equations (3-6) for a polynomial: ``N a = r`` with
    ``N_jk = Σ x_i^{j+k}``, ``r_j = Σ y_i x_i^j`` (j, k = 0..m)."""
    x, y = _xy(x, y)
    p = np.arange(2 * degree + 1)
    sums = (x[:, None] ** p[None, :]).sum(axis=0)
    N = sums[np.add.outer(np.arange(degree + 1), np.arange(degree + 1))]
    r = (y[:, None] * x[:, None] ** np.arange(degree + 1)[None, :]).sum(axis=0)
    return N, r


def fit_polynomial(x, y, degree: int) -> PolyFit:
    """Least-squares polynomial of the given degree, Eq. (3-1)–(3-6).

    Solves the normal equations (3-6) in the scaled variable ``t = (x − c)/s`` (same minimiser,
    far better conditioned than raw powers of x) and maps the coefficients back to x."""
    x, y = _xy(x, y)
    degree = int(degree)
    if degree < 0 or len(x) < degree + 1:
        raise ValueError(
            f"need degree >= 0 and at least degree+1 = {degree + 1} samples, got {len(x)}"
        )
    c, s = x.mean(), (np.ptp(x) / 2 or 1.0)
    t = (x - c) / s
    N, r = normal_equations(t, y, degree)
    try:
        a_t = np.linalg.solve(N, r)
    except np.linalg.LinAlgError:
        raise ValueError("normal equations are singular: fewer distinct x than degree+1") from None
    coeffs = Polynomial(a_t)(Polynomial([-c / s, 1 / s])).coef
    coeffs = np.pad(coeffs, (0, degree + 1 - len(coeffs)))
    m = error_metrics(Polynomial(coeffs)(x), y)
    return PolyFit(coeffs, m["residuals"], m["S"], m["mean_error"], m["max_error"], m["rms"])


def fit_curve(x, y, rtol: float = 1e-6, atol: float | None = None, max_degree: int = 6) -> PolyFit:
    """The book's two-step pipeline: difference table -> degree, then least squares."""
    return fit_polynomial(x, y, detect_degree(x, y, rtol=rtol, atol=atol, max_degree=max_degree))


def sample_curve(curve: ReferenceCurve, lo: float, hi: float, n: int = 21):
    """Equally spaced samples ``(x, y)`` of a reference curve."""
    x = np.linspace(lo, hi, int(n))
    return x, curve(x)


# ----------------------------------------------------------------- piecewise coordination


@dataclass(frozen=True)
class PiecewiseLinear:
    """Continuous piecewise-linear function through ``(knots, values)``; ``S`` and
    ``mean_error`` of the fit that produced it."""

    knots: np.ndarray
    values: np.ndarray
    S: float = float("nan")
    mean_error: float = float("nan")

    def __call__(self, x):
        x = np.asarray(x, dtype=float)
        k, v = self.knots, self.values
        slope_l = (v[1] - v[0]) / (k[1] - k[0])
        slope_r = (v[-1] - v[-2]) / (k[-1] - k[-2])
        y = np.interp(x, k, v)
        y = np.where(x < k[0], v[0] + slope_l * (x - k[0]), y)
        return np.where(x > k[-1], v[-1] + slope_r * (x - k[-1]), y)

    @property
    def slopes(self) -> np.ndarray:
        return np.diff(self.values) / np.diff(self.knots)


def _pwl_lstsq(x, y, knots):
    # hat-function basis on the knots: continuous piecewise-linear least squares
    B = np.stack([np.interp(x, knots, np.eye(len(knots))[j]) for j in range(len(knots))], axis=1)
    vals, *_ = np.linalg.lstsq(B, y, rcond=None)
    pred = B @ vals
    return vals, float(np.sum((pred - y) ** 2)), float(np.mean(np.abs(pred - y)))


def fit_piecewise_linear(
    x, y, n_segments: int = 3, breakpoints=None, candidates: int = 60
) -> PiecewiseLinear:
    """Continuous piecewise-linear least squares (Fig. 3-9: segments A–B, B–C, C–D).

    With ``breakpoints`` given (interior knots) only the values are fitted; otherwise the
    interior knots are searched exhaustively over ``candidates`` positions between the data
    and the best (smallest S) kept."""
    x, y = _xy(x, y)
    order = np.argsort(x)
    x, y = x[order], y[order]
    lo, hi = x[0], x[-1]
    if hi <= lo:
        raise ValueError("x must span a non-empty range")
    if breakpoints is not None:
        bp = np.sort(np.asarray(breakpoints, dtype=float))
        if np.any(bp <= lo) or np.any(bp >= hi):
            raise ValueError(f"breakpoints must lie strictly inside ({lo:g}, {hi:g})")
        knots = np.concatenate([[lo], bp, [hi]])
        vals, S, me = _pwl_lstsq(x, y, knots)
        return PiecewiseLinear(knots, vals, S, me)
    n_segments = int(n_segments)
    if n_segments < 1 or len(x) < n_segments + 1:
        raise ValueError(f"need n_segments >= 1 and at least n_segments+1 samples, got {len(x)}")
    if n_segments == 1:
        return fit_piecewise_linear(x, y, breakpoints=[])
    grid = np.linspace(lo, hi, int(candidates) + 2)[1:-1]
    best = None
    for bp in itertools.combinations(grid, n_segments - 1):
        knots = np.concatenate([[lo], bp, [hi]])
        vals, S, me = _pwl_lstsq(x, y, knots)
        if best is None or S < best.S:
            best = PiecewiseLinear(knots, vals, S, me)
    # polish: local refinement of the knots on a finer grid around the best
    h = (hi - lo) / (int(candidates) + 1)
    for _ in range(2):
        local = [
            np.clip(np.linspace(b - h, b + h, 9), lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))
            for b in best.knots[1:-1]
        ]
        for bp in itertools.product(*local):
            if np.any(np.diff(bp) <= 0):
                continue
            knots = np.concatenate([[lo], bp, [hi]])
            vals, S, me = _pwl_lstsq(x, y, knots)
            if S < best.S:
                best = PiecewiseLinear(knots, vals, S, me)
        h /= 4
    return best


@dataclass
class JointCoordination:
    """Joint angles as piecewise-linear functions of a master angle (the elbow θ1, Fig. 3-9)."""

    master: str
    segments: dict[str, PiecewiseLinear] = field(default_factory=dict)

    def __call__(self, theta1) -> dict[str, np.ndarray]:
        return {k: f(theta1) for k, f in self.segments.items()}


def coordinate_joints(
    theta1, joints: dict, n_segments: int = 3, master: str = "theta1", breakpoints=None
) -> JointCoordination:
    """Fit every joint of ``joints`` (name -> samples) against ``theta1`` with ``n_segments``
    straight segments; a shared ``breakpoints`` list imposes the book's common A, B, C, D."""
    out = JointCoordination(master)
    for name, vals in joints.items():
        out.segments[name] = fit_piecewise_linear(theta1, vals, n_segments, breakpoints)
    return out
