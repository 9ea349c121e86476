"""``jit.switch(kernels)``: a kernel picked by an index known at run time — in a compiled
caller an if-chain written out from the tuple (Numba ``overload``), from Python or a reference
the tuple itself.  The IK-Geo class registry dispatches its class kernels with it, so a class
is added by its module and one registry line (``anthroarm.ik.classes``)."""

from __future__ import annotations

import warnings

import numba
import numpy as np
import pytest

from anthroarm.jit import callees, kernel, reference, switch


@kernel
def _plus(x, out):
    out[0] = x + 1.0
    return 1


@kernel
def _times(x, out):
    out[0] = 10.0 * x
    return 2


@kernel
def _minus(x, out):
    out[0] = -x
    return 3


_pick = switch((_plus, _times, _minus))


@kernel
def _caller(k, x, out):
    return _pick(k, x, out)


@pytest.mark.parametrize(
    "k, value, ret", [(0, 3.0, 1), (1, 20.0, 2), (2, -2.0, 3), (7, -2.0, 3), (-1, -2.0, 3)]
)
def test_a_switch_calls_the_kernel_of_its_index(k, value, ret):
    for run in (_caller.dispatcher, reference(_caller), lambda *a: _pick(*a)):
        out = np.zeros(1)
        assert run(k, 2.0, out) == ret  # an index out of range: the last kernel, as compiled
        assert out[0] == value


@kernel
def _caller_once(k, x, out):
    return _pick(k, x, out)


def test_a_switch_is_compiled_as_direct_calls():
    """Compiled as an if-chain of calls of the kernels themselves: no first-class function
    objects (Numba warns when it makes them: ``NumbaExperimentalFeatureWarning``)."""
    out = np.zeros(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", numba.errors.NumbaExperimentalFeatureWarning)
        assert _caller_once.dispatcher(1, 2.0, out) == 2
    assert all(k.dispatcher.signatures for k in (_plus, _times, _minus))  # each compiled
    assert {id(c) for c in callees(_caller)} >= {id(_plus), id(_times), id(_minus)}


def test_the_reference_of_a_caller_runs_the_references_of_the_switch(monkeypatch):
    """``reference(caller)`` runs the switch's kernels as references too, whatever the process
    runs for them (``Kernel.fn``: compiled code once switched)."""

    def not_the_reference(*args):
        raise AssertionError("the reference called the kernel's compiled form")

    ref = reference(_caller)
    monkeypatch.setattr(_minus, "fn", not_the_reference)
    out = np.zeros(1)
    assert ref(2, 2.0, out) == 3 and out[0] == -2.0
    with pytest.raises(AssertionError, match="compiled form"):
        _pick(2, 2.0, out)  # from Python the switch calls the kernel as the process runs it


def test_a_switch_takes_kernels_only():
    with pytest.raises(TypeError, match="non-empty tuple of kernels"):
        switch(())
    with pytest.raises(TypeError, match="non-empty tuple of kernels"):
        switch((_plus, abs))
