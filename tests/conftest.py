"""Shared test configuration."""

import os

import matplotlib
import pytest

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")
# The suite tests the compiled kernels: each compiles (or loads) on first use, in the test's
# thread (anthroarm.jit mode "compile"), so no test depends on when a background compilation
# ends.  The default mode "auto" (the reference path while compiling in the background) is
# tested by tests that start their own processes (tests/foundation/test_jit_modes.py,
# tests/adversarial/test_cold_start.py).
os.environ.setdefault("ANTHROARM_JIT", "compile")


def _same_urdf_text(a: str, b: str, rtol: float = 1e-12) -> bool:
    """Two URDF texts equal up to the last bits of their numbers: every token equal, numbers to
    ``rtol`` (relative, 1 absolute floor).  A generator's floats differ in the 16th digit
    between numpy/libm builds (rpy from a rotation, a 0 printed as -6.9e-18); a stale file
    differs by far more."""
    import re

    split = re.compile(r"(-?\d+\.?\d*(?:[eE][-+]?\d+)?)")
    ta, tb = split.split(a), split.split(b)
    if len(ta) != len(tb):
        return False
    for i, (x, y) in enumerate(zip(ta, tb)):
        if i % 2 == 0:
            if x != y:
                return False
        elif abs(float(x) - float(y)) > rtol * max(1.0, abs(float(x)), abs(float(y))):
            return False
    return True


@pytest.fixture
def same_urdf_text():
    """:func:`_same_urdf_text` for the committed-URDF tests."""
    return _same_urdf_text
