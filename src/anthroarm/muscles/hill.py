"""Hill-type muscle forces: OpenSim's ``Thelen2003Muscle`` in static equilibrium, and the joint
torques τ = Rᵀ f of the muscles' tendon forces.

The curves, each as opensim-core 4.x evaluates it (``OpenSim/Actuators/Thelen2003Muscle.cpp``)
after Thelen, *Adjustment of muscle mechanics model parameters to simulate dynamic
contractions in older adults*, J Biomech Eng 125 (2003) 70-77:

* active force–length (Thelen 2003, Eq. 2): f_L(l̃) = exp(−(l̃ − 1)² / γ), γ = ``KshapeActive``;
* passive force–length (Eq. 3): f_PE(l̃) = (exp(k_PE (l̃ − 1)/ε₀ᴹ) − 1) / (exp(k_PE) − 1) for
  l̃ > 1, else 0 (k_PE = ``KshapePassive``, ε₀ᴹ = ``FmaxMuscleStrain``);
* tendon force–strain (Eq. 1, with OpenSim's exact toe constants ``calcfse``): exponential toe
  F_toe (exp(k_toe ε/ε_toe) − 1)/(exp(k_toe) − 1) up to ε_toe = 99 ε₀ e³/(166 e³ − 67), then
  linear with slope k_lin = 0.67/(ε₀ − ε_toe); F_toe = 0.33, k_toe = 3, ε₀ = ``FmaxTendonStrain``;
* force–velocity (Eq. 6): at zero fibre velocity f_V = 1 (a static state — every state of
  :func:`equilibrium`);
* pennation: the fixed-width parallelogram (``MuscleFixedWidthPennationModel.cpp``; Zajac,
  *Muscle and tendon: properties, models, scaling, and application to biomechanics and motor
  control*, Crit Rev Biomed Eng 17 (1989) 359-411): l sin φ = l₀ sin φ₀, φ clamped at
  ``maximum_pennation_angle`` (the minimum fibre length l₀ sin φ₀ / sin φ_max);
* activation floored at ``minimum_activation`` (0.01), as OpenSim's
  ``MuscleFirstOrderActivationDynamicModel::clampActivation`` does.

Equilibrium (compliant tendon): the fibre length l at which the fibre force along the tendon
equals the tendon force, (a f_L(l̃) f_V + f_PE(l̃)) F₀ cos φ = f_SE((L − l cos φ)/l_s) F₀, for
the musculotendon length L of the path (``Thelen2003Muscle::initMuscleState`` with zero
lengthening speed).  Solved here by bisection on [l_min, the fibre length of a slack tendon]
to machine precision; the fibre at its minimum length when the bracket holds no root (OpenSim's
``Warning_FiberAtLowerBound``).  Rigid tendon (``ignore_tendon_compliance``): the tendon at its
slack length, l = √(h² + (L − l_s)²).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MuscleError
from . import millard
from .paths import lengths_and_moment_arms, muscle_set

#: bisection steps: the bracket shrinks by 2^-80, below one ulp of any fibre length
BISECTIONS = 80
#: SimTK::SignificantReal
SIGNIFICANT = np.finfo(float).eps ** 0.875


def active_force_length(lceN, k_shape_active):
    """Thelen (2003) Eq. 2: exp(−(l̃ − 1)²/γ)."""
    x = (np.asarray(lceN, dtype=float) - 1.0) ** 2
    return np.exp(-x / k_shape_active)


def passive_force_length(lceN, fmax_muscle_strain, k_shape_passive):
    """Thelen (2003) Eq. 3, as ``Thelen2003Muscle::calcfpe`` (zero below l̃ = 1)."""
    lceN = np.asarray(lceN, dtype=float)
    t5 = np.exp(k_shape_passive * (np.maximum(lceN, 1.0) - 1.0) / fmax_muscle_strain)
    return np.where(lceN > 1.0, (t5 - 1.0) / (np.exp(k_shape_passive) - 1.0), 0.0)


def tendon_force_strain(tlN, fmax_tendon_strain):
    """Thelen (2003) Eq. 1 with OpenSim's constants (``Thelen2003Muscle::calcfse``): the
    normalised tendon force at normalised tendon length l_T / l_s."""
    x = np.asarray(tlN, dtype=float) - 1.0
    e0 = fmax_tendon_strain
    t1 = np.exp(3.0)
    e_toe = (99.0 * e0 * t1) / (166.0 * t1 - 67.0)
    k_lin = (67.0 / 100.0) * 1.0 / (e0 - (99.0 * e0 * t1) / (166.0 * t1 - 67.0))
    f_toe, k_toe = 33.0 / 100.0, 3.0
    toe = (f_toe / (np.exp(k_toe) - 1.0)) * (np.exp(k_toe * np.minimum(x, e_toe) / e_toe) - 1.0)
    return np.where(x > e_toe, k_lin * (x - e_toe) + f_toe, np.where(x > 0.0, toe, 0.0))


@dataclass(frozen=True)
class Equilibrium:
    """Static equilibrium of muscles (arrays of shape ``(N, M)``, SI units): fibre length,
    pennation angle, fibre force, tendon force (the force the muscle applies to its path),
    active and passive fibre force, the activation used (floored at the minimum)."""

    fiber_length: np.ndarray
    pennation_angle: np.ndarray
    fiber_force: np.ndarray
    tendon_force: np.ndarray
    active_fiber_force: np.ndarray
    passive_fiber_force: np.ndarray
    activation: np.ndarray


def _parameters(ms):
    keys = ["FmaxTendonStrain", "FmaxMuscleStrain", "KshapeActive", "KshapePassive"]
    keys += ["maximum_pennation_angle", "minimum_activation"]
    p = {k: np.array([m.params[k] for m in ms.muscles]) for k in keys}
    for k in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length"):
        p[k] = np.array([getattr(m, k) for m in ms.muscles])
    p["pennation_angle_at_optimal"] = np.array([m.pennation_angle_at_optimal for m in ms.muscles])
    p["rigid"] = np.array([m.ignore_tendon_compliance for m in ms.muscles])
    return p


def check_activation(activation, shape) -> np.ndarray:
    """``activation`` broadcast to ``shape``; :class:`~anthroarm.errors.MuscleError` when it
    is not finite or outside [0, 1]."""
    a = np.asarray(activation, dtype=float)
    try:
        a = np.broadcast_to(a, shape)
    except ValueError:
        raise MuscleError(f"activations of shape {a.shape} do not fit {shape}") from None
    if not np.all(np.isfinite(a)):
        raise MuscleError("activations must be finite numbers")
    if np.any((a < 0.0) | (a > 1.0)):
        bad = a[(a < 0.0) | (a > 1.0)].ravel()[0]
        raise MuscleError(f"activation {bad} is outside [0, 1]")
    return a


def equilibrium(muscles, lengths, activation, *, rigid_tendon=None) -> Equilibrium:
    """The static equilibrium of the muscles (``Thelen2003Muscle`` as in the module docstring,
    ``Millard2012EquilibriumMuscle`` by :func:`anthroarm.muscles.millard.static_equilibrium`)
    at musculotendon ``lengths`` (m, ``(M,)`` or ``(N, M)``) and ``activation`` (in [0, 1],
    broadcast), zero lengthening speed.  ``rigid_tendon``: None follows each muscle's
    ``ignore_tendon_compliance``; True / False forces it for all."""
    ms = muscles
    L = np.asarray(lengths, dtype=float)
    one = L.ndim == 1
    L2 = np.atleast_2d(L)
    if L2.shape[-1] != len(ms) or not np.all(np.isfinite(L2)):
        raise MuscleError(f"lengths must be finite, shape (N, {len(ms)}); got {L.shape}")
    a_in = check_activation(activation, L2.shape)
    kinds = {"Thelen2003Muscle": [], "Millard2012EquilibriumMuscle": []}
    for i, m in enumerate(ms.muscles):
        if m.type not in kinds:
            raise MuscleError(
                f"muscle {m.name!r} is a {m.type}: only Thelen2003Muscle and "
                "Millard2012EquilibriumMuscle forces are evaluated"
            )
        kinds[m.type].append(i)
        for k in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length"):
            v = getattr(m, k)
            if not (np.isfinite(v) and v > 0):
                raise MuscleError(f"muscle {m.name!r}: {k} {v} is not a positive number")
    fields = [np.zeros(L2.shape) for _ in range(7)]
    th = kinds["Thelen2003Muscle"]
    if th:
        sub = ms if len(th) == len(ms) else ms.select([ms.muscles[i].name for i in th])
        for f, v in zip(fields, _thelen(sub, L2[:, th], a_in[:, th], rigid_tendon)):
            f[:, th] = v
    for i in kinds["Millard2012EquilibriumMuscle"]:
        m = ms.muscles[i]
        rigid = m.ignore_tendon_compliance if rigid_tendon is None else bool(rigid_tendon)
        *values, _at_bound = millard.static_equilibrium(m, L2[:, i], a_in[:, i], rigid)
        for f, v in zip(fields, values):
            f[:, i] = v
    out = Equilibrium(*fields)
    if one:
        out = Equilibrium(*(np.asarray(v)[0] for v in out.__dict__.values()))
    return out


def _thelen(ms, L2, a_in, rigid_tendon):
    """Thelen2003 static equilibrium (module docstring): the seven fields of
    :class:`Equilibrium`, arrays (N, M)."""
    p = _parameters(ms)
    a = np.maximum(a_in, p["minimum_activation"])
    rigid = p["rigid"] if rigid_tendon is None else np.full(len(ms), bool(rigid_tendon))
    fiso, ofl, tsl = p["max_isometric_force"], p["optimal_fiber_length"], p["tendon_slack_length"]
    phi0, phimax = p["pennation_angle_at_optimal"], p["maximum_pennation_angle"]
    h = ofl * np.sin(phi0)
    smax = np.sin(phimax)
    # MuscleFixedWidthPennationModel::extendFinalizeFromProperties
    lmin = np.where(phimax > SIGNIFICANT, h / np.where(smax > 0, smax, 1.0), 0.01 * ofl)
    lmin_at = lmin * np.cos(phimax)

    def pennation(lce):
        s = h / np.maximum(lce, 1e-300)
        phi = np.where(s < smax, np.arcsin(np.minimum(s, 1.0)), phimax)
        phi = np.where(lce > lmin, phi, phimax)
        return np.where(phi0 > np.finfo(float).eps, phi, 0.0)

    def fiber_from_tendon(tl):
        at = L2 - tl
        return np.where(at >= lmin_at, np.sqrt(h * h + at * at), lmin)

    def forces(lce):
        phi = pennation(lce)
        lceN = lce / ofl
        fal = active_force_length(lceN, p["KshapeActive"])
        fpe = passive_force_length(lceN, p["FmaxMuscleStrain"], p["KshapePassive"])
        return phi, fal, fpe

    def residual(lce):
        phi, fal, fpe = forces(lce)
        tl = L2 - lce * np.cos(phi)
        fse = tendon_force_strain(tl / tsl, p["FmaxTendonStrain"])
        return (a * fal + fpe) * np.cos(phi) - fse

    hi = fiber_from_tendon(tsl)  # tendon slack: no tendon force, residual >= 0
    lo = np.broadcast_to(lmin, L2.shape).copy()
    r_lo = residual(lo)
    at_bound = r_lo >= 0.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        neg = residual(mid) < 0.0
        lo = np.where(neg, mid, lo)
        hi = np.where(neg, hi, mid)
    lce = np.where(at_bound, lmin, 0.5 * (lo + hi))
    rigid_len = np.maximum(fiber_from_tendon(tsl), lmin)
    lce = np.where(rigid, rigid_len, lce)
    phi, fal, fpe = forces(lce)
    # a fibre at its minimum length and not lengthening is clamped: no fibre force
    # (Thelen2003Muscle::isFiberStateClamped, calcMuscleDynamicsInfo)
    clamped = lce <= lmin
    active = np.where(clamped, 0.0, a * fal * fiso)
    fiber = np.where(clamped, 0.0, active + fpe * fiso)
    tl = L2 - lce * np.cos(phi)
    tendon = np.where(
        rigid, fiber * np.cos(phi), tendon_force_strain(tl / tsl, p["FmaxTendonStrain"]) * fiso
    )
    return lce, phi, fiber, tendon, active, fpe * fiso, a


def joint_torques(robot, muscles=None, q=None, activation=1.0, *, wrap: bool = True):
    """τ = R(q)ᵀ f: the generalized forces (N m, or N for a translational coordinate) of the
    muscles' tendon forces f at static equilibrium with ``activation``, in the independent
    coordinates; ``(nq,)`` for one state, ``(N, nq)`` for a batch.  Returns (τ,
    :class:`Equilibrium`, R).  R = −∂l/∂q (:func:`~anthroarm.muscles.moment_arms`): a tension
    f ≥ 0 shortening the path does the work f · (−dl) = (Rᵀ f) · dq."""
    ms = muscle_set(robot, muscles)
    L, R = lengths_and_moment_arms(robot, ms, q, wrap=wrap)
    eq = equilibrium(ms, L, activation)
    tau = np.einsum("...mk,...m->...k", R, eq.tendon_force)
    return tau, eq, R
