"""Hostile input to :mod:`anthroarm.batch` (issue 30): damaged and forged result files, paths
that are not regular files, absurd voxel sizes and counts, a wrong output suffix, and a job of
10**12 configurations.  Each is refused with a typed error naming the file or the parameter
(:class:`~anthroarm.batch.errors.BatchResultError`, ``BatchParameterError``,
``JobTooLargeError``), or run in bounded memory.

Before the fixes of issue 30, loading damaged files raised zipfile.BadZipFile, JSONDecodeError,
KeyError, zlib.error or numpy's allow_pickle ValueError from inside the dependencies; a result
whose coordinates do not match its array loaded as valid; ``n = 10**12`` made all ~10**6 tasks
up front (4.8 GB); a subnormal voxel raised OverflowError and a huge one made infinite
coordinates; ``--out r.txt`` wrote a zip under a text name.
"""

from __future__ import annotations

import io
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np
import pytest

from anthroarm import batch
from anthroarm.batch import engine
from anthroarm.batch.errors import (
    BatchParameterError,
    BatchResultError,
    JobTooLargeError,
)

META = {"format": "anthroarm.batch/1", "job": "x", "dims": {"a": ["i"]}, "attrs": {}}


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A real result file (a small reachability map) and its bytes."""
    r = batch.reachability_map("human_arm7", n=5000, voxel=0.1, progress=False)
    p = tmp_path_factory.mktemp("batch") / "r.npz"
    r.save(p)
    return r, p, p.read_bytes()


def _npz(tmp_path, name="f.npz", meta=META, **arrays):
    buf = io.BytesIO()
    if meta is not None:
        raw = meta if isinstance(meta, bytes) else json.dumps(meta).encode()
        arrays["__meta__"] = np.frombuffer(raw, np.uint8)
    np.savez(buf, **arrays)
    p = tmp_path / name
    p.write_bytes(buf.getvalue())
    return p


def _refused(path, match):
    with pytest.raises(BatchResultError, match=match) as e:
        batch.load(path)
    assert e.value.path == str(path)
    return e.value


# ------------------------------------------------------------------ damaged and forged files
def test_round_trip_still_works(good):
    r, p, _ = good
    assert batch.load(p).equals(r)


def test_truncated_file(good, tmp_path):
    p = tmp_path / "t.npz"
    p.write_bytes(good[2][: len(good[2]) // 2])
    _refused(p, "not a batch result")


def test_random_bytes(tmp_path):
    p = tmp_path / "g.npz"
    p.write_bytes(os.urandom(4096))
    _refused(p, "not a batch result")


def test_empty_file(tmp_path):
    p = tmp_path / "e.npz"
    p.write_bytes(b"")
    _refused(p, "not a batch result")


def test_flipped_byte_in_compressed_data(good, tmp_path):
    b = bytearray(good[2])
    b[200] ^= 0xFF
    p = tmp_path / "crc.npz"
    p.write_bytes(bytes(b))
    _refused(p, "damaged|not a batch result")


def test_zip_with_junk_before_it(good, tmp_path):
    p = tmp_path / "j.npz"
    p.write_bytes(b"junk" + good[2])
    _refused(p, "not a batch result")


def test_object_array_is_never_unpickled(tmp_path):
    p = _npz(tmp_path, a=np.array([object()], dtype=object))
    _refused(p, "Python objects")


def test_meta_not_json(tmp_path):
    _refused(_npz(tmp_path, meta=b"{not json", a=np.zeros(2)), "not JSON")


def test_meta_deeply_nested(tmp_path):
    _refused(_npz(tmp_path, meta=b"[" * 100000 + b"]" * 100000), "nested")


def test_meta_not_utf8(tmp_path):
    _refused(_npz(tmp_path, meta=b"\xff\xfe", a=np.zeros(2)), "UTF-8")


@pytest.mark.parametrize(
    "meta, match",
    [
        ({"format": "anthroarm.batch/1"}, "'job'"),
        ({**META, "dims": {"a": "i"}}, "'dims'"),
        ({**META, "attrs": []}, "'attrs'"),
        ([1, 2], "JSON object"),
        ({**META, "format": "other/9"}, "format"),
    ],
)
def test_meta_of_the_wrong_shape(tmp_path, meta, match):
    _refused(_npz(tmp_path, meta=meta, a=np.zeros(2)), match)


def test_no_meta_entry(tmp_path):
    _refused(_npz(tmp_path, meta=None, a=np.zeros(2)), "no __meta__")


def test_variable_without_its_array(tmp_path):
    _refused(_npz(tmp_path), "has no array")


def test_coordinates_that_do_not_match_the_array(good, tmp_path):
    r = good[0]
    coords = dict(r.coords)
    coords["x"] = coords["x"][:-1]
    forged = batch.BatchResult(r.job, dict(r.variables), coords, r.attrs)
    p = tmp_path / "c.npz"
    p.write_bytes(forged.to_bytes())
    _refused(p, "dimension 'x'.*length 16.*coordinate 'x' has length 15")
    with pytest.raises(BatchParameterError, match="inconsistent"):
        forged.save(tmp_path / "c2.npz")  # and it is never written
    assert not (tmp_path / "c2.npz").exists()


def test_array_with_the_wrong_rank(tmp_path):
    _refused(_npz(tmp_path, a=np.zeros((2, 2))), "shape \\(2, 2\\) but 1 dimensions")


def test_zip_bomb_is_refused_before_decompression(tmp_path):
    p = tmp_path / "bomb.npz"
    buf = io.BytesIO()
    meta = np.frombuffer(json.dumps(META).encode(), np.uint8)
    np.savez_compressed(buf, __meta__=meta, a=np.zeros(2**20))  # 8 MiB of zeros in ~8 KiB
    p.write_bytes(buf.getvalue())
    assert p.stat().st_size < 2**16
    with pytest.raises(BatchResultError, match="decompressed"):
        batch.load(p, max_bytes=2**20)


# ------------------------------------------------------------------ not regular files
def test_dev_zero_is_refused_unread():
    _refused("/dev/zero", "device")


def test_folder_and_missing_file(tmp_path):
    _refused(tmp_path, "folder")
    _refused(tmp_path / "nope.npz", "not found")


def test_fifo_is_refused_without_waiting(tmp_path):
    f = tmp_path / "fifo.npz"
    os.mkfifo(f)
    t0 = time.monotonic()
    _refused(f, "FIFO")
    assert time.monotonic() - t0 < 5


def test_file_beyond_the_size_bound(good):
    with pytest.raises(BatchResultError, match="more than the bound"):
        batch.load(good[1], max_bytes=100)


# ------------------------------------------------------------------ parameters
@pytest.mark.parametrize(
    "voxel, error",
    [
        (5e-324, JobTooLargeError),
        (1e-9, JobTooLargeError),
        (1e308, BatchParameterError),
        (float("nan"), BatchParameterError),
        (-0.1, BatchParameterError),
        ("a", BatchParameterError),
    ],
)
def test_voxel_sizes(voxel, error):
    with pytest.raises(error, match="voxel"):
        batch.reachability_map("human_arm7", n=10, voxel=voxel, progress=False)


def test_population_voxel_too_fine():
    with pytest.raises(JobTooLargeError, match="voxel"):
        batch.population_reach(
            n=10, voxel=1e-9, heights=[1.7], masses=[70.0], sexes=["male"], progress=False
        )


@pytest.mark.parametrize("n", [True, 0, -5, 2.5, "10"])
def test_counts_must_be_positive_integers(n):
    with pytest.raises(BatchParameterError, match="positive integer"):
        batch.reachability_map("human_arm7", n=n, voxel=0.1, progress=False)


def test_wrong_output_suffix_is_refused_before_the_job(tmp_path):
    ran = []
    with pytest.raises(BatchParameterError, match=r"\.npz.*r\.npz"):
        batch.run_job(
            "reach",
            "human_arm7",
            n=10,
            voxel=0.1,
            out=tmp_path / "r.txt",
            progress=False,
            callback=lambda *a: ran.append(a),
        )
    assert not ran and not list(tmp_path.iterdir())


def test_cli_out_txt_is_one_line_exit_2(tmp_path):
    out = tmp_path / "r.txt"
    p = subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", "batch", "reach", "--n", "10", "--voxel", "0.1"]
        + ["--out", str(out), "--no-progress"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 2, p.stderr
    assert "r.npz" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not out.exists()


# ------------------------------------------------------------------ 10**12 configurations
def test_1e12_configurations_stream_in_bounded_memory():
    """~10**6 tasks are made as they are submitted: cancelling after three tasks took no
    memory for the rest (before: 4.8 GB of payloads up front)."""
    seen = []

    def stop(done, total):
        seen.append(total)
        if done == 3:
            raise KeyboardInterrupt

    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(KeyboardInterrupt):
        batch.reachability_map(
            "human_arm7", n=10**12, voxel=0.1, chunk_size=1 << 12, progress=False, callback=stop
        )
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert seen[0] == -(-(10**12) // (1 << 12))  # 244 140 625 tasks, counted not made
    assert grown_mb < 200


def test_streamed_seeds_equal_chunk_seeds():
    ss = np.random.SeedSequence(123)
    lazy = list(engine.iter_seeds(ss, 2500))
    eager = engine.chunk_seeds(123, 2500)
    assert [s.spawn_key for s in lazy] == [s.spawn_key for s in eager]
    assert ss.n_children_spawned == 2500  # advanced as spawn(n) advances it


def test_streamed_job_on_dask_equals_local():
    """The lazily made tasks on a real LocalCluster (1 worker) give the local result."""
    from distributed import Client, LocalCluster

    kw = dict(n=40000, voxel=0.1, chunk_size=1 << 13, progress=False)
    local = batch.reachability_map("human_arm7", **kw)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        Client(cluster, set_as_default=False) as client,
    ):
        remote = batch.reachability_map("human_arm7", client=client, **kw)
    assert remote.equals(local)
