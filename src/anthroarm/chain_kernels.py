"""Compiled kernels of :mod:`anthroarm.chain` (:mod:`anthroarm.jit`), in a module of their own so
that reading a model does not import Numba."""

from __future__ import annotations

import math

from .jit import kernel


@kernel
def put_joint(q, j, continuous, theta, c, s):
    """One joint's entries of a configuration q: θ at q[j], or (c, s) = (cos θ, sin θ) at q[j],
    q[j + 1] for a continuous joint (Pinocchio's unit-complex form)."""
    if continuous:
        q[j], q[j + 1] = c, s
    else:
        q[j] = theta


@kernel
def configure(theta, index, q):
    """q (N, nq) from the positions θ (N, n) of the independent joints (rad, m for a prismatic
    joint; :meth:`anthroarm.chain.Chain.configuration`): a joint's θ, or (cos θ, sin θ) for a
    continuous one (``index`` (n, 2), ``Chain._configuration_index``: its first entry in q,
    continuous or not; :func:`put_joint`)."""
    for i in range(theta.shape[0]):
        for k in range(theta.shape[1]):
            t, cont = theta[i, k], index[k, 1] != 0
            put_joint(
                q[i],
                index[k, 0],
                cont,
                t,
                math.cos(t) if cont else 0.0,
                math.sin(t) if cont else 0.0,
            )


__all__ = ["configure", "put_joint"]
