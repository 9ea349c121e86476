"""Compiled kernels of :mod:`anthroarm.chain` (:mod:`anthroarm.jit`), in a module of their own so
that reading a model does not import Numba."""

from __future__ import annotations

import math

from .jit import kernel


@kernel
def configure(theta, index, q):
    """q (N, nq) from θ (N, n) of the independent joints (:meth:`Chain.configuration`; ``index``
    :attr:`Chain._configuration_index`)."""
    for i in range(theta.shape[0]):
        for k in range(theta.shape[1]):
            j = index[k, 0]
            if index[k, 1]:
                q[i, j], q[i, j + 1] = math.cos(theta[i, k]), math.sin(theta[i, k])
            else:
                q[i, j] = theta[i, k]


__all__ = ["configure"]
