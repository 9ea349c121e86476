"""The disk cache against a hostile or careless file system (issue 30): symlinks inside and as
the cache folder, a folder other users can write or own, planted entries with a restamped
SHA-256 sidecar, a truncated shared library with a restamped sidecar, FIFOs.

What the attacker writes is what the module docstring of :mod:`anthroarm.cache` says an entry
is (the bytes, and ``NAME.sha256`` holding ``sha256 <hex> <size>``): the digest catches
accidents, so an attacker who can write the folder restamps it, and only the folder's owner and
permissions keep them out.  Oracles: the file system (what exists, what was deleted, modes) and
a marker file that planted code would write if it were run."""

import hashlib
import os
import stat
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

import anthroarm as aa
from anthroarm import cache
from anthroarm.cli import main as cli_main
from anthroarm.dynamics import lagrange as L
from anthroarm.errors import UnsafeCacheError, UnsafeCacheWarning

posix = pytest.mark.skipif(os.name != "posix", reason="POSIX owners, modes and symlinks")
needs_cc = pytest.mark.skipif(cache.compiler() is None, reason="no C compiler")
pytestmark = posix

ENTRY = "lagrange_" + "ab" * 12 + ".py"  # the form of a generated entry's name (key: 24 hex)


def plant(folder: Path, name: str, data: bytes) -> None:
    """Put ``data`` as entry ``name`` with a sidecar that matches it (an attacker's restamp)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(data)
    digest = hashlib.sha256(data).hexdigest()
    (folder / (name + ".sha256")).write_text(f"sha256 {digest} {len(data)}\n")


def evil_source(mark: Path) -> bytes:
    return f"A = 2\nimport pathlib\npathlib.Path({str(mark)!r}).write_text('ran')\n".encode()


def tree(d: Path) -> dict:
    """Every path below ``d`` (not following links) -> its bytes (files) or its link target."""
    out = {}
    for p in sorted(d.rglob("*")):
        if p.is_symlink():
            out[str(p.relative_to(d))] = "-> " + os.readlink(p)
        elif p.is_file():
            out[str(p.relative_to(d))] = p.read_bytes()
    return out


@pytest.fixture
def croot(tmp_path, monkeypatch):
    """``$ANTHROARM_CACHE`` pointed at ``tmp_path/cache`` (not created)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("ANTHROARM_CACHE", str(d))
    L._MEMO.clear()
    yield d
    L._MEMO.clear()


def user_folder(tmp_path: Path) -> Path:
    """A user's folder with files named like cache entries, a sidecar and a note."""
    u = tmp_path / "thesis"
    u.mkdir()
    plant(u, ENTRY, b"A = 1\n")
    (u / "chapter1.tex").write_text("two years of work")
    (u / "x.nbi").write_bytes(b"not numba's")
    return u


# ------------------------------------------------------------------------- clear and symlinks
def test_clear_does_not_follow_a_symlinked_subfolder(croot, tmp_path):
    u = user_folder(tmp_path)
    before = tree(u)
    croot.mkdir(mode=0o700)
    (croot / "lagrange").symlink_to(u)
    cache.clear()
    assert tree(u) == before  # the user's folder is untouched
    assert (croot / "lagrange").is_symlink()


def test_clear_does_not_descend_into_a_symlinked_folder_inside_the_cache(croot, tmp_path):
    u = user_folder(tmp_path)
    before = tree(u)
    cache.write("lagrange", ENTRY, b"A = 1\n")
    (croot / "numba").mkdir(mode=0o700)
    (croot / "numba" / "kernels").symlink_to(u)
    (croot / "lagrange" / "linked.py").symlink_to(u / "chapter1.tex")
    assert cache.clear() == 1  # the one real entry
    assert tree(u) == before
    assert sorted(p.name for p in (croot / "lagrange").iterdir()) == ["linked.py"]
    assert (croot / "numba" / "kernels").is_symlink()


