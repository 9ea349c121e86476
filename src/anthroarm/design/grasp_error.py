"""Grasping (positioning) error of clamping fingers, book §2-4, Eq. (2-5)–(2-20).

The grasp error Δ is how far the centre C of a cylindrical object of radius R moves as R
ranges over [R_min, R_max] (Fig. 2-13 … 2-15):

* translational fingers (平移型): Δ = 0;
* single-pivot V-groove fingers (单支点回转型): both fingers turn about one pivot A; the
  finger A→B (length ``l``) carries a V groove of half angle ``theta`` whose bisector B→C makes
  the offset angle ``beta`` with AB.  X = |AC| (2-5)/(2-6), a hyperbola in (R, X) (2-7),
  symmetric about R0 = l sin θ cos β with minimum X_min = l sin β (2-8);
* double-pivot fingers (双支点回转型): pivots 2a apart; X is the distance of C from the line
  of the pivots (2-13)–(2-16).

The book's case split (2-9)–(2-11) and (2-17)–(2-19) equals ``max X − min X`` over the radius
range; :func:`grasp_error_brute` evaluates that by sampling and is the tests' oracle.
Lengths in any consistent unit (mm in the book's figures), angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GraspError:
    """Result of a grasp-error evaluation.

    ``delta`` is Δ; ``case`` is ``"same_side"`` ((2-9)/(2-17): R0 outside (R_min, R_max)) or
    ``"split"`` ((2-10)/(2-11), (2-18)/(2-19): R0 inside, Δ = max(Δ1, Δ2)); ``delta1``,
    ``delta2`` are the two split terms (NaN in the same-side case); ``r0``, ``x_min`` from
    (2-8)/(2-16)."""

    delta: float
    case: str
    r0: float
    x_min: float
    delta1: float = float("nan")
    delta2: float = float("nan")


def _check(l, theta, beta, rmin=None, rmax=None, a=0.0, R=0.0):
    for name, v in (("l", l), ("theta", theta), ("beta", beta), ("a", a), ("R", R)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be finite, got {v!r}")
    if np.any(np.asarray(l) <= 0):
        raise ValueError(f"finger length l must be positive, got {l!r}")
    if np.any(np.asarray(theta) <= 0) or np.any(np.asarray(theta) > np.pi / 2):
        raise ValueError(f"V-groove half angle theta must be in (0, pi/2], got {theta!r}")
    if np.any(np.asarray(a) < 0):
        raise ValueError(f"half pivot distance a must be >= 0, got {a!r}")
    if rmin is not None:
        if not (np.isfinite(rmin) and np.isfinite(rmax)) or not (0 < rmin < rmax):
            raise ValueError(f"need 0 < R_min < R_max, got R_min={rmin!r}, R_max={rmax!r}")


def grasp_error_translational(*_args, **_kw) -> float:
    """Translational (parallel) fingers: the object centre never moves, Δ = 0 (§2-4)."""
    return 0.0


def x_single(l, R, theta, beta):
    """Eq. (2-6): ``X = sqrt(l² + (R/sin θ)² − 2 l (R/sin θ) cos β)``, the pivot–centre distance
    of a single-pivot V finger (l_BC = R/sin θ, Eq. (2-5)).  Broadcasts over ``R``."""
    _check(l, theta, beta, R=R)
    lbc = np.asarray(R, dtype=float) / np.sin(theta)
    return np.sqrt(l**2 + lbc**2 - 2 * l * lbc * np.cos(beta))


def single_r0(l, theta, beta) -> float:
    """Eq. (2-8): radius of the hyperbola's vertex, ``R0 = l sin θ cos β``."""
    _check(l, theta, beta)
    return float(l * np.sin(theta) * np.cos(beta))


def single_x_min(l, theta, beta) -> float:
    """Eq. (2-8): ``X_min = l sin β`` (the centre is closest to the pivot at R = R0)."""
    _check(l, theta, beta)
    return float(l * abs(np.sin(beta)))


