"""Adversarial inputs to the motion-capture surface (issue 30, the motion family): C3D files
whose header or POINT:FRAMES announce more frames than they hold, an output path that is one of
the inputs, a marker on a ``null`` body, two subjects in one trial, duplicated CSV columns,
devices, FIFOs, oversized files and deeply nested JSON.  Every file here is real: the C3D files
are written with ezc3d and then cut or patched byte by byte; oversized files are sparse.
"""

from __future__ import annotations

import os
import struct
import threading
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.cli import main
from anthroarm.errors import AnthroarmError, C3DError, MarkerSetError, MotionDataError
from anthroarm.motion import (
    MarkerSet,
    MarkerTrajectories,
    default_marker_set,
    marker_ik,
    match_markers,
    read_c3d,
    read_joint_csv,
)

# ---------------------------------------------------------------------------- synthetic trials


def _motion(arm, n: int, seed: int) -> np.ndarray:
    """(n, nq) a small smooth motion around the comfortable posture, inside the limits."""
    from anthroarm.ik.qp import comfortable_posture

    rng = np.random.default_rng(seed)
    t = np.arange(n)[:, None] / 100.0
    half = 0.5 * (arm.upper - arm.lower)
    Q = comfortable_posture(arm) + 0.2 * half * np.sin(2 * np.pi * rng.uniform(0.3, 1, arm.nq) * t)
    return np.clip(Q, arm.lower + 1e-3, arm.upper - 1e-3)


def _marker_positions(arm, ms, Q) -> np.ndarray:
    """(N, M, 3) marker positions by Pinocchio frame placements (not anthroarm's kinematics)."""
    import pinocchio as pin

    data = arm.model.createData()
    fids = [arm.model.getFrameId(m.body) for m in ms]
    out = np.empty((len(Q), len(ms), 3))
    for n, q in enumerate(Q):
        pin.framesForwardKinematics(arm.model, data, q)
        for k, (m, f) in enumerate(zip(ms, fids)):
            out[n, k] = data.oMf[f].act(np.asarray(m.position, float))
    return out


# ---------------------------------------------------------------------------- C3D builders


def _ezc3d_file(path: Path, n_frames: int = 50, labels=("A", "B", "C"), rate=100.0) -> bytes:
    """A valid C3D written by ezc3d (float data, mm); returns its bytes."""
    import ezc3d

    rng = np.random.default_rng(len(labels) * 1000 + n_frames)
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c["parameters"]["POINT"]["LABELS"]["value"] = list(labels)
    c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
    pts = np.ones((4, len(labels), n_frames))
    pts[:3] = rng.uniform(100.0, 900.0, (3, len(labels), n_frames))
    c["data"]["points"] = pts
    c.write(str(path))
    return path.read_bytes()


def _records(data: bytes) -> dict:
    """(group id, name) -> byte offset of each parameter record (the C3D parameter section)."""
    out, i = {}, (data[0] - 1) * 512 + 4
    while data[i]:
        n = abs(struct.unpack("b", data[i : i + 1])[0])
        gid = struct.unpack("b", data[i + 1 : i + 2])[0]
        out[(gid, data[i + 2 : i + 2 + n].decode())] = i
        nxt = struct.unpack("<h", data[i + 2 + n : i + 4 + n])[0]
        if nxt == 0:
            break
        i += 2 + n + nxt
    return out


def _announce(data: bytes, *, header: int | None = None, point_frames: int | None = None) -> bytes:
    """``data`` with the header's last frame and/or POINT:FRAMES (int16) set."""
    b = bytearray(data)
    if header is not None:
        first = struct.unpack("<H", b[6:8])[0]
        b[8:10] = struct.pack("<H", first + header - 1)
    if point_frames is not None:
        at = _records(data)[(1, "FRAMES")]
        # name length, group id, "FRAMES", offset to next (2), type (1), 0 dimensions (1)
        assert b[at + 10 : at + 12] == bytes([2, 0])
        b[at + 12 : at + 14] = struct.pack("<h", point_frames)
    return bytes(b)


# ---------------------------------------------------------------------------- C3D frame counts


