"""Fault injection on every file the package writes (URDF output, exported HTML, cache entries,
benchmark results, all through :func:`anthroarm._io.atomic_write_text`): a folder or a FIFO as
the target, a folder under a regular file, a read-only file system, a full disk, and a writer
killed mid-write.  The target is always the old content or the complete new content; the CLI
answers with one line and exit status 2.

Root ignores permission bits, so "read-only" and "full" are real file systems: a small tmpfs
mounted here (skipped, with the reason, where mounting is not allowed) and remounted read-only.
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from anthroarm import cache, cli
from anthroarm._io import atomic_write_text

ROOT = Path(__file__).resolve().parents[2]


@contextlib.contextmanager
def tmpfs(where: Path, size: str = "64k"):
    """A tmpfs of ``size`` mounted at ``where`` (skip if this machine does not allow it)."""
    where.mkdir(parents=True, exist_ok=True)
    r = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)],
        capture_output=True,
        text=True,
    )
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (not root or no CAP_SYS_ADMIN): {r.stderr.strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


def fill(d: Path) -> None:
    """Fill a file system until it reports ENOSPC."""
    with open(d / "filler", "wb", buffering=0) as f:
        try:
            while True:
                f.write(b"\0" * 4096)
        except OSError as exc:
            assert exc.errno == errno.ENOSPC


def remount_ro(d: Path) -> None:
    r = subprocess.run(["mount", "-o", "remount,ro", str(d)], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot remount read-only: {r.stderr.strip()}")


def temps(d: Path) -> list[str]:
    return sorted(p for p in os.listdir(d) if p.endswith(".tmp"))


def run_cli(argv, capsys):
    try:
        rc = cli.main(argv)
    except SystemExit as e:
        rc = e.code
    out, err = capsys.readouterr()
    return rc, out, err


def assert_one_line(rc, err, *needles):
    lines = [ln for ln in err.splitlines() if ln.strip() and "warning" not in ln]
    assert rc == 2 and "Traceback" not in err and len(lines) == 1, (rc, err)
    for n in needles:
        assert n in lines[0], (n, lines[0])


# ------------------------------------------------------------------------- atomic_write_text
def test_disk_full_keeps_the_old_file_and_no_temp(tmp_path):
    with tmpfs(tmp_path / "fs") as d:
        target = d / "out.txt"
        atomic_write_text(target, "old")
        with pytest.raises(OSError) as ei:
            atomic_write_text(target, "x" * 200_000)
        assert ei.value.errno == errno.ENOSPC and ei.value.filename == str(target)
        assert target.read_text() == "old" and temps(d) == []


def test_read_only_file_system_keeps_the_old_file(tmp_path):
    with tmpfs(tmp_path / "fs") as d:
        target = d / "out.txt"
        atomic_write_text(target, "old")
        remount_ro(d)
        with pytest.raises(OSError) as ei:
            atomic_write_text(target, "new")
        assert ei.value.errno == errno.EROFS and ei.value.filename == str(target)
        assert target.read_text() == "old"


def test_folder_fifo_and_path_under_a_file_are_never_replaced(tmp_path):
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(IsADirectoryError):
        atomic_write_text(folder, "x")
    assert folder.is_dir() and temps(tmp_path) == []
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="not a regular file"):
        atomic_write_text(fifo, "x")
    assert not fifo.is_file() and fifo.exists()
    f = tmp_path / "file"
    f.write_text("keep")
    with pytest.raises(NotADirectoryError):
        atomic_write_text(f / "x.txt", "x")
    assert f.read_text() == "keep"


WRITER = textwrap.dedent("""
    import sys
    from anthroarm._io import atomic_write_text
    target, n = sys.argv[1], int(sys.argv[2])
    blobs = [b"A" * n, b"B" * n]
    print("ready", flush=True)
    i = 0
    while True:
        atomic_write_text(target, blobs[i % 2])
        i += 1