def hyperbola_single_residual(l, R, X, theta, beta):
    """Eq. (2-7) minus one: ``X²/(l sin β)² − (R − l sin θ cos β)²/(l sin θ sin β)² − 1``."""
    return (
        X**2 / (l * np.sin(beta)) ** 2
        - (R - l * np.sin(theta) * np.cos(beta)) ** 2 / (l * np.sin(theta) * np.sin(beta)) ** 2
        - 1
    )


def grasp_error_single(l, theta, beta, rmin, rmax) -> GraspError:
    """Grasp error of single-pivot V fingers, Eq. (2-9)–(2-11), case split as in the book."""
    _check(l, theta, beta, rmin, rmax)
    r0 = single_r0(l, theta, beta)
    xmin = single_x_min(l, theta, beta)
    xa, xb = (float(x_single(l, r, theta, beta)) for r in (rmax, rmin))
    if rmin < r0 < rmax:
        d1, d2 = xa - xmin, xb - xmin
        return GraspError(max(d1, d2), "split", r0, xmin, d1, d2)
    return GraspError(abs(xa - xb), "same_side", r0, xmin)


def optimal_beta_single(l, theta, rmin, rmax) -> float:
    """Eq. (2-12): offset angle that puts R0 at the mid radius R_cp = (R_min + R_max)/2,
    ``β_c = acos(R_cp / (l sin θ))``.  Raises ``ValueError`` if R_cp > l sin θ (the finger is
    too short for any offset angle to centre the hyperbola)."""
    _check(l, theta, 0.0, rmin, rmax)
    rcp = 0.5 * (rmin + rmax)
    c = rcp / (l * np.sin(theta))
    if c > 1:
        raise ValueError(
            f"(2-12) needs R_cp <= l sin(theta): R_cp = {rcp:g} > l sin(theta) = "
            f"{l * np.sin(theta):g}; lengthen the finger or widen the V"
        )
    return float(np.arccos(c))


# ------------------------------------------------------------------ double pivot


def x_double(l, R, theta, beta, a):
    """Eq. (2-14): distance of the object centre from the pivot line of double-pivot fingers
    (pivots 2a apart), ``X = sqrt((R − l sin θ cos β)²/sin²θ + l² sin²β − a²)``, i.e.
    (2-13) with l_BC = R/sin θ.  NaN-free: raises ``ValueError`` where |AC| < a (the centre
    cannot lie between pivots closer than the finger geometry allows)."""
    _check(l, theta, beta, a=a, R=R)
    R = np.asarray(R, dtype=float)
    x2 = (
        (R - l * np.sin(theta) * np.cos(beta)) ** 2 / np.sin(theta) ** 2
        + (l * np.sin(beta)) ** 2
        - a**2
    )
    if np.any(x2 < 0):
        raise ValueError(
            f"double-pivot geometry impossible: |AC| < a={a!r} for some R (l sin(beta) too small)"
        )
    return np.sqrt(x2)


def double_x_min(l, theta, beta, a) -> float:
    """Eq. (2-16): ``X_min = sqrt(l² sin²β − a²)``; requires l² sin²β > a²."""
    _check(l, theta, beta, a=a)
    v = (l * np.sin(beta)) ** 2 - a**2
    if v < 0:
        raise ValueError(
            f"(2-16) needs l^2 sin^2(beta) >= a^2: {(l * np.sin(beta)) ** 2:g} < {a**2:g}"
        )
    return float(np.sqrt(v))


def hyperbola_double_residual(l, R, X, theta, beta, a):
    """Eq. (2-15) minus one."""
    k = (l * np.sin(beta)) ** 2 - a**2
    return X**2 / k - (R - l * np.sin(theta) * np.cos(beta)) ** 2 / (np.sin(theta) ** 2 * k) - 1


