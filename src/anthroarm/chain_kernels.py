"""Compiled kernels of :mod:`anthroarm.chain` (:mod:`anthroarm.jit`), in a module of their own so
that reading a model does not import Numba."""

from __future__ import annotations

import math

from .jit import kernel


@kernel
def configure(theta, index, q):
    """q (N, nq) from the positions θ (N, n) of the independent joints (rad, m for a prismatic
    joint; :meth:`anthroarm.chain.Chain.configuration`): a joint's θ, or (cos θ, sin θ) for a
    continuous one (``index`` (n, 2), ``Chain._configuration_index``: its first entry in q,
    continuous or not)."""
    for i in range(theta.shape[0]):
        for k in range(theta.shape[1]):
            j = index[k, 0]
            if index[k, 1]:
                q[i, j], q[i, j + 1] = math.cos(theta[i, k]), math.sin(theta[i, k])
            else:
                q[i, j] = theta[i, k]


__all__ = ["configure"]
