"""Spatial cell method, book §7-3 Eq. (7-32): property tests and the book's error bounds
(ch7 notes §4 E2).  Expected values: the exact IK's FK (Pinocchio) and mathematics."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.ik.cells import (
    CORNERS,
    CellTable,
    OutsideCellTableError,
    nested_division,
    trilinear_weights,
)

# "hand horizontal and forward": l = (0, -1, 0), m = (0, 0, -1), n = (1, 0, 0) (Table 7.2 row 9)
R_FWD = np.array([[0.0, 0, 1], [-1, 0, 0], [0, -1, 0]])
BOX = ((0.2, -0.4, -0.25), (0.6, 0.15, 0.25))
PATHS_MM = [((350, -250, -60), (480, 50, 60)), ((300, -300, -150), (300, -300, 150))]
# (D mm, bound on |Δx|, |Δy| mm): the book prints x errors ≤ 2.5 / 1.2 / 0.5 mm at D = 50 / 37.5 /
# 25 (l. 5212-5216); the notes reproduce 1.96 / 1.25 / 0.52 and recommend these bounds.
BOUNDS = [(50.0, 2.5), (37.5, 1.5), (25.0, 0.6)]


@pytest.fixture(scope="module")
def arm():
    return aa.load("prosthetic_arm")


@pytest.fixture(scope="module")
def tables(arm):
    return {D: CellTable.build(arm, R_FWD, D / 1000, BOX, progress=False) for D, _ in BOUNDS}


@pytest.mark.parametrize("D,bound", BOUNDS)
@pytest.mark.parametrize("path", PATHS_MM)
def test_cell_error_bounds_on_straight_paths(arm, tables, D, bound, path):
    P = np.linspace(*path, 61) / 1000
    look = tables[D].lookup_batch(P)
    assert look.ok.all()
    T = arm.fk(look.q)
    err = np.abs(T[:, :3, 3] - P).max(0) * 1000  # mm
    assert err[0] <= bound and err[1] <= bound
    assert err[2] <= 1.0  # z ≤ 1.0 mm (l. 5194)
    assert np.abs(T[:, :3, :3] - R_FWD).max() <= 0.01  # direction cosines ≤ 1 %
    assert err.max() > 0  # interpolation is not exact between lattice points


def test_cell_error_shrinks_with_D(arm, tables):
    P = np.linspace(*PATHS_MM[0], 61) / 1000
    errs = [np.abs(arm.fk(tables[D].lookup_batch(P).q)[:, :3, 3] - P).max() for D, _ in BOUNDS]
    assert errs[0] > errs[1] > errs[2]


def test_cell_one_newton_step(arm, tables):
    """Cell guess + one Newton step: 1.96 mm -> below 0.01 mm at D = 50 mm (notes: 0.0066 mm)."""
    tab = tables[50.0]
    P = np.linspace(*PATHS_MM[0], 21) / 1000
    worst = 0.0
    for p in P:
        q = tab.refine(arm, p, tab.lookup(p))
        worst = max(worst, np.abs(arm.fk(q)[:3, 3] - p).max())
    assert worst < 1e-5


def test_cell_exact_at_lattice_points(arm, tables):
    tab = tables[37.5]
    ii = np.argwhere(tab.valid)[::37]
    for i, j, k in ii:
        p = tab.origin + tab.D * np.array([i, j, k])
        if not tab.cell_ok[tuple(np.minimum([i, j, k], np.array(tab.shape) - 2))]:
            continue
        q = tab.lookup(p)
        np.testing.assert_allclose(q, tab.Q[i, j, k], atol=1e-12)
        np.testing.assert_allclose(arm.fk(q)[:3, 3], p, atol=1e-10)


@settings(max_examples=50, deadline=None)
@given(st.tuples(*[st.floats(0, 1)] * 3))
def test_cell_weights(m):
    w = trilinear_weights(m)
    assert np.all(w >= 0) and abs(w.sum() - 1) < 1e-12
    # the weights interpolate the corner positions exactly: Σ w_c · corner_c = m
    np.testing.assert_allclose(w @ CORNERS, m, atol=1e-12)
    # the book's chain N1..N6, P0 equals the expanded form (7-32)
    M = np.random.default_rng(0).normal(size=(8, 4))
    np.testing.assert_allclose(nested_division(M, m), w @ M, atol=1e-12)


def _printed_chain(M, m):
    """The chain as printed (l. 5159): N2 = t1 M2 - m1 M4, N3 = t3 M3 + m1 M6, N6 = t2 N1 + m2 N3,
    N8 = t2 N5 + m2 N4 (no N5 defined; we read the printed N8 as the result's second input)."""
    m1, m2, m3 = m
    t1, t2, t3 = 1 - m1, 1 - m2, 1 - m3
    N1 = t1 * M[0] + m1 * M[1]
    N2 = t1 * M[2] - m1 * M[4]  # noqa: F841 - printed, unused by the chain
    N3 = t3 * M[3] + m1 * M[6]
    N4 = t1 * M[5] + m1 * M[7]
    N6 = t2 * N1 + m2 * N3
    N8 = t2 * N6 + m2 * N4
    return t3 * N6 + m3 * N8


def test_cell_printed_chain_fails():
    """The printed linear-division chain does not reproduce a constant field (weights do not sum to
    1)."""
    M = np.ones((8, 1))
    assert abs(_printed_chain(M, (0.3, 0.6, 0.2))[0] - 1.0) > 0.05
    assert abs(nested_division(M, (0.3, 0.6, 0.2))[0] - 1.0) < 1e-12


def test_cell_save_load_roundtrip(arm, tables, tmp_path):
    tab = tables[50.0]
    path = tab.save(tmp_path / "cells")
    assert path.suffix == ".npz" and path.exists()
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left behind
    back = CellTable.load(path)
    np.testing.assert_array_equal(back.Q, tab.Q)
    np.testing.assert_array_equal(back.valid, tab.valid)
    assert (
        back.D == tab.D
        and back.matches(arm)
        and not back.matches(aa.load("prosthetic_arm", L2=0.24))
    )
    p = np.array([0.4, -0.1, 0.0])
    np.testing.assert_array_equal(back.lookup(p), tab.lookup(p))
    (tmp_path / "junk.npz").write_bytes(b"not a table")
    with pytest.raises(ValueError, match="not a cell table"):
        CellTable.load(tmp_path / "junk.npz")


def test_cell_bad_queries(arm, tables):
    tab = tables[50.0]
    with pytest.raises(OutsideCellTableError):
        tab.lookup([2.0, 0.0, 0.0])
    with pytest.raises(ValueError):
        tab.lookup([np.nan, 0, 0])
    look = tab.lookup_batch(np.array([[2.0, 0, 0], [0.4, -0.1, 0.0]]))
    assert look.ok.tolist() == [False, True] and np.isnan(look.q[0]).all()
    with pytest.raises(ValueError):
        CellTable.build(arm, R_FWD, -0.05, BOX, progress=False)
    with pytest.raises(ValueError):
        CellTable.build(arm, R_FWD * 2, 0.05, BOX, progress=False)


def test_cell_progress_bar(arm, capsys):
    CellTable.build(arm, R_FWD, 0.1, BOX, progress=True)
    err = capsys.readouterr().err
    assert "cell table prosthetic_arm" in err