def grasp_error_double(l, theta, beta, a, rmin, rmax) -> GraspError:
    """Grasp error of double-pivot fingers, Eq. (2-17)–(2-19) (the (2-17) bracket corrected,
    see docs/errata.md)."""
    _check(l, theta, beta, rmin, rmax, a)
    r0 = single_r0(l, theta, beta)  # (2-16): same vertex radius
    xmin = double_x_min(l, theta, beta, a)
    xa, xb = (float(x_double(l, r, theta, beta, a)) for r in (rmax, rmin))
    if rmin < r0 < rmax:
        d1, d2 = xa - xmin, xb - xmin
        return GraspError(max(d1, d2), "split", r0, xmin, d1, d2)
    return GraspError(abs(xa - xb), "same_side", r0, xmin)


def beta_two_sizes(l, theta, r1, r2) -> float:
    """Eq. (2-20): for exactly two object radii, ``β0 = acos((R1 + R2)/(2 l sin θ))`` makes
    X(R1) = X(R2), so Δ = 0 (single or double pivot)."""
    _check(l, theta, 0.0)
    if not (np.isfinite(r1) and np.isfinite(r2)) or r1 <= 0 or r2 <= 0:
        raise ValueError(f"radii must be positive, got R1={r1!r}, R2={r2!r}")
    c = (r1 + r2) / (2 * l * np.sin(theta))
    if c > 1:
        raise ValueError(
            f"(2-20) needs (R1+R2)/2 <= l sin(theta): {(r1 + r2) / 2:g} > {l * np.sin(theta):g}"
        )
    return float(np.arccos(c))


def grasp_error_brute(l, theta, beta, rmin, rmax, a=None, n: int = 20001) -> float:
    """Reference: ``max X − min X`` sampled at ``n`` radii plus R0 (if inside).  The object
    centre is built geometrically (B on the finger, C on the groove bisector at R/sin θ from B),
    not with the law of cosines of (2-5)."""
    _check(l, theta, beta, rmin, rmax, 0.0 if a is None else a)
    R = np.linspace(rmin, rmax, n)
    r0 = single_r0(l, theta, beta)
    if rmin < r0 < rmax:
        R = np.append(R, r0)
    B = np.array([l, 0.0])
    d = np.array([-np.cos(beta), np.sin(beta)])  # bisector B->C, at beta from B->A reversed
    C = B[None, :] + (R / np.sin(theta))[:, None] * d[None, :]
    if a is None:
        X = np.linalg.norm(C, axis=1)  # pivot A at the origin
    else:
        # A at the origin, the other pivot a mirror image: X = distance from the pivot line,
        # |AC|² = X² + a² (C sits symmetrically between the two pivots 2a apart)
        ac2 = np.sum(C**2, axis=1)
        if np.any(ac2 < a**2):
            raise ValueError("double-pivot geometry impossible for some R")
        X = np.sqrt(ac2 - a**2)
    return float(X.max() - X.min())


def plot_grasp_error(l, theta, rmin, rmax, a=0.0, betas=None, ax=None):
    """Plot Δ against the offset angle β (single pivot if ``a == 0``), marking β_c of (2-12).
    Returns the matplotlib Axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 3.5))
    lo = np.arcsin(min(1.0, a / l)) + 1e-3 if a > 0 else 1e-3
    betas = np.linspace(lo, np.pi / 2, 400) if betas is None else np.asarray(betas)
    fn = (
        (lambda b: grasp_error_single(l, theta, b, rmin, rmax).delta)
        if a == 0
        else (lambda b: grasp_error_double(l, theta, b, a, rmin, rmax).delta)
    )
    ax.plot(np.rad2deg(betas), [fn(b) for b in betas], label=f"a = {a:g}")
    try:
        bc = optimal_beta_single(l, theta, rmin, rmax)
        ax.axvline(np.rad2deg(bc), ls="--", c="k", lw=0.8)
        ax.annotate(r"$\beta_c$", (np.rad2deg(bc), ax.get_ylim()[1] * 0.9))
    except ValueError:
        pass
    ax.set_xlabel(r"offset angle $\beta$ (deg)")
    ax.set_ylabel(r"grasp error $\Delta$")
    ax.set_title(f"l = {l:g}, 2θ = {np.rad2deg(2 * theta):g}°, R ∈ [{rmin:g}, {rmax:g}]")
    ax.legend()
    return ax
