"""What the subproblems share: the :class:`Solutions` they return, the checks of their inputs,
numpy helpers, the rotation matrix rot(k, θ) and the angle as (cos θ, sin θ)
(:func:`unit_cs`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...jit import kernel
from ..vec3 import atan2

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
    :func:`anthroarm.ik.classes.branches.angles`).  r by ``math.hypot`` where x² + y² would
    lose digits (below 1e-290 or above 1e290); cos and sin of atan2(y, x) where r is 0 or not
    finite."""
    rr = x * x + y * y
    r = math.sqrt(rr) if 1e-290 < rr < 1e290 else math.hypot(x, y)
    if 0.0 < r < math.inf:
        return x / r, y / r
    theta = atan2(y, x)
    return math.cos(theta), math.sin(theta)
