"""``@kernel(inline=True)`` compiles the kernel's source into each caller (Numba's
``inline="always"``), as it says: Numba's inliner reads the ``targetoptions`` of the global a
kernel calls, which a :class:`anthroarm.jit.Kernel` must show.  An inlined kernel is never
compiled as a function of its own: its dispatcher has no signature after its caller compiled.
The one-pose IK kernel (``ik/geometric/verify.py``) relies on it: a ``_pose_plan`` tuple of a
dozen arrays returned by a call, not inlined, cost a third of the call."""

from __future__ import annotations

import numpy as np

from anthroarm.jit import kernel, reference


@kernel(inline=True)
def _scaled(a, k):
    return a[0] * k, a[1] * k  # a tuple holding array values: what an inlined plan returns


@kernel
def _not_inlined(a, k):
    return a[0] * k


@kernel
def _caller(a):
    x, y = _scaled(a, 2.0)
    return x + y + _not_inlined(a, 3.0)


def test_an_inline_kernel_shows_numba_its_inline_option():
    assert _scaled.targetoptions.get("inline") == "always"
    assert _not_inlined.targetoptions.get("inline") is None


def test_an_inline_kernel_is_compiled_into_its_caller():
    a = np.array([1.0, 2.0])
    assert _caller.dispatcher(a) == 2.0 + 4.0 + 3.0
    assert reference(_caller)(a) == 9.0
    assert _caller.dispatcher.signatures
    assert not _scaled.dispatcher.signatures  # never compiled as a function: inlined
    assert _not_inlined.dispatcher.signatures  # called as one
