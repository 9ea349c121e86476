"""Kernels compiled without reference counts (jit.kernel(counted=False)) and their local
arrays (jit.local*): values, shapes, and the heap allocation they refuse."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from anthroarm.jit import kernel, local, local2, local_flags, local_ints2


@kernel(counted=False)
def _fill(x, out):
    a, b, c, d = local2(8, 7), local(5), local_flags(3), local_ints2(2, 3)
    for i in range(8):
        for j in range(7):
            a[i, j] = x * i + j
    for i in range(5):
        b[i] = i * x
    for i in range(3):
        c[i] = i % 2 == 1
    for i in range(2):
        for j in range(3):
            d[i, j] = 10 * i + j
    v = a[:4].reshape((2, 14))              # views of a local array, uncounted
    out[0] = v[1, 13]
    out[1] = b.sum()
    out[2] = c[1] and not c[2]
    out[3] = d[1, 2]
    return a.shape[0] * 100 + a.shape[1] * 10 + b.shape[0]


def test_local_arrays_hold_what_is_written():
    out = np.zeros(4)
    assert _fill(2.0, out) == 875
    # a[3, 6] = 2·3 + 6; Σ 2i over 0..4; c[1] and not c[2]; d[1, 2]
    assert out.tolist() == [12.0, 20.0, 1.0, 12.0]


def test_an_uncounted_kernel_refuses_a_heap_array():
    def allocates(n):
        return np.empty(n).sum()

    with pytest.raises(numba.core.errors.TypingError, match="empty"):
        kernel(counted=False)(allocates)(3)


def test_local_sizes_must_be_literal():
    @numba.njit
    def runtime_size(n):
        return local(n).shape[0]

    with pytest.raises(numba.core.errors.TypingError):
        runtime_size(3)
