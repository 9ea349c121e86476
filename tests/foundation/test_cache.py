"""The one disk cache (anthroarm.cache): where it is, integrity (a damaged entry is rebuilt,
never run), atomic writes, fallback to memory, ``anthroarm cache info|clear``.

Oracles: Pinocchio (rnea) for the numbers the rebuilt code gives; the file system for what is
written; a subprocess for what would crash the interpreter."""

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import cache
from anthroarm._io import atomic_write_text
from anthroarm.cli import main as cli_main
from anthroarm.dynamics import lagrange as L

needs_cc = pytest.mark.skipif(cache.compiler() is None, reason="no C compiler")


def damage(path: Path, data: bytes) -> None:
    """Put ``data`` at ``path`` as a new file (this process may have the old one mapped: changing
    that inode in place would crash it, which is not what these tests are about)."""
    tmp = path.with_name(path.name + ".damage")
    tmp.write_bytes(data)
    os.replace(tmp, path)


@pytest.fixture
def cdir(tmp_path, monkeypatch):
    d = tmp_path / "cache"
    monkeypatch.setenv("ANTHROARM_CACHE", str(d))
    L._MEMO.clear()
    yield d
    L._MEMO.clear()


def test_folder_precedence(monkeypatch, tmp_path):
    monkeypatch.setenv("HOME", str(tmp_path / "home"))  # root() creates the folder it returns
    monkeypatch.delenv("ANTHROARM_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.root() == tmp_path / "xdg" / "anthroarm"
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path / "mine"))
    assert cache.root() == tmp_path / "mine"
    monkeypatch.delenv("ANTHROARM_CACHE")
    monkeypatch.delenv("XDG_CACHE_HOME")
    if sys.platform.startswith("linux"):
        assert cache.root() == tmp_path / "home" / ".cache" / "anthroarm"


def test_entry_roundtrip_and_damage_detected(cdir):
    assert cache.write("lagrange", "x.py", b"A = 1\n") == cdir / "lagrange" / "x.py"
    assert cache.read("lagrange", "x.py") == b"A = 1\n"
    assert sorted(p.name for p in (cdir / "lagrange").iterdir()) == [
        "x.py",
        "x.py.sha256",
    ]  # no temp files
    (cdir / "lagrange" / "x.py").write_bytes(b"A = 2\n")  # same size, other content
    assert cache.read("lagrange", "x.py") is None
    assert not (cdir / "lagrange" / "x.py").exists()  # the damaged entry is gone
    cache.write("lagrange", "y.py", b"B = 1\n")
    (cdir / "lagrange" / "y.py.sha256").unlink()  # no record: not trusted
    assert cache.read("lagrange", "y.py") is None
    with pytest.raises(ValueError, match="lagrange, ik"):
        cache.folder("seeds")


def _flip_a_digit(text: str) -> str:
    """Change one digit of the first long numeric constant (a model parameter) of ``tau_1``."""
    start = text.index("def tau_1(")
    m = re.compile(r"(?<![\w.])(\d\.\d{6,})(?![\de])").search(text, start)  # no 1e-16 noise
    i = m.start(1) + 3
    return text[:i] + ("7" if text[i] != "7" else "3") + text[i + 1 :]


def test_edited_cached_python_is_rebuilt_not_run(cdir):
    robot = aa.load("kinova")
    key = L.chain_info(robot).key()
    dyn = L.load(robot)
    assert dyn.source == "derived"
    path = cdir / "lagrange" / f"lagrange_{key}.py"
    good = path.read_text()
    bad = _flip_a_digit(good)
    path.write_text(bad)
    rng = np.random.default_rng(0)
    q, v, a = robot.random_q(rng=rng), rng.standard_normal(robot.nv), rng.standard_normal(robot.nv)
    ref = pin.rnea(robot.model, robot.model.createData(), q, v, a)
    # the edit matters: the edited module, run as it is, gives another τ
    ns = {}
    exec(compile(bad, "edited", "exec"), ns)
    th = robot.chain.angles(q)
    assert np.max(np.abs(ns["tau_1"](th, v, a) - ref)) > 1e-6
    L._MEMO.clear()
    dyn2 = L.load(robot)
    assert dyn2.source == "derived"  # detected, derived again
    assert np.max(np.abs(dyn2.tau(q, v, a) - ref)) < 1e-12
    assert path.read_text() == good  # and the entry repaired
    L._MEMO.clear()
    assert L.load(robot).source == "cache"


