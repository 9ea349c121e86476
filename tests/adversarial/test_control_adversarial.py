"""Hostile inputs to the control surface (issue 30): anthroarm.control (DDA, interpolation, servo,
motor, bilateral, gripper, teach/playback) and anthroarm.trajectory.  Every case is a typed error
from anthroarm.errors naming the parameter, or a correct (finite) answer; none may hang, crash
inside numpy/Python, or hand back NaN/inf."""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import time

import numpy as np
import pytest

from anthroarm.control import dda as dda_mod
from anthroarm.control import gripper
from anthroarm.control.bilateral import Bilateral
from anthroarm.control.interpolation import (
    arc_poses,
    circle_through,
    line_points,
    line_poses,
)
from anthroarm.control.motor import DCMotor, rms
from anthroarm.control.servo import PositionServo
from anthroarm.control.teach import (
    Call,
    Jump,
    Program,
    Step,
    play_fixed,
    play_jump,
    play_random_access,
    play_select,
    play_subroutines,
    record,
)
from anthroarm.errors import (
    AnthroarmError,
    ControlError,
    DegenerateArcError,
    ParameterError,
    PlaybackError,
)


@contextlib.contextmanager
def within(seconds: float):
    """Fail (instead of hanging the suite) when the block takes longer than ``seconds``."""

    def on_alarm(*_):
        raise TimeoutError(f"took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


SERVO = dict(k_m=0.1, k=0.01, J_m=1e-5, J_L=1e-3, i=100.0, k_a=10.0, k_p=1.0, k_s=0.01)


def _step(x, **kw):
    return Step([float(x), 0.0], 1.0, **kw)


# =============================================================================== control: DDA
@pytest.mark.parametrize(
    "counts",
    [
        [2**63],
        np.array([2**63], dtype=np.uint64),
        np.array([2**64 - 1], dtype=np.uint64),
        np.array([-(2**63)], dtype=np.int64),
        [2**62 + 1, 3],
    ],
    ids=["int 2^63", "uint64 2^63", "uint64 max", "int64 min", "just beyond 2^62"],
)
def test_dda_refuses_counts_beyond_the_range(counts):
    """Counts of 2**63 wrapped to negative counts with status "ok" (and uint64 2**64-1 to -1)."""
    with within(5), pytest.raises(ControlError, match="counts"):
        dda_mod.dda(counts)


@pytest.mark.parametrize("counts", [[1 + 2j], [True, False], ["3"]])
def test_dda_refuses_counts_that_are_not_integers(counts):
    with pytest.raises(ControlError, match="counts"):
        dda_mod.dda(counts)


def test_dda_huge_tick_count_names_the_budget():
    with within(5), pytest.raises(ControlError, match="budget"):
        dda_mod.dda([1, 2], n_ticks=10**12)


@pytest.mark.parametrize(
    "args",
    [
        (["a"], [1.0], 1.0),
        ([0.0, 0.0], [1.0, 1.0], [1.0, 2.0, 3.0]),
        ([0.0, 0.0], [1.0, 1.0], [[1.0, 2.0], [1.0, 2.0]]),
        ([], [], 1.0),
    ],
    ids=["string", "resolution length", "resolution 2-D", "no axes"],
)
def test_pulse_counts_refuses_malformed_input(args):
    with pytest.raises(ControlError):
        dda_mod.pulse_counts(*args)