def test_clear_deletes_only_the_files_the_cache_writes(croot):
    cache.write("lagrange", ENTRY, b"A = 1\n")
    lg = croot / "lagrange"
    (lg / "notes.txt").write_text("a user's note")
    (lg / "mine").mkdir()
    (lg / "mine" / "data.csv").write_text("1,2\n")
    nb = croot / "numba" / "src_folder"
    nb.mkdir(parents=True)
    (nb / "mod.f-3.py311.nbi").write_bytes(b"index")
    (nb / "mod.f-3.py311.1.nbc").write_bytes(b"data")
    assert cache.clear() == 3  # the entry and numba's two files
    assert sorted(p.name for p in lg.iterdir()) == ["mine", "notes.txt"]
    assert (lg / "mine" / "data.csv").read_text() == "1,2\n"
    assert not (croot / "numba" / "src_folder").exists()  # emptied, so removed


def test_info_counts_no_file_behind_a_symbolic_link(croot, tmp_path):
    u = user_folder(tmp_path)
    cache.write("ik", "lm_" + "cd" * 12 + ".so", b"\x7fELF")
    (croot / "lagrange").symlink_to(u)
    (croot / "ik" / "linked.so").symlink_to(u / ENTRY)
    got = cache.info()
    assert got["by_folder"]["lagrange"] == (0, 0)
    assert got["by_folder"]["ik"] == (1, 4 + len(f"sha256 {'0' * 64} 4\n"))  # entry + sidecar


def test_clear_refuses_a_symlinked_cache_folder(croot, tmp_path):
    u = tmp_path / "project"
    plant(u / "lagrange", ENTRY, b"A = 1\n")
    before = tree(u)
    croot.symlink_to(u)
    with pytest.raises(UnsafeCacheError, match="symbolic link"):
        cache.clear()
    assert tree(u) == before


def test_cli_clear_refuses_a_world_writable_cache_and_info_says_why(croot, capsys):
    plant(croot / "lagrange", ENTRY, b"A = 1\n")
    os.chmod(croot, 0o777)
    before = tree(croot)
    with pytest.warns(UnsafeCacheWarning):  # once per folder and reason, whoever looks first
        assert cli_main(["cache", "clear"]) == 2
        err = capsys.readouterr().err
        assert cli_main(["cache", "info"]) == 0
    assert len(err.strip().splitlines()) == 1
    assert str(croot) in err and "chmod" in err
    assert tree(croot) == before
    out = capsys.readouterr().out
    assert "not used" in out and "writable by" in out


# ------------------------------------------------------------------------- the cache folder itself
def test_a_symlinked_cache_folder_is_not_written_into(croot, tmp_path):
    """The link's target passes an owner check here (we own it, mode 0755), as /usr/lib does
    for root: so the link itself is refused, not resolved."""
    system = tmp_path / "system"
    system.mkdir(mode=0o755)
    croot.symlink_to(system)
    with pytest.warns(UnsafeCacheWarning, match="symbolic link"):
        p = cache.write("lagrange", ENTRY, b"A = 1\n")
    assert list(system.iterdir()) == []
    assert p is not None and not str(p).startswith(str(croot))  # a private folder instead
    assert "symbolic link" in cache.status()