def test_c3d_point_frames_reaching_into_the_block_padding(tmp_path):
    """50 frames of one marker (16 bytes each) end inside the last 512-byte block.  ezc3d reads
    as many frames as POINT:FRAMES says: at 60 (the header still says 50) it returns 10 frames
    of the block's zero padding, silently.  Refused, naming the file and both counts."""
    good = _ezc3d_file(tmp_path / "g.c3d", 50, labels=("A",))
    bad = tmp_path / "more.c3d"
    bad.write_bytes(_announce(good, point_frames=60))
    with pytest.raises(C3DError, match="announces 60 frames.* holds 50") as ei:
        read_c3d(bad)
    assert str(bad) in str(ei.value) and "the header 50" in str(ei.value)
    # both agreeing on 60 cannot be told from a file ending in 10 frames of zeros: those frames
    # are read, and only as missing samples (never as markers at the origin)
    both = tmp_path / "both.c3d"
    both.write_bytes(_announce(good, header=60, point_frames=60))
    tr = read_c3d(both)
    assert tr.n_frames == 60 and tr.visible[:50].all() and not tr.visible[50:].any()


def test_c3d_point_frames_larger_than_header(tmp_path):
    """POINT:FRAMES (what ezc3d reads) says 60, the header 50: refused, both counts named."""
    good = _ezc3d_file(tmp_path / "g.c3d", 50, labels=("A",))
    bad = tmp_path / "pf.c3d"
    bad.write_bytes(_announce(good, point_frames=60))
    with pytest.raises(C3DError, match="60") as ei:
        read_c3d(bad)
    assert "50" in str(ei.value) and str(bad) in str(ei.value)


def test_c3d_announcing_beyond_the_file_names_the_frames_it_holds(tmp_path):
    """Announced 80, the file's bytes reach 64 frames of which 14 are block padding: the
    message says 50, not ezc3d's 64."""
    good = _ezc3d_file(tmp_path / "g.c3d", 50, labels=("A",))
    bad = tmp_path / "far.c3d"
    bad.write_bytes(_announce(good, header=80, point_frames=80))
    with pytest.raises(C3DError, match="announces 80 frames.* holds 50"):
        read_c3d(bad)


def test_c3d_partial_reading_is_explicit_and_has_a_status(tmp_path):
    good = _ezc3d_file(tmp_path / "g.c3d", 50, labels=("A", "B", "C"))
    full = read_c3d(tmp_path / "g.c3d")
    assert full.meta["status"] == "complete" and full.meta["frames_announced"] == 50
    data_start = (struct.unpack("<H", good[16:18])[0] - 1) * 512
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(good[: data_start + 37 * 48 + 20])  # 37 whole frames and part of one
    with pytest.raises(C3DError, match="announces 50 frames.* holds 37"):
        read_c3d(cut)
    part = read_c3d(cut, partial=True)
    assert part.n_frames == 37 and part.meta["status"] == "truncated"
    assert part.meta["frames_announced"] == 50
    np.testing.assert_array_equal(part.positions, full.positions[:37])
    padded = tmp_path / "padded.c3d"
    padded.write_bytes(_announce(_ezc3d_file(tmp_path / "a.c3d", 50, ("A",)), point_frames=60))
    tr = read_c3d(padded, partial=True)
    assert tr.n_frames == 50 and tr.meta["status"] == "truncated" and tr.visible.all()


# ---------------------------------------------------------------------------- not regular files


def _blocks(fn, timeout=10.0):
    """Run ``fn`` in a thread; return (finished, exception)."""
    box = {}

    def run():
        try:
            fn()
        except BaseException as exc:  # noqa: BLE001 - reported to the test
            box["exc"] = exc

    th = threading.Thread(target=run, daemon=True)
    th.start()
    th.join(timeout)
    return not th.is_alive(), box.get("exc")


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
@pytest.mark.parametrize(
    "reader, error",
    [
        (read_joint_csv, MotionDataError),
        (MarkerSet.read_json, MarkerSetError),
        (read_c3d, C3DError),
    ],
    ids=["csv", "marker_set", "c3d"],
)
def test_dev_zero_is_refused_without_reading_it(tmp_path, reader, error):
    link = tmp_path / "zero.file"
    link.symlink_to("/dev/zero")
    for p in ("/dev/zero", link):
        done, exc = _blocks(lambda p=p: reader(p))
        assert done, f"{reader.__qualname__}({p}) did not return"
        assert isinstance(exc, error) and "not a regular file" in str(exc), exc
        assert str(p) in str(exc)


@pytest.mark.parametrize(
    "reader, error",
    [(read_joint_csv, MotionDataError), (MarkerSet.read_json, MarkerSetError)],
    ids=["csv", "marker_set"],
)
def test_fifo_is_refused_without_waiting_for_a_writer(tmp_path, reader, error):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    try:
        done, exc = _blocks(lambda: reader(fifo), timeout=5.0)
    finally:  # release a reader blocked in open()
        fd = os.open(fifo, os.O_RDWR | os.O_NONBLOCK)
        os.close(fd)
    assert done and isinstance(exc, error) and "FIFO" in str(exc), exc