""")


def test_sigkill_mid_write_leaves_old_or_new_and_stale_temps_are_removed(tmp_path):
    """A writer killed at random moments: the target is always one whole version; its
    leftover temp file is hidden and removed by the next write to the same target."""
    n = 4_000_000
    target = tmp_path / "big.bin"
    atomic_write_text(target, b"A" * n)
    seen_temp = False
    for delay in (0.05, 0.13, 0.21, 0.34, 0.55):
        p = subprocess.Popen(
            [sys.executable, "-c", WRITER, str(target), str(n)], stdout=subprocess.PIPE
        )
        assert p.stdout.readline().strip() == b"ready"
        time.sleep(delay)
        p.send_signal(signal.SIGKILL)
        p.wait()
        data = target.read_bytes()
        assert data in (b"A" * n, b"B" * n), (len(data), data[:1], data[-1:])
        seen_temp |= bool(temps(tmp_path))
        atomic_write_text(target, b"A" * n)  # the next write cleans the dead writer's temp
        assert temps(tmp_path) == [], temps(tmp_path)
    assert target.read_bytes() == b"A" * n
    del seen_temp  # how often a temp was caught depends on timing; the cleanup is asserted above


def test_temp_of_a_live_writer_is_not_removed(tmp_path):
    target = tmp_path / "t.txt"
    live = tmp_path / f".t.txt.{os.getppid()}.1.abcd.tmp"  # a live process (our parent)
    live.write_text("in progress")
    atomic_write_text(target, "x")
    assert live.exists()


# ------------------------------------------------------------------------- the CLI's outputs
def test_cli_urdf_on_a_full_disk(tmp_path, capsys):
    with tmpfs(tmp_path / "fs") as d:
        target = d / "arm.urdf"
        atomic_write_text(target, "old")
        fill(d)
        rc, out, err = run_cli(["urdf", "prosthetic_arm", "-o", str(target)], capsys)
        assert_one_line(rc, err, str(target), "No space left")
        assert target.read_text() == "old" and temps(d) == []


def test_cli_urdf_on_a_read_only_file_system(tmp_path, capsys):
    with tmpfs(tmp_path / "fs") as d:
        target = d / "arm.urdf"
        atomic_write_text(target, "old")
        remount_ro(d)
        rc, out, err = run_cli(["urdf", "prosthetic_arm", "-o", str(target)], capsys)
        assert_one_line(rc, err, str(target), "Read-only")
        assert target.read_text() == "old"


@pytest.mark.parametrize("where", ["folder", "fifo", "under-file", "sysfs"])
def test_cli_urdf_bad_targets(tmp_path, capsys, where):
    folder, fifo, f = tmp_path / "folder", tmp_path / "fifo", tmp_path / "file"
    folder.mkdir()
    os.mkfifo(fifo)
    f.write_text("keep")
    target = {
        "folder": folder,
        "fifo": fifo,
        "under-file": f / "x.urdf",
        "sysfs": Path("/sys/anthroarm_x.urdf"),
    }
    rc, out, err = run_cli(["urdf", "prosthetic_arm", "-o", str(target[where])], capsys)
    assert_one_line(rc, err)
    assert folder.is_dir() and list(folder.iterdir()) == [] and fifo.exists() and not fifo.is_file()
    assert f.read_text() == "keep" and temps(tmp_path) == []


def test_cli_view_html_on_a_full_disk(tmp_path, capsys):
    with tmpfs(tmp_path / "fs") as d:
        target = d / "scene.html"
        atomic_write_text(target, "old")
        fill(d)
        rc, out, err = run_cli(["view", "planar2r", "--html", str(target)], capsys)
        assert_one_line(rc, err, str(target))
        assert target.read_text() == "old" and temps(d) == []


# ------------------------------------------------------------------------- cache and benchmarks
@pytest.mark.parametrize("fault", ["full", "read-only"])
def test_cache_write_faults_store_nothing_and_say_why(tmp_path, monkeypatch, fault):
    with tmpfs(tmp_path / "fs") as d:
        os.chmod(d, 0o700)  # a tmpfs root is 1777: the cache refuses a folder others can write
        monkeypatch.setenv("ANTHROARM_CACHE", str(d))
        assert cache.write("lagrange", "small.py", b"x = 1\n") is not None
        if fault == "full":
            fill(d)
        else:
            remount_ro(d)
        assert cache.write("lagrange", "big.py", b"y = 2\n" * 50_000) is None
        assert "in memory" in cache.status()
        assert cache.read("lagrange", "big.py") is None
        assert cache.read("lagrange", "small.py") == b"x = 1\n"  # the old entry is intact
        assert temps(d / "lagrange") == []
        cache.clear() if fault == "full" else None


def test_benchmark_results_on_a_full_disk_keep_the_old_table(tmp_path):
    sys.path.insert(0, str(ROOT))
    try:
        from benchmarks.common import write_result
    finally:
        sys.path.remove(str(ROOT))
    with tmpfs(tmp_path / "fs") as d:
        old = d / "fk.json"
        atomic_write_text(old, "{}")
        fill(d)
        rows = [[i, "x" * 100] for i in range(2000)]
        with pytest.raises(OSError) as ei:
            write_result("fk", {"title": "t", "columns": ["a", "b"], "rows": rows}, out_dir=d)
        assert ei.value.errno == errno.ENOSPC
        assert old.read_text() == "{}" and temps(d) == []