@needs_cc
def test_truncated_shared_library_is_rebuilt_in_a_fresh_process(cdir):
    """A .so cut to a third: loading it used to kill the process with SIGBUS.  A fresh
    process must detect it, rebuild, and compute τ equal to Pinocchio's."""
    L.load(aa.load("planar2r", l1=0.57), backend="c")  # a fresh parameterisation: not loaded yet
    libs = list((cdir / "lagrange").glob("lagrange_*.so"))
    assert len(libs) == 1
    data = libs[0].read_bytes()
    damage(libs[0], data[: len(data) // 3])
    code = textwrap.dedent("""
        import numpy as np, pinocchio as pin, anthroarm as aa
        from anthroarm.dynamics import lagrange as L
        r = aa.load("planar2r", l1=0.57)
        d = L.load(r, backend="c")
        q, v, a = np.array([0.3, -0.7]), np.array([1.1, 0.4]), np.array([-0.2, 0.9])
        ref = pin.rnea(r.model, r.model.createData(), q, v, a)
        print(float(np.max(np.abs(d.tau(q, v, a) - ref))))
    """)
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=os.environ.copy(),
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert float(r.stdout.strip().splitlines()[-1]) < 1e-12
    assert cache.read("lagrange", libs[0].name) is not None  # rebuilt and verified


def test_damaged_compiled_kernels_are_compiled_again(tmp_path):
    """The compiled IK kernels (anthroarm.jit, Numba's cache in the folder 'numba'): the stamp
    lists the SHA-256 of every file; truncated, bit-flipped and foreign data files and a garbled
    index are deleted and compiled again, never loaded (fresh processes: each checks the folder
    against the stamp on its first kernel call), and the stamp lists the new files."""
    code = textwrap.dedent("""
        import numpy as np, anthroarm as aa
        r = aa.load("planar2r")
        res = aa.ik.analytic(r, r.fk(np.array([0.3, 0.4])))
        print(res.success, np.abs(res.solutions - [0.3, 0.4]).max(1).min())
    """)
    env = dict(os.environ, ANTHROARM_CACHE=str(tmp_path), ANTHROARM_JIT="compile")
    env.pop("NUMBA_CACHE_DIR", None)

    def run(source=code):
        r = subprocess.run(
            [sys.executable, "-c", source], capture_output=True, text=True, env=env, timeout=600
        )
        assert r.returncode == 0, r.stderr[-2000:]
        return r.stdout.split()

    assert run()[0] == "True"
    data = sorted((tmp_path / "numba").rglob("*.nbc"))
    index = sorted((tmp_path / "numba").rglob("*.nbi"))
    assert len(data) >= 3 and len(index) >= 4
    damaged = {
        data[0]: data[0].read_bytes()[: data[0].stat().st_size // 2],  # truncated
        data[1]: bytes(b ^ 0xFF if i == 40 else b for i, b in enumerate(data[1].read_bytes())),
        data[2]: b"not numba's",  # foreign
        index[3]: index[3].read_bytes()[:20],  # garbled index
    }
    for f, body in damaged.items():
        damage(f, body)
    ok, err = run()
    assert ok == "True" and float(err) < 1e-9
    for f, body in damaged.items():
        assert not f.exists() or f.read_bytes() != body  # deleted, compiled again
    check = (
        "from anthroarm import jit\nprint(jit._read_stamp()[0] == jit._files(jit.numba_folder()))"
    )
    assert run(check) == ["True"]  # every file there is listed with its digest


def test_unwritable_cache_falls_back_to_memory(tmp_path, monkeypatch):
    """ANTHROARM_CACHE under a regular file cannot be created (even as root)."""
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("ANTHROARM_CACHE", str(blocker / "cache"))
    L._MEMO.clear()
    robot = aa.load("planar2r", l1=0.61)  # a fresh parameterisation (no memo anywhere)
    dyn = L.load(robot)
    assert dyn.source == "derived"
    q, v, a = np.array([0.2, 0.5]), np.array([0.3, -1.0]), np.array([1.0, 2.0])
    assert np.allclose(
        dyn.tau(q, v, a), pin.rnea(robot.model, robot.model.createData(), q, v, a), atol=1e-12
    )
    # the folder cannot be created: this process runs from a private temporary folder
    assert "private temporary folder" in cache.status() and str(blocker) in cache.status()
    if cache.compiler() is not None:
        dc = L.load(robot, backend="c")
        assert np.allclose(dc.tau(q, v, a), dyn.tau(q, v, a), atol=1e-13)
        assert not str(dc._c.path).startswith(str(blocker))  # compiled into a private folder
    assert blocker.read_text() == "not a folder"
    L._MEMO.clear()


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_read_only_folder_falls_back_to_memory(tmp_path, monkeypatch):
    """A read-only cache folder: as root chmod does not stop writes, so this test only runs
    its assertion about writes where the folder really is read-only."""
    d = tmp_path / "ro"
    (d / "lagrange").mkdir(parents=True)
    os.chmod(d / "lagrange", 0o555)
    monkeypatch.setenv("ANTHROARM_CACHE", str(d))
    L._MEMO.clear()
    try:
        dyn = L.load("planar2r")
        assert dyn.mass_matrix(np.zeros(2)).shape == (2, 2)
        if not os.access(d / "lagrange", os.W_OK):
            assert not list((d / "lagrange").iterdir())
            assert "in memory" in cache.status()
    finally:
        os.chmod(d / "lagrange", 0o755)
        L._MEMO.clear()


def test_atomic_write_keeps_old_file_on_failure(tmp_path):
    p = tmp_path / "f.txt"
    atomic_write_text(p, "old")

    with pytest.raises(TypeError):
        atomic_write_text(p, object())  # not text: nothing is written
    assert p.read_text() == "old" and sorted(x.name for x in tmp_path.iterdir()) == ["f.txt"]
    with pytest.raises(FileNotFoundError, match="does not exist"):
        atomic_write_text(tmp_path / "nope" / "x", "text")


def test_cli_cache_info_and_clear(cdir, capsys):
    L.load("planar2r")
    assert cli_main(["cache", "info", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["folder"] == str(cdir) and got["entries"] >= 1 and got["bytes"] > 0
    assert got["by_folder"]["lagrange"][0] >= 1
    (cdir / "keep.txt").write_text("a user's file next to the cache folders")
    assert cli_main(["cache", "clear"]) == 0
    assert "removed" in capsys.readouterr().out
    assert not list((cdir / "lagrange").iterdir())
    assert (cdir / "keep.txt").is_file()  # only the cache's own files go
    assert cli_main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert "entries 0" in out and str(cdir) in out


def test_damaged_bytecode_entry_is_recompiled(cdir):
    robot = aa.load("planar2r", l1=0.83)
    L.load(robot)
    (code,) = (cdir / "lagrange").glob("*.code")
    damage(code, code.read_bytes()[:50])
    L._MEMO.clear()
    dyn = L.load(robot)
    assert dyn.source == "cache"  # the verified source, compiled again
    q, v, a = np.array([0.2, 0.5]), np.array([0.3, -1.0]), np.array([1.0, 2.0])
    assert np.allclose(
        dyn.tau(q, v, a), pin.rnea(robot.model, robot.model.createData(), q, v, a), atol=1e-12
    )
    assert cache.read("lagrange", code.name) is not None


def test_a_kernel_is_compiled_again_when_a_kernel_it_calls_changes(tmp_path):
    """Numba keys a cached kernel by its own file only, but the compiled code holds the kernels
    it calls from other modules: package module b's kernel calls module a's; after a's kernel is
    edited (b untouched), a fresh process must run the new a.  anthroarm's own kernels live in a
    Numba folder per digest of their sources (jit.OWN_FOLDER); another package's kernels are
    not cached unless they ask (``cache=True``), so they are compiled in each process."""
    pkg = tmp_path / "kpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text(
        "from anthroarm.jit import kernel\n\n\n@kernel\ndef f(x):\n    return x + 1.0\n"
    )
    (pkg / "b.py").write_text(
        "from anthroarm.jit import kernel\n\nfrom .a import f\n\n\n@kernel\ndef g(x):\n"
        "    return 10.0 * f(x)\n"
    )
    env = dict(os.environ, ANTHROARM_CACHE=str(tmp_path / "cache"), PYTHONPATH=str(tmp_path))
    env.pop("NUMBA_CACHE_DIR", None)

    def run():
        r = subprocess.run(
            [sys.executable, "-c", "from kpkg.b import g; print(g(1.0))"],
            capture_output=True,
            text=True,
            env=env,
            timeout=300,
        )
        assert r.returncode == 0, r.stderr[-2000:]
        return float(r.stdout)

    assert run() == 20.0
    assert not list((tmp_path / "cache").rglob("*.nbi"))  # not cached: not anthroarm's sources
    assert run() == 20.0
    b_stat = (pkg / "b.py").stat()
    (pkg / "a.py").write_text(
        "from anthroarm.jit import kernel\n\n\n@kernel\ndef f(x):\n    return x + 2.0\n"
    )
    assert (pkg / "b.py").stat().st_mtime_ns == b_stat.st_mtime_ns
    assert run() == 30.0
