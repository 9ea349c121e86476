"""The local arrays of kernels (jit.local*: in the kernel's stack frame) and their views
(jit.view2, view3): values and shapes, compiled and in the reference (the interpreter), the
owner a returned view keeps alive, and the arguments they refuse."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from anthroarm.jit import (
    borrow,
    kernel,
    local,
    local2,
    local_flags,
    local_ints2,
    part,
    part2,
    reference,
    view2,
    view3,
)


@kernel
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
    v = a[:4].reshape((2, 14))  # a view of a local array
    out[0] = v[1, 13]
    out[1] = b.sum()
    out[2] = c[1] and not c[2]
    out[3] = d[1, 2]
    return a.shape[0] * 100 + a.shape[1] * 10 + b.shape[0]


@pytest.mark.parametrize("run", ["compiled", "reference"])
def test_local_arrays_hold_what_is_written(run):
    f = _fill.dispatcher if run == "compiled" else reference(_fill)
    out = np.zeros(4)
    assert f(2.0, out) == 875
    # a[3, 6] = 2·3 + 6; Σ 2i over 0..4; c[1] and not c[2]; d[1, 2]
    assert out.tolist() == [12.0, 20.0, 1.0, 12.0]


def test_local_sizes_must_be_literal():
    @numba.njit
    def runtime_size(n):
        return local(n).shape[0]

    with pytest.raises(numba.core.errors.TypingError):
        runtime_size(3)


@kernel
def _views(a, n, out):
    v, w = view2(a, 3, n), view3(a[2:], 2, 2, 2)
    s = view2(local(12), 3, n)  # a view of a local array
    for i in range(3):
        for j in range(n):
            s[i, j] = v[i, j] * 2.0
    out[0], out[1], out[2] = v[2, 1], w[1, 1, 0], s[2, 3]
    out[3], out[4], out[5], out[6] = v.shape[0], v.shape[1], v.strides[0], w.strides[1]


@kernel
def _view_returned(a):
    return view2(a, 2, 3)


@pytest.mark.parametrize("run", ["compiled", "reference"])
def test_views_are_numpys_reshape_of_the_leading_entries(run):
    f = _views.dispatcher if run == "compiled" else reference(_views)
    a = np.arange(20.0)
    out = np.zeros(7)
    f(a, 4, out)
    v, w = a[:12].reshape(3, 4), a[2:10].reshape(2, 2, 2)
    assert out.tolist() == [v[2, 1], w[1, 1, 0], 2 * v[2, 3], 3, 4, v.strides[0], w.strides[1]]


def test_a_returned_view_keeps_its_owner_alive():
    a = np.arange(6.0) + 0.5
    x = _view_returned(a)
    del a
    import gc

    gc.collect()
    assert x.tolist() == [[0.5, 1.5, 2.5], [3.5, 4.5, 5.5]]
    b = np.arange(6, dtype=np.int64)
    assert _view_returned(b).dtype == np.int64 and _view_returned(b)[1, 2] == 5


def test_a_view_takes_only_c_order_arrays():
    with pytest.raises(numba.core.errors.TypingError, match="C-order"):
        _view_returned(np.arange(12.0)[::2])


@kernel
def _parts(a, ints, out):
    v, w = part(a, 3, 4), part2(a, 5, 2, 3)
    k = part2(ints, 2, 2, 2)
    out[0], out[1], out[2] = v[0], v[3], w[1, 2]
    out[3], out[4] = w.shape[0], w.strides[0]
    out[5] = k[1, 0]
    w[0, 0] = -1.0  # a view: writes reach a


@pytest.mark.parametrize("run", ["compiled", "reference"])
def test_parts_are_numpys_flat_slices(run):
    f = _parts.dispatcher if run == "compiled" else reference(_parts)
    a, ints = np.arange(20.0), np.arange(10)
    out = np.zeros(6)
    f(a, ints, out)
    w = np.arange(20.0)[5:11].reshape(2, 3)
    assert out.tolist() == [3.0, 6.0, w[1, 2], 2, w.strides[0], 4]
    assert a[5] == -1.0


@kernel
def _borrowed(a, ints, out):
    b, k, o = borrow(a), borrow(ints), borrow(out)
    o[0], o[1] = b[1, 2], b.strides[0]
    o[2], o[3] = b.shape[0] * 10 + b.shape[1], k[3]
    b[0, 0] = -1.0  # the same data: writes reach a
    return _sum_rows(b)  # passed on to another kernel, borrowed


@kernel
def _sum_rows(a):
    s = 0.0
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            s += a[i, j]
    return s


@pytest.mark.parametrize("run", ["compiled", "reference"])
def test_a_borrowed_array_is_the_array(run):
    f = _borrowed.dispatcher if run == "compiled" else reference(_borrowed)
    a, ints, out = np.arange(12.0).reshape(3, 4), np.arange(5), np.zeros(4)
    expected_sum = np.arange(12.0).sum() - 0.0 - 1.0  # a[0, 0] (0) became −1
    assert f(a, ints, out) == expected_sum
    assert out.tolist() == [6.0, 32.0, 34.0, 3.0]
    assert a[0, 0] == -1.0


def test_borrow_takes_only_c_order_arrays():
    with pytest.raises(numba.core.errors.TypingError, match="C-order"):
        _borrowed.dispatcher(np.zeros((4, 6))[:, ::2], np.arange(5), np.zeros(4))
