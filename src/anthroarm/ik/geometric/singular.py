"""Singular solutions: the normalised volume of the Jacobian of the first six joints at each
solution (0 at a singular configuration of the arm)."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..fk import chain_fk_jacobian, solve6
from ..vec3 import dot
from .plan import GeoPlan, _unpack

#: a solution whose normalised Jacobian volume (:func:`_volume`) is at most this is at a
#: singular configuration of the arm
SINGULAR_TOL = 1e-6


@kernel
def _volume(A, q, n, J, W, F):
    """The normalised volume |det J| / Π‖J_k‖ ∈ [0, 1] (Hadamard's inequality) of the 6×6
    Jacobian of the first six joints at ``q`` (path order, rad), at the tool point, in the base
    frame (:func:`anthroarm.ik.fk.chain_fk_jacobian`, the first six of its n columns): 0 at a singular configuration
    — a wrist with aligned axes, a stretched elbow, the wrist centre on the first axis — where
    solutions coincide in pairs or form a one-parameter family.  ``J`` (6, 6), ``F`` (6,)
    scratch."""
    chain_fk_jacobian(A, q, J, W, n)
    scale = 1.0
    for i in range(6):
        c, w = (J[0, i], J[1, i], J[2, i]), (J[3, i], J[4, i], J[5, i])
        scale *= math.sqrt(dot(c, c) + dot(w, w))
        F[i] = 0.0
    return abs(solve6(J, F)) / scale


@kernel
def _volume_loop(cf, ci, TH, OK, VOL):
    """:func:`_volume` of every solution (``OK``) of θ (N, B, n) in independent-joint order
    into VOL (N, B) (1 elsewhere)."""
    _, _, n, _, _, _, _, _, _, A, _, _, order, _ = _unpack(cf, ci)
    q, J, W, F = np.empty(n), np.empty((6, n)), np.empty((n, 6)), np.empty(6)
    for i in range(TH.shape[0]):
        for b in range(TH.shape[1]):
            VOL[i, b] = 1.0
            if OK[i, b]:
                for k in range(n):
                    q[order[k]] = TH[i, b, k]
                VOL[i, b] = _volume(A, q, n, J, W, F)


def jacobian_volumes(plan: GeoPlan, TH, OK) -> np.ndarray:
    """The normalised Jacobian volume (:func:`_volume`) of each solution θ (N, B, n)
    (independent-joint order, rad) where ``OK`` (N, B); 1 elsewhere."""
    cf, ci = plan.packed
    VOL = np.empty(OK.shape)
    _volume_loop(cf, ci, np.ascontiguousarray(TH, dtype=float), np.ascontiguousarray(OK), VOL)
    return VOL