@pytest.mark.parametrize("mode", [0o770, 0o707, 0o777, 0o1777])
def test_planted_code_in_a_folder_others_can_write_is_not_run(croot, tmp_path, mode):
    mark = tmp_path / "ran"
    plant(croot / "lagrange", ENTRY, evil_source(mark))
    os.chmod(croot, mode)
    with pytest.warns(UnsafeCacheWarning, match="writable by"):
        mod, origin = cache.python_module("lagrange", ENTRY, lambda: "A = 1\n", "planted")
    assert mod.A == 1 and not mark.exists()  # ours (derived, or from this process's own folder)
    assert not mod.__file__.startswith(str(croot))
    assert (croot / "lagrange" / ENTRY).read_bytes() == evil_source(mark)  # not ours to repair


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() != 0, reason="chown to another user needs root"
)
def test_planted_code_in_a_folder_owned_by_another_user_is_not_run(croot, tmp_path):
    """As root (CI): a cache owned by uid 12345 (say, a user's cache reached through sudo with
    their HOME) is not executed by root."""
    mark = tmp_path / "ran"
    plant(croot / "lagrange", ENTRY, evil_source(mark))
    os.chmod(croot, 0o700)
    os.chown(croot, 12345, 12345)
    with pytest.warns(UnsafeCacheWarning, match="owned by uid 12345"):
        mod, origin = cache.python_module("lagrange", ENTRY, lambda: "A = 1\n", "planted")
    assert mod.A == 1 and not mark.exists()  # ours (derived, or from this process's own folder)
    assert not mod.__file__.startswith(str(croot))


def test_a_new_cache_folder_is_private_whatever_the_umask(croot):
    old = os.umask(0o002)  # a common default (user private groups): folders 0775
    try:
        assert cache.write("lagrange", ENTRY, b"A = 1\n") is not None
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.lstat(croot).st_mode) == 0o700
    assert stat.S_IMODE(os.lstat(croot / "lagrange").st_mode) == 0o700


def test_a_folder_only_its_owner_can_write_is_used(croot):
    """0755 (what mkdir gives with umask 022): others can read, not write: accepted."""
    croot.mkdir(mode=0o755)
    os.chmod(croot, 0o755)
    assert cache.write("lagrange", ENTRY, b"A = 1\n") == croot / "lagrange" / ENTRY
    assert cache.read("lagrange", ENTRY) == b"A = 1\n"


# ------------------------------------------------------------------------- entries
def test_a_symlinked_subfolder_is_not_written_into(croot, tmp_path):
    u = tmp_path / "elsewhere"
    u.mkdir()
    croot.mkdir(mode=0o700)
    (croot / "lagrange").symlink_to(u)
    assert cache.write("lagrange", ENTRY, b"A = 1\n") is None
    assert list(u.iterdir()) == []
    assert "symbolic link" in cache.status()


def test_a_symlinked_entry_is_not_read_and_its_target_is_kept(croot, tmp_path):
    mark = tmp_path / "ran"
    outside = tmp_path / "outside.py"
    outside.write_bytes(evil_source(mark))
    plant(croot / "lagrange", ENTRY, evil_source(mark))
    (croot / "lagrange" / ENTRY).unlink()
    (croot / "lagrange" / ENTRY).symlink_to(outside)
    mod, origin = cache.python_module("lagrange", ENTRY, lambda: "A = 1\n", "planted")
    assert (mod.A, origin) == (1, "derived") and not mark.exists()
    assert outside.read_bytes() == evil_source(mark)  # the target: neither deleted nor written
    entry = croot / "lagrange" / ENTRY
    assert not entry.is_symlink() and entry.read_bytes() == b"A = 1\n"  # replaced by ours


def test_a_fifo_in_place_of_an_entry_does_not_hang_a_read(croot):
    cache.write("lagrange", ENTRY, b"A = 1\n")
    fifo = croot / "lagrange" / ENTRY
    fifo.unlink()
    os.mkfifo(fifo)
    got = []
    t = threading.Thread(target=lambda: got.append(cache.read("lagrange", ENTRY)), daemon=True)
    t.start()
    t.join(10)
    if t.is_alive():  # blocked in open(): give it a writer so the thread ends, then fail
        fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
        t.join(10)
        pytest.fail("reading a FIFO entry blocked")
    assert got == [None]


# ------------------------------------------------------------------------- shared libraries
SO_SOURCE = "double twice(double x) { return 2.0 * x; }\n"
SO_FLAGS = ["-O1", "-shared", "-fPIC"]


