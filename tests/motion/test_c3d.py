"""C3D files in and out (``anthroarm.motion.c3d``): edge cases of units, missing samples,
garbage, truncated and damaged files."""

import numpy as np
import pytest
from motion_synthetic import known_motion, pin_marker_positions

import anthroarm as aa
from anthroarm.errors import C3DError, MotionDataError
from anthroarm.motion import MarkerTrajectories, marker_ik, read_c3d, write_c3d


def _write_with_units(path, P, names, unit, scale):
    """A C3D written directly with ezc3d (not through write_c3d) in any POINT:UNITS."""
    import ezc3d

    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [50.0]
    c["parameters"]["POINT"]["LABELS"]["value"] = list(names)
    c["parameters"]["POINT"]["UNITS"]["value"] = [unit]
    pts = np.ones((4, P.shape[1], P.shape[0]))
    pts[:3] = P.transpose(2, 1, 0) * scale
    c["data"]["points"] = pts
    c.write(str(path))


def test_c3d_units_are_converted(tmp_path, arm, markers):
    _, Q = known_motion(arm, n=5)
    P = pin_marker_positions(arm, markers, Q)
    for unit, scale in (("mm", 1000.0), ("cm", 100.0), ("m", 1.0)):
        _write_with_units(tmp_path / f"u_{unit}.c3d", P, markers.names, unit, scale)
        tr = read_c3d(tmp_path / f"u_{unit}.c3d")
        assert tr.rate == 50.0 and tr.names == markers.names
        np.testing.assert_allclose(tr.positions, P, atol=1e-6)
    _write_with_units(tmp_path / "u_in.c3d", P, markers.names, "in", 39.37)
    with pytest.raises(C3DError, match="POINT:UNITS is 'in'"):
        read_c3d(tmp_path / "u_in.c3d")


def test_c3d_negative_residual_is_a_missing_sample(tmp_path):
    """A capture system may leave finite coordinates in a sample it flags invalid (residual < 0,
    the C3D convention): the sample is missing however plausible its coordinates (ezc3d reads
    them as NaN; read_c3d relies on that)."""
    import ezc3d

    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [100.0]
    c["parameters"]["POINT"]["LABELS"]["value"] = ["A", "B"]
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    pts = np.ones((4, 2, 3))
    pts[:3] = 100.0
    c["data"]["points"] = pts
    res = np.zeros((1, 2, 3))
    res[0, 1, 2] = -1.0  # marker B, frame 2: invalid, coordinates left at 100 mm
    c["data"]["meta_points"] = {"residuals": res, "camera_masks": np.zeros((7, 2, 3), dtype=bool)}
    c.write(str(tmp_path / "r.c3d"))
    tr = read_c3d(tmp_path / "r.c3d")
    assert tr.visible.tolist() == [[True, True], [True, True], [True, False]]
    np.testing.assert_allclose(tr.positions[2, 0], [0.1, 0.1, 0.1], rtol=1e-6)
    assert np.isnan(tr.positions[2, 1]).all()


def test_c3d_bad_files(tmp_path):
    with pytest.raises(C3DError, match="not found"):
        read_c3d(tmp_path / "nope.c3d")
    (tmp_path / "garbage.c3d").write_bytes(b"this is not a c3d file" * 50)
    with pytest.raises(C3DError, match="not a C3D file"):
        read_c3d(tmp_path / "garbage.c3d")
    (tmp_path / "short.c3d").write_bytes(b"garbage")
    with pytest.raises(C3DError, match="not a C3D file"):
        read_c3d(tmp_path / "short.c3d")
    with pytest.raises(C3DError, match="not a file"):
        read_c3d(tmp_path)


