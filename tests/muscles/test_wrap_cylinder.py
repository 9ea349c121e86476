"""The cylinder wrap's kernels (:mod:`anthroarm.muscles.wrap_cylinder`): the interpreter's
reference and the compiled kernel give the same answers (the pattern of
tests/foundation/test_jit_modes.py), on complex-step rows over every branch: inside, no wrap,
mandatory and one-sided wraps, one cylinder and the tangent points slid along the axis.  What
the answers are worth is tested against OpenSim (test_paths_vs_opensim.py) and central
differences (test_wrap_multi_exact.py)."""

from __future__ import annotations

import numpy as np

from anthroarm import jit
from anthroarm.muscles.wrap_cylinder import INSIDE, MANDATORY, NO_WRAP, WRAPPED, wrap_cylinder
from anthroarm.muscles.wrap_ellipsoid import H


def _rows(p, d=7):
    """Complex-step rows of the six numbers p: row 0 real, row 1 + k moved by i h along k."""
    P = np.tile(np.asarray(p, dtype=complex), (d, 1))
    P[np.arange(1, d), np.arange(d - 1)] += 1j * H
    return np.ascontiguousarray(P[:, :3]), np.ascontiguousarray(P[:, 3:])


def test_reference_answers_as_compiled():
    rng = np.random.default_rng(5)
    ref = jit.reference(wrap_cylinder)
    seen = set()
    for _ in range(60):
        p = rng.uniform(-0.06, 0.06, 6)
        quad = [(0, 0), (1, -1), (0, 1), (2, 1)][rng.integers(4)]
        for single in (True, False):
            args = (*_rows(p), 0.02, 0.3, quad[0], quad[1], single)
            c = wrap_cylinder.dispatcher(*args)
            r = ref(*args)
            assert c[0] == r[0]
            seen.add(c[0])
            for a, b in zip(c[1:], r[1:]):
                np.testing.assert_allclose(a.real, b.real, rtol=0, atol=1e-13)
                np.testing.assert_allclose(a.imag / H, b.imag / H, rtol=1e-9, atol=1e-12)
    assert {INSIDE, NO_WRAP, WRAPPED, MANDATORY} <= seen, seen