@needs_cc
@pytest.mark.parametrize("cut", [0.33, 0.9, -1])
def test_a_truncated_library_with_a_restamped_sidecar_is_compiled_again(croot, cut):
    """The digest cannot catch this (the sidecar matches the truncated bytes): the library's
    own headers name offsets beyond its end, so it is rebuilt instead of returned (dlopen of
    such a file dies of SIGBUS)."""
    path, origin = cache.shared_library("lagrange", "twice", SO_SOURCE, SO_FLAGS)
    assert origin == "compiled"
    good = path.read_bytes()
    n = len(good) - 1 if cut == -1 else int(len(good) * cut)
    path.unlink()
    plant(path.parent, path.name, good[:n])
    again, origin = cache.shared_library("lagrange", "twice", SO_SOURCE, SO_FLAGS)
    assert origin == "compiled" and again == path
    assert path.read_bytes() == good


@needs_cc
def test_a_truncated_library_with_a_restamped_sidecar_does_not_kill_a_fresh_process(croot):
    L.load(aa.load("planar2r", l1=0.47), backend="c")  # not loaded by this process before
    (lib,) = (croot / "lagrange").glob("lagrange_*.so")
    data = lib.read_bytes()
    lib.unlink()
    plant(lib.parent, lib.name, data[: len(data) // 3])
    code = textwrap.dedent("""
        import numpy as np, pinocchio as pin, anthroarm as aa
        from anthroarm.dynamics import lagrange as L
        r = aa.load("planar2r", l1=0.47)
        d = L.load(r, backend="c")
        q, v, a = np.array([0.3, -0.7]), np.array([1.1, 0.4]), np.array([-0.2, 0.9])
        ref = pin.rnea(r.model, r.model.createData(), q, v, a)
        print(float(np.max(np.abs(d.tau(q, v, a) - ref))))
    """)
    r = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=os.environ.copy(),
        timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])
    assert float(r.stdout.strip().splitlines()[-1]) < 1e-12
    assert lib.read_bytes() == data


# ------------------------------------------------------------------------- numba's pickles
def test_planted_numba_pickles_in_a_world_writable_cache_are_not_loaded(tmp_path):
    """Numba's cache (the folder ``numba`` under the cache folder) holds pickles; one restamped
    with a valid anthroarm header runs code when unpickled.  With the cache folder writable by
    others, a fresh process must neither load them nor write there."""
    croot, mark = tmp_path / "cache", tmp_path / "ran"
    code = textwrap.dedent("""
        import numpy as np, anthroarm as aa
        r = aa.load("planar2r")
        res = aa.ik.analytic(r, r.fk(np.array([0.3, 0.4])))
        print(res.success, np.abs(res.solutions - [0.3, 0.4]).max(1).min())
    """)
    env = dict(os.environ, ANTHROARM_CACHE=str(croot))
    env.pop("NUMBA_CACHE_DIR", None)

    def run():
        r = subprocess.run(
            [sys.executable, "-W", "always", "-c", code],
            capture_output=True,
            text=True,
            env=env,
            timeout=600,
        )
        assert r.returncode == 0, r.stderr[-2000:]
        ok, err = r.stdout.split()
        assert ok == "True" and float(err) < 1e-9
        return r.stderr

    run()  # a private cache (0700): numba's files are written there
    data = sorted((croot / "numba").rglob("*.nbc"))
    assert data
    payload = (  # a protocol-0 pickle that calls exec(<code>) when loaded
        b"cbuiltins\nexec\n(V"
        + f"import pathlib; pathlib.Path({str(mark)!r}).write_text('ran')".encode()
        + b"\ntR."
    )
    for f in data:
        f.unlink()
        f.write_bytes(b"anthroarm-sha256\n" + hashlib.sha256(payload).digest() + payload)
    os.chmod(croot, 0o777)
    before = {p: p.stat().st_mtime_ns for p in croot.rglob("*") if p.is_file()}
    err = run()
    assert not mark.exists()
    assert "UnsafeCacheWarning" in err and str(croot) in err
    time.sleep(0.01)
    assert {p: p.stat().st_mtime_ns for p in croot.rglob("*") if p.is_file()} == before
