"""DDA pulse distribution against an accumulator written out tick by tick (the definition of a
DDA) and against the counting facts it must satisfy."""

import numpy as np
import pytest

from anthroarm.control.dda import dda, pulse_counts
from anthroarm.errors import ControlError


def accumulator_dda(counts, N):
    """The textbook DDA: add |Δ| every tick, pulse and subtract N on overflow."""
    acc = [0] * len(counts)
    out = []
    for _ in range(N):
        row = []
        for k, c in enumerate(counts):
            acc[k] += abs(c)
            if acc[k] >= N:
                acc[k] -= N
                row.append(1 if c > 0 else -1)
            else:
                row.append(0)
        out.append(row)
    return np.array(out, dtype=np.int8).reshape(N, len(counts))


@pytest.mark.parametrize(
    "counts,N",
    [
        ([7, -3, 0, 5], None),
        ([1, 1, 1], None),
        ([13, 8, -5, 2, 1], 16),
        ([255, 100, -37], 256),
        ([1], 1),
    ],
)
def test_equals_the_accumulator_and_counts_are_exact(counts, N):
    r = dda(counts, N)
    n = max(abs(c) for c in counts) if N is None else N
    assert r.n_ticks == n and r.status == "ok"
    assert np.array_equal(r.pulses, accumulator_dda(counts, n))
    assert np.array_equal(r.pulses.sum(axis=0), counts)  # exact counts
    assert np.array_equal(r.positions()[-1], counts)


def test_every_moving_axis_ends_on_the_last_tick_and_pulses_are_even():
    rng = np.random.default_rng(7)
    for _ in range(50):
        counts = rng.integers(-60, 61, size=rng.integers(1, 7))
        if not counts.any():
            continue
        N = int(np.abs(counts).max()) + int(rng.integers(0, 40))
        r = dda(counts, N)
        last = r.last_pulse_tick()
        assert np.all(last[counts != 0] == N)
        assert np.all(last[counts == 0] == 0)
        # never more than one pulse per tick; the path stays within one pulse of the straight line
        assert np.abs(r.pulses).max() <= 1
        j = np.arange(N + 1)[:, None]
        assert np.all(np.abs(r.positions() - j * counts[None, :] / N) < 1.0)
        for k, c in enumerate(counts):  # gaps between pulses differ by <= 1 tick
            ticks = np.nonzero(r.pulses[:, k])[0]
            if abs(c) > 1:
                gaps = np.diff(ticks)
                assert gaps.max() - gaps.min() <= 1


def test_no_motion_and_bad_inputs():
    r = dda([0, 0, 0])
    assert r.status == "no motion" and r.n_ticks == 0 and r.pulses.shape == (0, 3)
    assert dda([0, 0], 5).pulses.shape == (5, 2)
    with pytest.raises(ControlError, match="zero steps"):
        dda([3, 1], 0)
    with pytest.raises(ControlError, match="below the largest"):
        dda([3, 1], 2)
    with pytest.raises(ControlError, match="whole numbers"):
        dda([1.5, 2])
    with pytest.raises(ControlError):
        dda([])
    with pytest.raises(ControlError):
        dda([1, 2], 2.0)


def test_pulse_counts_round_trip():
    q0 = np.array([0.1, -0.2, 0.3])
    res = np.array([1e-3, 2e-3, 5e-4])
    c = np.array([120, -35, 7])
    q1 = q0 + c * res
    assert np.array_equal(pulse_counts(q0, q1, res), c)
    with pytest.raises(ControlError):
        pulse_counts(q0, q1, 0.0)


def test_care_robot_cell_table_move_by_dda():
    """§9-3: the position registers give the pulses of a move (difference of two cell-table
    lookups); the DDA hands them out so that all six motors end on the same tick, and the
    registers then hold exactly the target's table pulses."""
    import anthroarm as aa
    from anthroarm.ik.cells import cell_table

    table = cell_table(aa.load("care_robot"))
    a, b = np.array([0.30, -0.05, 0.10]), np.array([0.42, 0.12, 0.22])
    rel = table.relative_pulses(a, b)
    move = dda(rel)
    last = move.last_pulse_tick()
    assert np.all(last[rel != 0] == move.n_ticks) and move.n_ticks == np.abs(rel).max()
    assert np.array_equal(table.lookup_pulses(a) + move.positions()[-1], table.lookup_pulses(b))
