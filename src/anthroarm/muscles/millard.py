"""OpenSim's ``Millard2012EquilibriumMuscle``: its curves and its static equilibrium.

Millard, Uchida, Seth & Delp, *Flexing computational muscle: modeling and simulation of
musculotendon dynamics*, J Biomech Eng 135(2) (2013) 021005, as opensim-core 4.x implements
it (``OpenSim/Actuators/Millard2012EquilibriumMuscle.cpp``, read to understand and rewritten
here).  Every curve is a ``SmoothSegmentedFunction``: C²-continuous quintic Bézier segments
between "corners" (``SegmentedQuinticBezierToolkit::calcQuinticBezierCornerControlPoints``:
the corner where the tangent lines at both ends meet, control points at ``curviness`` of the
way to it), extrapolated linearly outside (``SmoothSegmentedFunctionFactory.cpp``):

* :func:`active_force_length_curve` (``createFiberActiveForceLengthCurve``): five segments from
  ``min_norm_active_fiber_length`` (0.4441) through the shallow ascending limb (slope 0.8616 to
  0.73) to 1 at l̃ = 1 and down to ``max_norm_active_fiber_length`` (1.8123), floored at
  ``minimum_value`` (0.1), curviness 1 (after Gollapudi & Lin, *Experimental determination
  of sarcomere force-length relationship in type-I human skeletal muscle fibers*, J Biomech
  42 (2009) 2011-2016);
* :func:`force_velocity_curve` (``createFiberForceVelocityCurve``): four segments through
  (−1, 0), (−0.9, ·), (0, 1), (0.9, ·), (1, 1.4), isometric slope 5;
* :func:`fiber_force_length_curve` (``createFiberForceLengthCurve``): passive, 0 at strain
  ``strain_at_zero_force`` (0) to 1 at ``strain_at_one_norm_force`` (0.7), stiffness 0.2 at low
  force and 2/(e₁ − e₀) at one, curviness 0.75 (the values ``FiberForceLengthCurve`` fills in,
  after Thelen 2003 and the passive curve of Winters, Takahashi, Ward & Lieber, *Whole muscle
  length-tension relationships are accurately modeled as scaled sarcomeres in rabbit
  hindlimb muscles*, J Biomech 44 (2011) 109-115);
* :func:`tendon_force_length_curve` (``createTendonForceLengthCurve``): 0 at slack, toe to
  2/3 at the end of the toe, then linear with stiffness 1.375/e₀ to 1 at strain e₀ = 0.049
  (curviness 0.5: ``TendonForceLengthCurve``'s fitted defaults).

A Bézier segment is a parametric curve (x(u), y(u)); y(x) is found by solving x(u) = x for u
(bisection, then Newton to machine precision; OpenSim's ``calcU`` stops at 1e2 ε) and
dy/dx = y'(u)/x'(u).

OpenSim adjusts some properties when the model is finalised
(:func:`finalized_params`): with fibre damping (the default, 0.1) or a rigid tendon the active
curve's minimum becomes 0 and the force-velocity slopes at vmax 0; the classic undamped model
with an elastic tendon raises them (to 0.1 and half the slopes near vmax).

Pennation: ``MuscleFixedWidthPennationModel`` (constant parallelogram height l₀ sin φ₀; Zajac
1989).  The fibre's minimum length is the longer of the minimum active length and the length
at the maximum pennation angle (``m_minimumFiberLength``).

Static equilibrium (``computeFiberEquilibrium`` → ``estimateMuscleFiberState`` with zero
lengthening speed: fibre velocity 0, f_V = 1, no damping force): the fibre length at which
F₀ (a f_L(l̃) + f_PE(l̃)) cos φ = F₀ f_SE(l_T / l_s), by OpenSim's damped Newton iteration from
a tendon 1 % longer than slack, continued here to 1e-11 F₀ (OpenSim stops at 1e-8 F₀).  A
rigid tendon (``ignore_tendon_compliance``): the tendon at slack length.  A fibre at its
minimum length and not lengthening is clamped: no fibre force (``isFiberStateClamped``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MuscleError

EPS = np.finfo(float).eps
SIGNIFICANT = EPS**0.875  # SimTK::SignificantReal
SQRT_EPS = np.sqrt(EPS)
_BINOM5 = np.array([1.0, 5.0, 10.0, 10.0, 5.0, 1.0])
_BINOM4 = np.array([1.0, 4.0, 6.0, 4.0, 1.0])

#: the Millard2012EquilibriumMuscle properties with OpenSim 4's defaults
MILLARD_DEFAULTS = {
    "fiber_damping": 0.1,
    "minimum_activation": 0.01,
    "maximum_pennation_angle": float(np.arccos(0.1)),
    "activation_time_constant": 0.01,
    "deactivation_time_constant": 0.04,
    "default_activation": 0.05,
}
#: the curves' properties with their defaults (None: filled in from the others, as OpenSim)
CURVE_DEFAULTS = {
    "ActiveForceLengthCurve": {
        "min_norm_active_fiber_length": 0.47 - 0.0259,
        "transition_norm_fiber_length": 0.73,
        "max_norm_active_fiber_length": 1.8123,
        "shallow_ascending_slope": 0.8616,
        "minimum_value": 0.1,
    },
    "ForceVelocityCurve": {
        "concentric_slope_at_vmax": 0.0,
        "concentric_slope_near_vmax": 0.25,
        "isometric_slope": 5.0,
        "eccentric_slope_at_vmax": 0.0,
        "eccentric_slope_near_vmax": 0.15,
        "max_eccentric_velocity_force_multiplier": 1.4,
        "concentric_curviness": 0.6,
        "eccentric_curviness": 0.9,
    },
    "FiberForceLengthCurve": {
        "strain_at_zero_force": 0.0,
        "strain_at_one_norm_force": 0.7,
        "stiffness_at_low_force": None,
        "stiffness_at_one_norm_force": None,
        "curviness": None,
    },
    "TendonForceLengthCurve": {
        "strain_at_one_norm_force": 0.049,
        "stiffness_at_one_norm_force": None,
        "norm_force_at_toe_end": None,
        "curviness": None,
    },
}


def _corner(x0, y0, dydx0, x1, y1, dydx1, curviness):
    """``calcQuinticBezierCornerControlPoints``: the six control points (x (6,), y (6,)) of
    the segment from (x0, y0) with slope dydx0 to (x1, y1) with slope dydx1."""
    if abs(dydx0 - dydx1) > SQRT_EPS:
        xc = (y1 - y0 - x1 * dydx1 + x0 * dydx0) / (dydx0 - dydx1)
    else:
        xc = (x1 + x0) / 2.0
    yc = (xc - x1) * dydx1 + y1
    x0m, y0m = x0 + curviness * (xc - x0), y0 + curviness * (yc - y0)
    x1m, y1m = x1 + curviness * (xc - x1), y1 + curviness * (yc - y1)
    return np.array([x0, x0m, x0m, x1m, x1m, x1]), np.array([y0, y0m, y0m, y1m, y1m, y1])


def _scale_curviness(c):
    return 0.1 + 0.8 * c


def _bezier(u, P):
    """Value of the quintic Bézier with control points P (..., 6) at u (...)."""
    k = np.arange(6)
    basis = _BINOM5 * (1.0 - u[..., None]) ** (5 - k) * u[..., None] ** k
    return np.sum(basis * P, axis=-1)


def _bezier_du(u, P):
    k = np.arange(5)
    basis = _BINOM4 * (1.0 - u[..., None]) ** (4 - k) * u[..., None] ** k
    return 5.0 * np.sum(basis * np.diff(P, axis=-1), axis=-1)


@dataclass(frozen=True, eq=False)
class SmoothSegmentedFunction:
    """A curve of quintic Bézier segments (control points ``cx``, ``cy`` of shape (n, 6)),
    linear outside [x0, x1] (value y0 / y1, slope dydx0 / dydx1)."""

    cx: np.ndarray
    cy: np.ndarray
    x0: float
    x1: float
    y0: float
    y1: float
    dydx0: float
    dydx1: float

    def __call__(self, x):
        return self.eval(x)[0]

    def eval(self, x):
        """(y, dy/dx) at x (any shape)."""
        x = np.asarray(x, dtype=float)
        flat = x.reshape(-1)
        y = np.empty_like(flat)
        d = np.empty_like(flat)
        lo, hi = flat < self.x0, flat > self.x1
        y[lo], d[lo] = self.y0 + self.dydx0 * (flat[lo] - self.x0), self.dydx0
        y[hi], d[hi] = self.y1 + self.dydx1 * (flat[hi] - self.x1), self.dydx1
        mid = ~(lo | hi)
        if np.any(mid):
            xm = flat[mid]
            idx = np.clip(np.searchsorted(self.cx[:, 0], xm, side="right") - 1, 0, len(self.cx) - 1)
            PX, PY = self.cx[idx], self.cy[idx]
            up = PX[:, 5] >= PX[:, 0]
            a, b = np.zeros_like(xm), np.ones_like(xm)
            for _ in range(40):  # bisection: x(u) is monotonic on each segment
                m = 0.5 * (a + b)
                below = (_bezier(m, PX) < xm) == up
                a, b = np.where(below, m, a), np.where(below, b, m)
            u = 0.5 * (a + b)
            for _ in range(3):  # Newton: to machine precision
                dx = _bezier_du(u, PX)
                ok = np.abs(dx) > 0
                u = np.clip(
                    u - np.where(ok, (_bezier(u, PX) - xm) / np.where(ok, dx, 1.0), 0), 0, 1
                )
            y[mid] = _bezier(u, PY)
            d[mid] = _bezier_du(u, PY) / _bezier_du(u, PX)
        return y.reshape(x.shape), d.reshape(x.shape)


def _function(segments, x0, x1, y0, y1, dydx0, dydx1):
    cx = np.array([s[0] for s in segments])
    cy = np.array([s[1] for s in segments])
    return SmoothSegmentedFunction(cx, cy, x0, x1, y0, y1, dydx0, dydx1)


def active_force_length_curve(
    min_norm_active_fiber_length=0.4441,
    transition_norm_fiber_length=0.73,
    max_norm_active_fiber_length=1.8123,
    shallow_ascending_slope=0.8616,
    minimum_value=0.1,
    curviness=1.0,
):
    """``createFiberActiveForceLengthCurve`` (x0, x1, x2 = 1, x3, ylow, dydx, curviness)."""
    x0, x1, x2, x3 = (
        min_norm_active_fiber_length,
        transition_norm_fiber_length,
        1.0,
        max_norm_active_fiber_length,
    )
    ylow, dydx = minimum_value, shallow_ascending_slope
    if not (x0 >= 0 and x1 > x0 + SQRT_EPS and x2 > x1 + SQRT_EPS and x3 > x2 + SQRT_EPS):
        raise MuscleError(f"active force-length curve: need 0 <= {x0} < {x1} < 1 < {x3}")
    if not (ylow >= 0 and 0 <= dydx < (1 - ylow) / (x2 - x1)):
        raise MuscleError(f"active force-length curve: minimum {ylow} or slope {dydx} invalid")
    c = _scale_curviness(curviness)
    x_delta = 0.05 * x2
    xs = x2 - x_delta
    y0, dydx0 = 0.0, 0.0
    y1 = 1 - dydx * (xs - x1)
    dydx01 = 1.25 * (y1 - y0) / (x1 - x0)
    x01, y01 = x0 + 0.5 * (x1 - x0), y0 + 0.5 * (y1 - y0)
    x1s, y1s = x1 + 0.5 * (xs - x1), y1 + 0.5 * (1 - y1)
    y2, dydx2, y3, dydx3 = 1.0, 0.0, 0.0, 0.0
    x23 = (x2 + x_delta) + 0.5 * (x3 - (x2 + x_delta))
    y23 = y2 + 0.5 * (y3 - y2)
    dydx23 = (y3 - y2) / ((x3 - x_delta) - (x2 + x_delta))
    segs = [
        _corner(x0, ylow, dydx0, x01, y01, dydx01, c),
        _corner(x01, y01, dydx01, x1s, y1s, dydx, c),
        _corner(x1s, y1s, dydx, x2, y2, dydx2, c),
        _corner(x2, y2, dydx2, x23, y23, dydx23, c),
        _corner(x23, y23, dydx23, x3, ylow, dydx3, c),
    ]
    return _function(segs, x0, x3, ylow, ylow, 0.0, 0.0)


def force_velocity_curve(
    concentric_slope_at_vmax=0.0,
    concentric_slope_near_vmax=0.25,
    isometric_slope=5.0,
    eccentric_slope_at_vmax=0.0,
    eccentric_slope_near_vmax=0.15,
    max_eccentric_velocity_force_multiplier=1.4,
    concentric_curviness=0.6,
    eccentric_curviness=0.9,
):
    """``createFiberForceVelocityCurve``: f_V of the normalised fibre velocity (−1 at the
    maximum shortening velocity)."""
    fmax_e, dydx_c, dydx_near_c = (
        max_eccentric_velocity_force_multiplier,
        concentric_slope_at_vmax,
        concentric_slope_near_vmax,
    )
    dydx_iso, dydx_e, dydx_near_e = (
        isometric_slope,
        eccentric_slope_at_vmax,
        eccentric_slope_near_vmax,
    )
    if not (fmax_e > 1 and 0 <= dydx_c < 1 and dydx_c < dydx_near_c <= 1 and dydx_iso > 1):
        raise MuscleError("force-velocity curve: slopes or eccentric multiplier out of range")
    if not (0 <= dydx_e < fmax_e - 1 and dydx_e <= dydx_near_e < fmax_e - 1):
        raise MuscleError("force-velocity curve: eccentric slopes out of range")
    cc, ce = _scale_curviness(concentric_curviness), _scale_curviness(eccentric_curviness)
    xc, yc, xnc = -1.0, 0.0, -0.9
    ync = yc + 0.5 * dydx_near_c * (xnc - xc) + 0.5 * dydx_c * (xnc - xc)
    xi, yi, xe, ye, xne = 0.0, 1.0, 1.0, fmax_e, 0.9
    yne = ye + 0.5 * dydx_near_e * (xne - xe) + 0.5 * dydx_e * (xne - xe)
    segs = [
        _corner(xc, yc, dydx_c, xnc, ync, dydx_near_c, cc),
        _corner(xnc, ync, dydx_near_c, xi, yi, dydx_iso, cc),
        _corner(xi, yi, dydx_iso, xne, yne, dydx_near_e, ce),
        _corner(xne, yne, dydx_near_e, xe, ye, dydx_e, ce),
    ]
    return _function(segs, xc, xe, yc, ye, dydx_c, dydx_e)


def fiber_force_length_curve(
    strain_at_zero_force=0.0,
    strain_at_one_norm_force=0.7,
    stiffness_at_low_force=None,
    stiffness_at_one_norm_force=None,
    curviness=None,
):
    """``createFiberForceLengthCurve`` (passive); the optional three all None: OpenSim's
    fitted values 0.2, 2/(e₁ − e₀), 0.75 (``FiberForceLengthCurve::ensureCurveUpToDate``)."""
    e0, e1 = strain_at_zero_force, strain_at_one_norm_force
    opt = (stiffness_at_low_force, stiffness_at_one_norm_force, curviness)
    if all(v is None for v in opt):
        k_low, k_iso, curviness = 0.2, 2.0 / (e1 - e0), 0.75
    elif any(v is None for v in opt):
        raise MuscleError(
            "fiber force-length curve: stiffness_at_low_force, stiffness_at_one_norm_force and "
            "curviness must all be set or all be empty"
        )
    else:
        k_low, k_iso = stiffness_at_low_force, stiffness_at_one_norm_force
    if not (e1 > e0 and k_iso > 1.0 / (e1 - e0) and 0 < k_low < 1.0 / (e1 - e0)):
        raise MuscleError(f"fiber force-length curve: strains {e0}, {e1} or stiffnesses invalid")
    c = _scale_curviness(curviness)
    x_zero, x_iso = 1 + e0, 1 + e1
    delta = min(0.1 * (1.0 / k_iso), 0.1 * (x_iso - x_zero))
    x_low = x_zero + delta
    x_foot = x_zero + 0.5 * (x_low - x_zero)
    y_low = k_low * (x_low - x_foot)
    segs = [
        _corner(x_zero, 0.0, 0.0, x_low, y_low, k_low, c),
        _corner(x_low, y_low, k_low, x_iso, 1.0, k_iso, c),
    ]
    return _function(segs, x_zero, x_iso, 0.0, 1.0, 0.0, k_iso)


def tendon_force_length_curve(
    strain_at_one_norm_force=0.049,
    stiffness_at_one_norm_force=None,
    norm_force_at_toe_end=None,
    curviness=None,
):
    """``createTendonForceLengthCurve``; the optional three all None: OpenSim's fitted values
    1.375/e₀, 2/3, 0.5 (``TendonForceLengthCurve::ensureCurveUpToDate``)."""
    e0 = strain_at_one_norm_force
    opt = (stiffness_at_one_norm_force, norm_force_at_toe_end, curviness)
    if all(v is None for v in opt):
        k_iso, f_toe, curviness = 1.375 / e0, 2.0 / 3.0, 0.5
    elif any(v is None for v in opt):
        raise MuscleError(
            "tendon force-length curve: stiffness_at_one_norm_force, norm_force_at_toe_end and "
            "curviness must all be set or all be empty"
        )
    else:
        k_iso, f_toe = stiffness_at_one_norm_force, norm_force_at_toe_end
    if not (e0 > 0 and k_iso > 1.0 / e0 and 0 < f_toe < 1):
        raise MuscleError(f"tendon force-length curve: strain {e0} or stiffness invalid")
    c = _scale_curviness(curviness)
    x_iso = 1.0 + e0
    x_toe = (f_toe - 1) / k_iso + x_iso
    x_foot = 1.0 + (x_toe - 1.0) / 10.0
    y_toe_mid = f_toe * 0.5
    x_toe_mid = (y_toe_mid - 1.0) / k_iso + x_iso
    dydx_toe_mid = y_toe_mid / (x_toe_mid - x_foot)
    x_toe_ctrl = x_foot + 0.5 * (x_toe_mid - x_foot)
    y_toe_ctrl = dydx_toe_mid * (x_toe_ctrl - x_foot)
    segs = [
        _corner(1.0, 0.0, 0.0, x_toe_ctrl, y_toe_ctrl, dydx_toe_mid, c),
        _corner(x_toe_ctrl, y_toe_ctrl, dydx_toe_mid, x_toe, f_toe, k_iso, c),
    ]
    return _function(segs, 1.0, x_toe, 0.0, f_toe, 0.0, k_iso)


@dataclass(frozen=True, eq=False)
class MillardCurves:
    """The four curves of one muscle."""

    active_force_length: SmoothSegmentedFunction
    force_velocity: SmoothSegmentedFunction
    fiber_force_length: SmoothSegmentedFunction
    tendon_force_length: SmoothSegmentedFunction
    min_norm_active_fiber_length: float


#: fibre damping below this is none (``MIN_NONZERO_DAMPING_COEFFICIENT``)
MIN_NONZERO_DAMPING = 0.001


def finalized_params(params: dict, rigid_tendon: bool) -> dict:
    """``params`` as OpenSim's ``extendFinalizeFromProperties`` leaves them: damping below
    0.001 is none; the classic (undamped, compliant) model needs a minimum activation of at
    least 0.01 and raises the active curve's minimum to 0.1 and the force-velocity slopes at
    vmax to half those near vmax; the damped (or rigid) model clamps the minimum activation to
    [0, 1] and sets the active curve's minimum and the slopes at vmax to 0."""
    p = dict(params)
    for k, d in MILLARD_DEFAULTS.items():
        p.setdefault(k, d)
    for curve, props in CURVE_DEFAULTS.items():
        for k, d in props.items():
            if d is not None:
                p.setdefault(f"{curve}.{k}", d)
    damped = p["fiber_damping"] >= MIN_NONZERO_DAMPING
    if not damped:
        p["fiber_damping"] = 0.0
    fv = "ForceVelocityCurve."
    if not rigid_tendon and not damped:
        if p["minimum_activation"] < 0.01:
            raise MuscleError(
                f"minimum_activation {p['minimum_activation']} is below 0.01: the undamped "
                "Millard2012 model with an elastic tendon is singular at zero activation"
            )
        p["ActiveForceLengthCurve.minimum_value"] = max(
            p["ActiveForceLengthCurve.minimum_value"], 0.1
        )
        for side in ("concentric", "eccentric"):
            near = p[f"{fv}{side}_slope_near_vmax"]
            if p[f"{fv}{side}_slope_at_vmax"] < 0.5 * near:
                p[f"{fv}{side}_slope_at_vmax"] = 0.5 * near
    else:
        p["minimum_activation"] = min(max(p["minimum_activation"], 0.0), 1.0)
        p["ActiveForceLengthCurve.minimum_value"] = min(
            p["ActiveForceLengthCurve.minimum_value"], 0.0
        )
        for side in ("concentric", "eccentric"):
            p[f"{fv}{side}_slope_at_vmax"] = min(p[f"{fv}{side}_slope_at_vmax"], 0.0)
    return p


