"""Complex polar vectors (book §5-2): r = r e^{iθ} in the plane, and the spatial
complex-plus-j form (5-23)/(5-24).

The real axis is x, the imaginary axis y; θ is counter-clockwise from +x (rad).  The time
derivatives (5-10)/(5-11) split into four named terms, each a magnitude times a unit direction:

    d/dt (r e^{iθ})   = ṙ e^{iθ}                         (radial velocity)
                      + r θ̇ i e^{iθ}                     (tangential velocity)
    d²/dt² (r e^{iθ}) = r̈ e^{iθ}                         (radial acceleration)
                      − r θ̇² e^{iθ}                      (centripetal)
                      + r θ̈ i e^{iθ}                     (tangential)
                      + 2 ṙ θ̇ i e^{iθ}                   (Coriolis)

(the OCR's intermediate term ṙ(e^{iθ} i θ̈) in (5-11) reads ṙ(e^{iθ} i θ̇); the final line is
right).  Everything is vectorised over numpy arrays of r, θ and their rates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .rotations import as_angle, as_vector3


def polar(r, theta) -> np.ndarray:
    """r e^{iθ} = r(cos θ + i sin θ), Eq. (5-1)–(5-4), as a complex number (array)."""
    return as_angle(r, "r") * np.exp(1j * as_angle(theta, "theta"))


def unit(theta) -> np.ndarray:
    """The unit vector α = e^{iθ}, Eq. (5-4)."""
    return np.exp(1j * as_angle(theta, "theta"))


def rotate(z, phi) -> np.ndarray:
    """e^{iφ}(r e^{iθ}) = r e^{i(φ+θ)}, Eq. (5-5): rotation of a planar vector by φ."""
    z = np.asarray(z, complex)
    if not np.all(np.isfinite(z)):
        raise ValueError(f"z must be finite, got {z.tolist()}")
    return z * np.exp(1j * as_angle(phi, "phi"))


def to_xy(z) -> np.ndarray:
    """Complex → (..., 2) array (x, y)."""
    z = np.asarray(z, complex)
    return np.stack([z.real, z.imag], -1)


def from_xy(xy) -> np.ndarray:
    xy = np.asarray(xy, float)
    if xy.shape[-1] != 2 or not np.all(np.isfinite(xy)):
        raise ValueError(f"planar point must have shape (..., 2) and be finite, got {xy.tolist()}")
    return xy[..., 0] + 1j * xy[..., 1]


@dataclass
class PolarMotion:
    """Position, velocity and acceleration of r e^{iθ} (complex), Eq. (5-10)/(5-11), with the
    named terms.  ``velocity = radial_velocity + tangential_velocity`` and
    ``acceleration = radial_acc + centripetal + tangential_acc + coriolis``."""

    position: np.ndarray
    velocity: np.ndarray
    radial_velocity: np.ndarray
    tangential_velocity: np.ndarray
    acceleration: np.ndarray
    radial_acc: np.ndarray
    centripetal: np.ndarray
    tangential_acc: np.ndarray
    coriolis: np.ndarray


def polar_motion(r, r_dot, r_ddot, theta, theta_dot, theta_ddot) -> PolarMotion:
    """The derivatives (5-10)/(5-11) of r(t) e^{iθ(t)} split into radial, tangential,
    centripetal and Coriolis terms (m, m/s, m/s²)."""
    r, rd, rdd = (as_angle(x, n) for x, n in ((r, "r"), (r_dot, "r_dot"), (r_ddot, "r_ddot")))
    th, thd, thdd = (
        as_angle(x, n)
        for x, n in ((theta, "theta"), (theta_dot, "theta_dot"), (theta_ddot, "theta_ddot"))
    )
    e = np.exp(1j * th)
    ie = 1j * e
    rv, tv = rd * e, r * thd * ie
    ra, ce, ta, co = rdd * e, -r * thd**2 * e, r * thdd * ie, 2.0 * rd * thd * ie
    return PolarMotion(r * e, rv + tv, rv, tv, ra + ce + ta + co, ra, ce, ta, co)


def spherical_to_xyz(r_p, theta, phi) -> np.ndarray:
    """r_p(e^{iθ} sin φ + j cos φ), Eq. (5-23), as (x, y, z): θ azimuth in the xy-plane, φ polar
    angle from +z (j is the unit vector along z, not a quaternion unit)."""
    r_p, th, ph = as_angle(r_p, "r_p"), as_angle(theta, "theta"), as_angle(phi, "phi")
    return np.stack(
        [
            r_p * np.sin(ph) * np.cos(th),
            r_p * np.sin(ph) * np.sin(th),
            r_p * np.cos(ph) * np.ones_like(th),
        ],
        -1,
    )


def xyz_to_spherical(p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(r_p, θ, φ) of a point, Eq. (5-24), with atan2 (θ ∈ (−π, π], φ ∈ [0, π]).  On the z-axis
    θ is undefined and 0 is returned."""
    p = as_vector3(p, "point")
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    rho = np.hypot(x, y)
    return np.sqrt(rho**2 + z**2), np.arctan2(y, x), np.arctan2(rho, z)