def test_oversized_files_are_refused_before_reading(tmp_path):
    from anthroarm.motion.c3d import MAX_C3D_BYTES
    from anthroarm.motion.csv_io import MAX_CSV_BYTES
    from anthroarm.motion.markers import MAX_MARKER_SET_BYTES

    csv = tmp_path / "big.csv"
    csv.write_text("t,a\n0,1\n")
    os.truncate(csv, MAX_CSV_BYTES + 1)  # sparse: no disk used
    with pytest.raises(MotionDataError, match=f"bound of {MAX_CSV_BYTES} bytes"):
        read_joint_csv(csv)
    js = tmp_path / "big.json"
    js.write_text('{"markers": {}}')
    os.truncate(js, MAX_MARKER_SET_BYTES + 1)
    with pytest.raises(MarkerSetError, match=f"bound of {MAX_MARKER_SET_BYTES} bytes"):
        MarkerSet.read_json(js)
    c3d = tmp_path / "big.c3d"
    _ezc3d_file(c3d, 5)
    os.truncate(c3d, MAX_C3D_BYTES + 1)  # a valid file with a sparse tail ezc3d would skip
    with pytest.raises(C3DError, match=f"bound of {MAX_C3D_BYTES} bytes"):
        read_c3d(c3d)


def test_deeply_nested_marker_set_json_is_a_typed_error(tmp_path):
    from anthroarm.motion.markers import MAX_MARKER_SET_DEPTH

    p = tmp_path / "deep.json"
    p.write_text('{"markers": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(MarkerSetError, match=f"bound of {MAX_MARKER_SET_DEPTH}") as ei:
        MarkerSet.read_json(p)
    assert str(p) in str(ei.value)
    # brackets inside strings are not nesting
    ok = tmp_path / "ok.json"
    ok.write_text(
        '{"name": "'
        + "[" * 500
        + '", "markers": {"EL": {"body": "forearm", "position": [0, 0, 0]}}}'
    )
    assert MarkerSet.read_json(ok).names == ("EL",)


# ---------------------------------------------------------------------------- marker sets


def test_marker_on_a_null_body_is_an_error_naming_the_marker(tmp_path, arm):
    p = tmp_path / "null.json"
    p.write_text(
        '{"markers": {"EL": {"body": "forearm", "position": [0, 0, 0]},'
        ' "RS": {"body": null, "position": [0.01, 0, 0]}}}'
    )
    with pytest.raises(MarkerSetError, match="'RS'.*body"):
        MarkerSet.read_json(p)
    with pytest.raises(MarkerSetError, match="'RS'"):
        MarkerSet.from_dict({"RS": [None, [0, 0, 0]]})
    with pytest.raises(MarkerSetError, match="'RS'"):
        MarkerSet.from_dict({"RS": ["", [0, 0, 0]]}).bind(arm)


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


def _two_subjects(arm, n=3):
    ms = default_marker_set(arm)
    Q = _motion(arm, n, seed=3)
    P = _marker_positions(arm, ms, Q)
    other = P + np.array([1.5, 0.0, 0.0])  # a second person 1.5 m away
    names = [f"Subj1:{m}" for m in ms.names] + [f"Subj2:{m}" for m in ms.names]
    return ms, Q, MarkerTrajectories(names, np.concatenate([other, P], axis=1), rate=100.0)


def test_two_subjects_in_one_trial_are_refused_until_one_is_chosen(arm):
    ms, Q, trial = _two_subjects(arm)
    with pytest.raises(MarkerSetError, match="Subj1.*Subj2.*subject=") as ei:
        marker_ik(arm, trial, ms)
    assert "--subject" in str(ei.value)
    with pytest.raises(MarkerSetError, match="Subj1.*Subj2"):
        match_markers(trial.names, ms)
    cols = match_markers(trial.names, ms, subject="Subj2")
    assert [trial.names[c] for c in cols] == [f"Subj2:{m}" for m in ms.names]
    res = marker_ik(arm, trial, ms, subject="Subj2")
    assert (res.status == "ok").all() and np.max(np.abs(res.q - Q)) < 1e-4
    with pytest.raises(MarkerSetError, match="Subj3.*Subj1, Subj2"):
        match_markers(trial.names, ms, subject="Subj3")


def test_cli_two_subjects_needs_subject(tmp_path, arm, capsys):
    from anthroarm.motion import write_c3d

    _, _, trial = _two_subjects(arm, n=3)
    write_c3d(tmp_path / "two.c3d", trial)
    out = tmp_path / "two.csv"
    rc = main(["ik-markers", str(tmp_path / "two.c3d"), "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and "Subj1" in err and "Subj2" in err and not out.exists()
    rc = main(
        ["ik-markers", str(tmp_path / "two.c3d"), "--out", str(out), "--no-progress"]
        + ["--subject", "Subj2"]
    )
    assert rc == 0 and read_joint_csv(out, arm).q.shape == (3, arm.nq)


# ---------------------------------------------------------------------------- CSV


@pytest.mark.parametrize(
    "header, column",
    [("t,a,b,a", "a"), ("t,a_deg,a", "a"), ("t,time,a", "time"), ("t,a,status,status", "status")],
)
def test_csv_duplicated_column_is_an_error_naming_it(tmp_path, header, column):
    p = tmp_path / "dup.csv"
    n = header.count(",") + 1
    p.write_text(header + "\n" + ",".join(["0"] * n) + "\n" + ",".join(["1"] * n) + "\n")
    with pytest.raises(MotionDataError, match=f"'{column}'") as ei:
        read_joint_csv(p)
    assert "line" in str(ei.value) and str(p) in str(ei.value)


# ---------------------------------------------------------------------------- output = input


def _small_trial(tmp_path, arm) -> Path:
    from anthroarm.motion import write_c3d

    ms = default_marker_set(arm)
    Q = _motion(arm, 4, seed=5)
    p = tmp_path / "trial.c3d"
    write_c3d(p, MarkerTrajectories(ms.names, _marker_positions(arm, ms, Q), rate=100.0))
    ms.write_json(tmp_path / "set.json")
    return p


def test_cli_refuses_an_output_that_is_an_input(tmp_path, arm, capsys, monkeypatch):
    trial = _small_trial(tmp_path, arm)
    before = trial.read_bytes()
    (tmp_path / "link.csv").symlink_to(trial)
    os.link(trial, tmp_path / "hard.c3d")
    monkeypatch.chdir(tmp_path)
    for out in (
        str(trial),
        "trial.c3d",
        "./sub/../trial.c3d",
        str(tmp_path / "link.csv"),
        "hard.c3d",
    ):
        (tmp_path / "sub").mkdir(exist_ok=True)
        rc = main(["ik-markers", str(trial), "--out", out, "--no-progress"])
        err = capsys.readouterr().err
        assert rc == 2 and "is an input" in err and "trial" in err, (out, err)
        assert trial.read_bytes() == before
    for extra in (["--static", "s.c3d"], ["--markers", "set.json"]):
        target = extra[1]
        if target == "s.c3d":
            (tmp_path / "s.c3d").write_bytes(before)
        keep = (tmp_path / target).read_bytes()
        rc = main(["ik-markers", str(trial), "--out", target, "--no-progress", *extra])
        assert rc == 2 and "is an input" in capsys.readouterr().err
        assert (tmp_path / target).read_bytes() == keep
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_cli_output_is_written_whole_or_not_at_all(tmp_path, arm, capsys):
    """A failing run leaves an existing output as it was (the CSV is written atomically after
    the solve), and a successful one replaces it whole."""
    trial = _small_trial(tmp_path, arm)
    out = tmp_path / "angles.csv"
    out.write_text("old\n")
    (tmp_path / "bad.json").write_text(
        '{"markers": {"X": {"body": "nowhere", "position": [0,0,0]}}}'
    )
    rc = main(
        ["ik-markers", str(trial), "--out", str(out), "--markers", str(tmp_path / "bad.json")]
        + ["--no-progress"]
    )
    assert rc == 2 and out.read_text() == "old\n"
    capsys.readouterr()
    assert main(["ik-markers", str(trial), "--out", str(out), "--no-progress"]) == 0
    assert read_joint_csv(out, arm).q.shape == (4, arm.nq)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "angles.csv",
        "bad.json",
        "set.json",
        "trial.c3d",
    ]


def test_every_motion_reader_error_is_typed(tmp_path):
    """Garbage in each reader: an AnthroarmError naming the file, never a bare exception."""
    cases = {
        "c3d": (read_c3d, b"\x02\x50" + b"\xff" * 1000),
        "csv": (read_joint_csv, b"t,a\n\xff\xfe\n"),
        "json": (
            MarkerSet.read_json,
            b'{"markers": {"A": {"body": "x", "position": [1e999999, 0, 0]}}}',
        ),
        "bigint": (MarkerSet.read_json, b'{"markers": {"A": ["x", [' + b"9" * 5000 + b", 0, 0]]}}"),
    }
    for name, (reader, data) in cases.items():
        p = tmp_path / f"{name}.bin"
        p.write_bytes(data)
        with pytest.raises(AnthroarmError) as ei:
            reader(p)
        assert str(p) in str(ei.value), (name, ei.value)


def test_io_readers_helper(tmp_path):
    """The shared helper of anthroarm._io the motion readers use (others will adopt it)."""
    from anthroarm._io import json_depth, load_json_bounded, read_bounded

    def err(problem):
        return MotionDataError(problem, "x")

    assert json_depth('{"a": [1, {"b": "[[[\\\\\\"[["}]}') == 3  # escapes inside strings
    assert json_depth("[]") == 1 and json_depth('"{"') == 0
    p = tmp_path / "f.json"
    p.write_text('{"a": [[1]]}')
    assert load_json_bounded(p, 100, error=err, max_depth=3) == {"a": [[1]]}
    with pytest.raises(MotionDataError, match="nested 3 levels deep, more than the bound of 2"):
        load_json_bounded(p, 100, error=err, max_depth=2)
    with pytest.raises(MotionDataError, match="12 bytes, more than the bound of 11 bytes"):
        read_bounded(p, 11, error=err)
    assert read_bounded(p, 12, error=err, encoding=None) == b'{"a": [[1]]}'
    with pytest.raises(MotionDataError, match="is a folder"):
        read_bounded(tmp_path, 100, error=err)
    with pytest.raises(MotionDataError, match="report not found"):
        read_bounded(tmp_path / "none", 100, error=err, what="report")


def test_csv_with_a_byte_order_mark_reads(tmp_path):
    """Spreadsheets save UTF-8 CSV with a byte-order mark: it is not part of the first column's
    name (it was: 'no time column', header ['\\ufefft', ...])."""
    p = tmp_path / "excel.csv"
    p.write_text("t,a_deg\n0,90\n0.01,45\n", encoding="utf-8-sig")
    tr = read_joint_csv(p)
    assert tr.names == ("a",) and np.allclose(tr.q[:, 0], [np.pi / 2, np.pi / 4])


def test_marker_positions_and_weights_must_be_numbers(tmp_path):
    """ "1" and true are not coordinates or weights (they were kept as given: position ('1', '2',
    '3'), weight True)."""
    for entry, what in (
        ('{"body": "hand", "position": ["0.1", "0", "0"]}', "position"),
        ('{"body": "hand", "position": [0.1, 0, 0], "weight": true}', "weight"),
        ('{"body": "hand", "position": [true, 0, 0]}', "position"),
    ):
        p = tmp_path / "s.json"
        p.write_text('{"markers": {"MC3": ' + entry + "}}")
        with pytest.raises(MarkerSetError, match=f"'MC3': {what}") as ei:
            MarkerSet.read_json(p)
        assert str(p) in str(ei.value)


@pytest.mark.parametrize("bad", [None, 5, ""])
def test_readers_take_only_paths(bad):
    """read_c3d(5), read_joint_csv(None): typed errors, not a TypeError from pathlib."""
    for reader, error in (
        (read_c3d, C3DError),
        (read_joint_csv, MotionDataError),
        (MarkerSet.read_json, MarkerSetError),
    ):
        with pytest.raises(error, match="path must be a file path"):
            reader(bad)


def test_cli_refuses_a_device_as_output_before_solving(tmp_path, arm, capsys):
    trial = _small_trial(tmp_path, arm)
    rc = main(["ik-markers", str(trial), "--out", "/dev/null", "--no-progress"])
    cap = capsys.readouterr()
    assert rc == 2 and "not a regular file" in cap.err and cap.out == ""  # no summary: not solved


@pytest.mark.parametrize("field", ["points", "data_start"])
def test_c3d_header_disagreeing_with_its_parameters_is_refused(tmp_path, field):
    """The frame count is checked on the bytes a frame takes and where the data start: a header
    whose point count or data block disagrees with POINT:USED / POINT:DATA_START is damaged."""
    good = _ezc3d_file(tmp_path / "g.c3d", 20, labels=("A", "B", "C"))
    b = bytearray(good)
    at = {"points": 2, "data_start": 16}[field]
    b[at : at + 2] = struct.pack("<H", struct.unpack("<H", good[at : at + 2])[0] + 1)
    bad = tmp_path / "bad.c3d"
    bad.write_bytes(bytes(b))
    with pytest.raises(C3DError, match="damaged C3D file: the header") as ei:
        read_c3d(bad)
    assert str(bad) in str(ei.value)