def curves(params: dict) -> MillardCurves:
    """The curves of a muscle whose ``params`` (``Muscle.params``, after
    :func:`finalized_params`) hold ``"<Curve>.<property>"`` entries (missing ones take
    ``CURVE_DEFAULTS``)."""

    def kw(curve):
        return {k: params.get(f"{curve}.{k}", d) for k, d in CURVE_DEFAULTS[curve].items()}

    afl = kw("ActiveForceLengthCurve")
    return MillardCurves(
        active_force_length_curve(**afl),
        force_velocity_curve(**kw("ForceVelocityCurve")),
        fiber_force_length_curve(**kw("FiberForceLengthCurve")),
        tendon_force_length_curve(**kw("TendonForceLengthCurve")),
        float(afl["min_norm_active_fiber_length"]),
    )


def _pennation_model(ofl, phi0, phimax):
    """``MuscleFixedWidthPennationModel``: (height, sin φ_max, minimum fibre length, its
    projection along the tendon)."""
    h = ofl * np.sin(phi0)
    smax = np.sin(phimax)
    lmin = h / smax if phimax > SIGNIFICANT else 0.01 * ofl
    return h, smax, lmin, lmin * np.cos(phimax)


def static_equilibrium(muscle, lengths, activation, rigid: bool):
    """Static equilibrium of one Millard2012 muscle at musculotendon ``lengths`` (N,) and
    (already validated) ``activation`` (N,): (fibre length, pennation angle, fibre force,
    tendon force, active fibre force, passive fibre force, activation used, at the lower bound
    (N,): the fibre at its minimum length, OpenSim's ``Warning_FiberAtLowerBound``).
    Raises :class:`~anthroarm.errors.MuscleError` when the iteration fails away from the
    fibre's lower bound (OpenSim's ``MuscleCannotEquilibrate``)."""
    p = finalized_params(muscle.params, muscle.ignore_tendon_compliance)
    cv = curves(p)
    fiso, ofl, tsl = (
        muscle.max_isometric_force,
        muscle.optimal_fiber_length,
        muscle.tendon_slack_length,
    )
    phi0 = muscle.pennation_angle_at_optimal
    phimax = p.get("maximum_pennation_angle", MILLARD_DEFAULTS["maximum_pennation_angle"])
    amin = p.get("minimum_activation", MILLARD_DEFAULTS["minimum_activation"])
    if not (0 <= phi0 < np.pi / 2 - SIGNIFICANT):
        raise MuscleError(
            f"muscle {muscle.name!r}: pennation_angle_at_optimal {phi0} not in [0, pi/2)"
        )
    h, smax, pen_min, pen_min_at = _pennation_model(ofl, phi0, phimax)
    lmin = max(SIGNIFICANT, cv.min_norm_active_fiber_length * ofl, pen_min)
    L = np.asarray(lengths, dtype=float)
    a = np.maximum(amin, np.minimum(1.0, np.asarray(activation, dtype=float)))

    def pennation(lce):
        if phi0 <= EPS:
            return np.zeros_like(lce)
        s = h / np.maximum(lce, 1e-300)
        return np.where((lce > pen_min) & (s < smax), np.arcsin(np.minimum(s, 1.0)), phimax)

    def fiber_length(tl):  # calcFiberLength, clamped
        at = L - tl
        lce = np.where(at >= pen_min_at, np.sqrt(h * h + at * at), pen_min)
        return np.maximum(lce, lmin)

    def state(lce):
        phi = pennation(lce)
        c = np.cos(phi)
        tl = L - lce * c
        fal, dfal = cv.active_force_length.eval(lce / ofl)
        fpe, dfpe = cv.fiber_force_length.eval(lce / ofl)
        fse, dfse = cv.tendon_force_length.eval(tl / tsl)
        fm = fiso * (a * fal + fpe)
        return phi, c, tl, fal, fpe, fse, fm, fm * c - fse * fiso, (dfal, dfpe, dfse)

    if rigid:
        lce = fiber_length(np.full_like(L, tsl))
        converged = np.ones(L.shape, dtype=bool)
    else:
        lce = fiber_length(np.full_like(L, 1.01 * tsl))
        tol = max(1e-11 * fiso, SIGNIFICANT * 10)
        lce, converged = _newton(lce, state, lmin, ofl, tsl, fiso, a, tol)
        bad = ~converged & (lce > lmin)
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise MuscleError(
                f"muscle {muscle.name!r}: no static equilibrium at length {L[i]} m, activation "
                f"{a[i]} (OpenSim's MuscleCannotEquilibrate)"
            )
        lce = np.where(converged, lce, lmin)
    phi, c, tl, fal, fpe, fse, fm, _, _ = state(lce)
    clamped = lce <= lmin  # isFiberStateClamped with zero fibre velocity
    active = np.where(clamped, 0.0, fiso * a * fal)
    passive = np.where(clamped, 0.0, fiso * fpe)
    fiber = active + passive
    tendon = fiber * c if rigid else fse * fiso
    return lce, phi, fiber, tendon, active, passive, a, ~converged


