"""OpenSim ``.trc`` marker files: anthroarm's reader and writer against OpenSim's own
``TRCFileAdapter`` (the oracle), on the shipped Gait2354 walking trial, and bad input."""

import numpy as np
import pytest
from osim_recordings_data import TRC

from anthroarm.errors import MotionDataError
from anthroarm.motion import MarkerTrajectories, read_trc, write_trc


def opensim_trc(osim, path):
    """(labels, time, positions (N, M, 3) in the file's units, units) read by OpenSim."""
    table = osim.TimeSeriesTableVec3(str(path))
    flat = table.flatten()
    mat = flat.getMatrix()
    X = mat.to_numpy().copy()
    labels = tuple(table.getColumnLabels())
    time = np.array(table.getIndependentColumn())
    units = table.getTableMetaDataAsString("Units")
    return labels, time, X.reshape(len(time), len(labels), 3), units


def test_real_trial_equals_opensim(osim):
    trial = read_trc(TRC)
    labels, time, X, units = opensim_trc(osim, TRC)
    assert units == "mm" and trial.meta["units"] == "mm"
    assert trial.names == labels and len(trial.names) == 41 and trial.n_frames == 151
    assert trial.rate == 60.0 and trial.meta["status"] == "complete"
    np.testing.assert_array_equal(trial.meta["time"], time)
    np.testing.assert_allclose(trial.positions, X * 1e-3, rtol=0, atol=1e-15)


@pytest.mark.parametrize("units", ["mm", "m"])
def test_written_file_is_read_by_opensim(osim, tmp_path, units):
    trial = read_trc(TRC)
    P = trial.positions[:20].copy()
    P[3, 5] = np.nan  # a gap
    P[4:7, 0] = np.nan
    cut = MarkerTrajectories(
        trial.names, P, rate=trial.rate, meta={"time": trial.meta["time"][:20]}
    )
    out = write_trc(tmp_path / "w.trc", cut, units=units)
    labels, time, X, file_units = opensim_trc(osim, out)
    assert labels == trial.names and file_units == units
    np.testing.assert_array_equal(time, trial.meta["time"][:20])
    scale = 1e-3 if units == "mm" else 1.0
    assert np.array_equal(np.isnan(X), np.isnan(P))
    np.testing.assert_allclose(X * scale, P, rtol=1e-15, atol=0, equal_nan=True)
    back = read_trc(out)
    np.testing.assert_allclose(back.positions, P, rtol=1e-15, atol=0, equal_nan=True)
    assert not back.visible[3, 5] and back.visible[3, 4]


def _lines():
    return TRC.read_text().split("\n")


def _write(tmp_path, lines, name="bad.trc"):
    p = tmp_path / name
    p.write_text("\n".join(lines))
    return p


def _cell(line: str, k: int, value: str) -> str:
    cells = line.split("\t")
    cells[k] = value
    return "\t".join(cells)


# each case: how to damage the real file, and the text the error must contain
BAD = {
    "not a trc": (lambda L: ["hello", *L[1:]], "line 1: not a TRC file"),
    "key missing": (lambda L: [L[0], L[1].replace("Units", "Unit"), *L[2:]], "line 2"),
    "unknown units": (lambda L: [*L[:2], L[2].replace("mm", "furlong"), *L[3:]], "line 3: Units"),
    "units contradicted": (
        lambda L: [*L[:2], L[2].replace("\tmm\t", "\tm\t"), *L[3:]],
        "outside [0.01, 100] m",
    ),
    "rate": (lambda L: [*L[:2], "0" + L[2][5:], *L[3:]], "line 3: DataRate"),
    "marker renamed away": (
        lambda L: [*L[:3], L[3].replace("\tL.ASIS\t", "\t\t"), *L[4:]],
        "line 4 names 40 markers, line 3 says NumMarkers 41",
    ),
    "duplicate label": (
        lambda L: [*L[:3], L[3].replace("L.ASIS", "R.ASIS"), *L[4:]],
        "line 4: marker labels ['R.ASIS'] appear twice",
    ),
    "xyz labels": (lambda L: [*L[:4], L[4].replace("Y2", "Q2"), *L[5:]], "line 5"),
    "ragged row": (lambda L: [*L[:10], L[10].rsplit("\t", 4)[0], *L[11:]], "line 11: "),
    "non-numeric": (lambda L: [*L[:12], _cell(L[12], 7, "12,5"), *L[13:]], "line 13: Z of marker"),
    "infinite": (lambda L: [*L[:12], _cell(L[12], 3, "inf"), *L[13:]], "line 13: Y of marker"),
    "time backwards": (lambda L: [*L[:14], _cell(L[14], 1, "0.0"), *L[15:]], "line 15: Time"),
    "blank inside": (lambda L: [*L[:20], "", *L[20:]], "line 22: data after the blank line 21"),
    "frames missing": (lambda L: L[:-10], "NumFrames 151, the file holds 142 rows"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_names_the_line(tmp_path, case):
    damage, text = BAD[case]
    p = _write(tmp_path, damage(_lines()))
    with pytest.raises(MotionDataError) as err:
        read_trc(p)
    assert text in str(err.value), str(err.value)
    assert str(p) in str(err.value)


def test_partial_reads_with_a_status(tmp_path):
    p = _write(tmp_path, _lines()[:-10])
    trial = read_trc(p, partial=True)
    assert trial.n_frames == 142 and trial.meta["status"] == "truncated"


def test_units_override_and_contradiction(tmp_path):
    L = _lines()
    p = _write(tmp_path, [*L[:2], L[2].replace("\tmm\t", "\tm\t"), *L[3:]])
    trial = read_trc(p, units="mm")  # the header is wrong; the caller knows better
    np.testing.assert_array_equal(trial.positions, read_trc(TRC).positions)


def test_gaps_and_partial_samples(tmp_path, osim):
    L = _lines()
    row = L[6].split("\t")
    row[2:5] = ["", "", ""]  # R.ASIS missing in frame 1
    row[6] = ""  # L.ASIS's Z missing: the marker is missing (OpenSim's rule)
    p = _write(tmp_path, [*L[:6], "\t".join(row), *L[7:]])
    trial = read_trc(p)
    assert not trial.visible[0, 0] and not trial.visible[0, 1] and trial.visible[0, 2]
    assert trial.meta["partial_samples"] == 1
    _, _, X, _ = opensim_trc(osim, p)
    assert np.array_equal(np.isnan(X).any(axis=2), ~trial.visible)


def test_not_a_regular_file():
    with pytest.raises(MotionDataError, match="not a regular file"):
        read_trc("/dev/zero")