def test_c3d_truncated_and_damaged_files_are_c3d_errors(tmp_path):
    """A file cut short is refused (ezc3d alone returns the frames it found, silently); a damaged
    parameter section is refused before ezc3d reads it.  With ezc3d 1.7.2 alone (measured in a
    subprocess when this test was written) "group" is a RuntimeError, "desc" never returns and
    "sign" kills the interpreter with SIGSEGV."""
    P = np.random.default_rng(0).uniform(-1, 1, (50, 10, 3))
    write_c3d(
        tmp_path / "good.c3d", MarkerTrajectories([f"M{i}" for i in range(10)], P, rate=100.0)
    )
    good = (tmp_path / "good.c3d").read_bytes()
    assert read_c3d(tmp_path / "good.c3d").n_frames == 50
    for cut, needle in ((600, "parameter section"), (len(good) // 2, "announces 50 frames")):
        (tmp_path / "cut.c3d").write_bytes(good[:cut])
        with pytest.raises(C3DError, match=needle):
            read_c3d(tmp_path / "cut.c3d")
    # the parameter records of an ezc3d-written file: group POINT first, then its parameters
    start = (good[0] - 1) * 512
    assert (
        good[start + 4 : start + 6] == bytes([5, 0xFF]) and good[start + 6 : start + 11] == b"POINT"
    )
    records, i = [], start + 4
    while good[i]:
        n = abs(int.from_bytes(good[i : i + 1], "little", signed=True))
        records.append((i, good[i + 2 : i + 2 + n].decode()))
        nxt = int.from_bytes(good[i + 2 + n : i + 4 + n], "little", signed=True)
        if nxt == 0:
            break
        i = i + 2 + n + nxt
    where = dict((name, at) for at, name in records)
    damaged = {}
    d = bytearray(good)  # a parameter of a group id no group has
    d[where["USED"] + 1] = 100
    damaged["group"] = bytes(d)
    d = bytearray(good)  # a parameter's group id flipped negative (read as a group)
    d[where["FORMAT"] + 1] = 0xA7
    damaged["sign"] = bytes(d)
    d = bytearray(good)  # a description length that runs into the next record
    at = where["RATE"]
    d[at + 2 + 4 + 2 + 2 + 4] = 200  # name length, group, "RATE", offset, type + 0 dims, float
    damaged["desc"] = bytes(d)
    for kind, data in damaged.items():
        (tmp_path / f"{kind}.c3d").write_bytes(data)
        with pytest.raises(C3DError, match="damaged C3D parameter section"):
            read_c3d(tmp_path / f"{kind}.c3d")
    with pytest.raises(MotionDataError, match="duplicate"):
        MarkerTrajectories(["A", "A"], np.zeros((2, 2, 3)))
    with pytest.raises(MotionDataError, match="shape"):
        MarkerTrajectories(["A"], np.zeros((2, 2, 3)))
    with pytest.raises(C3DError, match="folder"):
        write_c3d(tmp_path / "no" / "x.c3d", MarkerTrajectories(["A"], np.ones((3, 1, 3))))
    with pytest.raises(C3DError, match="is a folder"):
        write_c3d(tmp_path, MarkerTrajectories(["A"], np.ones((3, 1, 3))))
    with pytest.raises(C3DError, match="255 bytes"):  # ezc3d writes it, then cannot read it
        write_c3d(tmp_path / "long.c3d", MarkerTrajectories(["A" * 256], np.ones((3, 1, 3))))
    assert not (tmp_path / "long.c3d").exists()
    # a coordinate no lab holds (wrong units, a corrupt sample): its squares would overflow to inf
    with pytest.raises(MotionDataError, match="marker 'B' in frame 2 .* beyond 1e\\+06 m"):
        MarkerTrajectories(
            ["A", "B"], np.where(np.arange(12).reshape(2, 2, 3) == 9, 1e200, 1.0).repeat(2, 0)
        )
    with pytest.raises(MotionDataError, match="wrong units"):
        marker_ik(aa.load("human_arm7"), np.full((2, 10, 3), 2e6))
    # a zero sample is a gap (old capture systems write (0, 0, 0) for missing markers)
    P = np.ones((4, 2, 3))
    P[1, 0] = 0.0
    write_c3d(tmp_path / "z.c3d", MarkerTrajectories(["A", "B"], P))
    assert read_c3d(tmp_path / "z.c3d").visible.tolist() == [
        [True, True],
        [False, True],
        [True, True],
        [True, True],
    ]
    assert read_c3d(tmp_path / "z.c3d", zero_is_missing=False).visible.all()
    # no half-written file: a failing write leaves the old file and no temp file
    before = (tmp_path / "z.c3d").read_bytes()
    with pytest.raises(C3DError):
        write_c3d(tmp_path / "z.c3d", "not a trial")
    assert (tmp_path / "z.c3d").read_bytes() == before and not list(tmp_path.glob(".*tmp*"))