def _newton(lce, state, lmin, ofl, tsl, fiso, a, tol):
    """``estimateMuscleFiberState``'s damped Newton iteration (static), vectorised."""
    phi, c, tl, fal, fpe, fse, fm, ferr, (dfal, dfpe, dfse) = state(lce)
    for _ in range(200):
        todo = np.abs(ferr) > tol
        if not np.any(todo):
            break
        s = np.sin(phi)
        dphi = np.where(phi > 0, -np.tan(phi) / lce, 0.0)  # sin φ = h / l
        dfm = fiso * (a * dfal + dfpe) / ofl
        dfmat = dfm * c - fm * s * dphi
        dft = dfse * fiso / tsl * -(c - lce * s * dphi)
        slope = dfmat - dft
        step = np.where(todo & (np.abs(slope) > 0), -ferr / np.where(slope == 0, 1.0, slope), 0.0)
        h = np.ones_like(lce)
        new = lce.copy()
        nerr = ferr.copy()
        pending = todo.copy()
        while np.any(pending):  # halve the step until the error decreases
            trial = np.maximum(lce + h * step, lmin)
            t = state(trial)
            better = np.abs(t[7]) < np.abs(ferr)
            take = pending & (better | (h <= SQRT_EPS))
            new = np.where(take, trial, new)
            nerr = np.where(take, t[7], nerr)
            pending &= ~take
            h = np.where(pending, 0.5 * h, h)
        stuck = todo & (new == lce)
        lce = new
        phi, c, tl, fal, fpe, fse, fm, ferr, (dfal, dfpe, dfse) = state(lce)
        if np.all(stuck | ~todo):
            break
    return lce, np.abs(ferr) <= max(tol, 1e-8 * fiso)
