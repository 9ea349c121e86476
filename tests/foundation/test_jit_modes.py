"""The three modes of :mod:`anthroarm.jit` (issue 28: no compilation on the user's clock).

- ``reference``: every kernel runs its source in the interpreter, with the same answers as the
  compiled kernel (the closed-form IK of arms of every kind, compared pose by pose);
- ``auto`` with an empty cache: the first call answers from the reference at once, and one
  background compilation is started; a process switches to compiled code when a ready stamp
  appears and its files verify; a damaged or unlisted file is deleted and never loaded;
- ``compile``: Numba's own behaviour (the test suite's mode, tests/conftest.py).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import jit

ARMS = ("ur5", "prosthetic_arm", "sixr_arm", "human_arm7", "panda", "planar2r")

DIGEST = r"""
import json, sys
import numpy as np
import anthroarm as aa
from anthroarm import jit
out = {}
for name in sys.argv[1].split(","):
    r = aa.load(name)
    Q = r.random_q(12, np.random.default_rng(7))
    T = r.fk(Q)
    sols = []
    for i in range(len(T)):
        kw = {"swivel": 0.4} if name == "human_arm7" else {}
        if name == "panda":
            kw = {"param": float(Q[i, -1])}
        res = aa.ik.analytic(r, T[i], **kw)
        sols.append([np.round(res.solutions, 9).tolist(), [str(b) for b in res.branches]])
    out[name] = sols
out["status"] = jit.status()
print(json.dumps(out))
"""


def _run(code, env_extra, *args, timeout=600):
    env = dict(os.environ, **env_extra)
    p = subprocess.run(
        [sys.executable, "-c", code, *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=timeout,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    return p.stdout


def test_reference_answers_as_compiled(tmp_path):
    """Pose by pose, the reference (interpreter) and the compiled kernels give the same
    solutions (to 1e-9 rad) and branches, on arms of every closed-form kind: IK-Geo classes
    (ur5, the prosthetic arm, the 6R arm), the SRS family (human_arm7 at a swivel angle), a
    7-joint arm with its last joint held (panda) and the planar 2R arm."""
    names = ",".join(ARMS)
    ref = json.loads(_run(DIGEST, {"ANTHROARM_JIT": "reference"}, names))
    com = json.loads(_run(DIGEST, {"ANTHROARM_JIT": "compile"}, names))
    assert ref.pop("status") == "reference (ANTHROARM_JIT=reference)"
    assert com.pop("status") == "compiled"
    assert sum(len(s[0]) for arm in com.values() for s in arm) > 100  # solutions were found
    for name in ARMS:
        for (qr, br), (qc, bc) in zip(ref[name], com[name]):
            assert br == bc, name
            np.testing.assert_allclose(np.array(qr), np.array(qc), atol=1e-9, err_msg=name)


def test_reference_math_is_numbas():
    """Where CPython's math raises, the reference returns what the compiled kernel does."""
    assert np.isnan(jit.MATH.sqrt(-1.0)) and np.isnan(jit.MATH.acos(1.5))
    assert np.isnan(jit.MATH.floor(float("nan"))) and jit.MATH.floor(2.7) == 2
    assert jit.MATH.exp(1e4) == float("inf")
    assert jit.MATH.atan2(1.0, 0.0) == np.pi / 2


def test_unknown_mode_is_a_typed_error(monkeypatch):
    monkeypatch.setenv("ANTHROARM_JIT", "fast")
    with pytest.raises(aa.errors.ParameterError, match="ANTHROARM_JIT='fast'.*auto, compile"):
        jit.mode()


PACKAGE = {
    "__init__.py": "",
    "k.py": textwrap.dedent(
        """
        import math
        from anthroarm.jit import kernel, local

        @kernel(cache=True)
        def norm2(x, y):
            a = local(2)
            a[0], a[1] = x, y
            return math.sqrt(a[0] * a[0] + a[1] * a[1])
        """
    ),
}

PROBE = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1])
from tinypkg.k import norm2
from anthroarm import jit
t = time.perf_counter()
v = norm2(3.0, 4.0)
first = time.perf_counter() - t
out = {"value": v, "first": first, "status": jit.status(), "compiled": norm2.fn is norm2.dispatcher}
if len(sys.argv) > 2 and sys.argv[2] == "wait":
    out["switched"] = jit.wait(float(sys.argv[3]))
    out["value2"] = norm2(6.0, 8.0)
    out["compiled2"] = norm2.fn is norm2.dispatcher
if len(sys.argv) > 2 and sys.argv[2] == "stamp":
    out["files"] = len(jit.write_stamp(complete=True))
print(json.dumps(out))
"""


@pytest.fixture
def tiny(tmp_path):
    pkg = tmp_path / "src" / "tinypkg"
    pkg.mkdir(parents=True)
    for name, text in PACKAGE.items():
        (pkg / name).write_text(text)
    cache = tmp_path / "cache"
    env = {"ANTHROARM_CACHE": str(cache), "NUMBA_CACHE_DIR": str(cache / "numba")}
    return str(tmp_path / "src"), cache, env


def _sleeper():
    """A live process standing for a background compilation (its pid in the lock)."""
    return subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])


def _hold_lock(src, env, pid):
    """Write ``pid`` into the lock of this stamp (as start_background does)."""
    code = f"import sys; sys.path.insert(0, {src!r}); import tinypkg.k; from anthroarm import jit\n"
    code += (
        f"p = jit.lock_path(); p.parent.mkdir(parents=True, exist_ok=True); p.write_text('{pid}')"
    )
    _run(code, env)


def test_auto_answers_at_once_then_switches(tiny):
    """auto, empty cache: the first call answers from the reference (no compilation in the
    caller's thread) while a compilation runs; when another process has compiled the kernels
    and written the ready stamp, the waiting process verifies the files and switches; a third
    process starts compiled."""
    src, cache, env = tiny
    sleeper = _sleeper()
    try:
        _hold_lock(src, env, sleeper.pid)  # a background compilation "runs"
        waiting = subprocess.Popen(
            [sys.executable, "-c", PROBE, src, "wait", "600"],
            env=dict(os.environ, **env, ANTHROARM_JIT="auto"),
            stdout=subprocess.PIPE,
            text=True,
        )
        time.sleep(3.0)  # it answered from the reference and waits
        made = json.loads(_run(PROBE, dict(env, ANTHROARM_JIT="compile"), src, "stamp"))
        assert made["value"] == 5.0 and made["files"] >= 2  # an index and a data file
        out = json.loads(waiting.communicate(timeout=120)[0])
    finally:
        sleeper.kill()
    assert out["value"] == 5.0 and not out["compiled"]
    assert out["status"] == "reference (compiling in the background)"
    assert out["switched"] and out["compiled2"] and out["value2"] == 10.0
    warm = json.loads(_run(PROBE, dict(env, ANTHROARM_JIT="auto"), src))
    assert warm["compiled"] and warm["status"] == "compiled" and warm["value"] == 5.0


def test_auto_starts_one_background_compilation(tiny):
    """With an empty cache the first kernel call starts ``python -m anthroarm.warmup`` (its pid
    in the lock file), and a second process does not start another."""
    src, cache, env = tiny
    code = PROBE + "print(jit.running())\n"
    out = _run(code, dict(env, ANTHROARM_JIT="auto"), src).splitlines()
    pid = int(out[-1])
    try:
        assert pid > 0 and json.loads(out[0])["status"] == "reference (compiling in the background)"
        again = _run(code, dict(env, ANTHROARM_JIT="auto"), src).splitlines()
        assert int(again[-1]) == pid
        # in the callers' session (Linux gives each session an equal share of the CPU, whatever
        # its nice: a compilation in a session of its own took a core from a caller on 2), in
        # its own process group (a Ctrl-C in the caller's terminal does not stop it), and at
        # the lowest priority once it runs
        assert os.getpgid(pid) == pid
        if sys.version_info >= (3, 11):  # Popen(process_group=); 3.10 starts a new session
            assert os.getsid(pid) == os.getsid(0)
        deadline = time.monotonic() + 60
        while os.getpriority(os.PRIO_PROCESS, pid) < 19 and time.monotonic() < deadline:
            time.sleep(0.1)
        assert os.getpriority(os.PRIO_PROCESS, pid) == 19
    finally:
        try:
            os.killpg(pid, signal.SIGKILL)  # it runs in its own process group
        except ProcessLookupError:
            pass


def test_damaged_or_planted_files_are_never_loaded(tiny):
    """A ready stamp lists the SHA-256 of every Numba file: a file edited after it (or one it
    does not list, in a kernel folder) is deleted, the stamp withdrawn and the process stays
    on the reference, with the same answer."""
    src, cache, env = tiny
    _run(PROBE, dict(env, ANTHROARM_JIT="compile"), src, "stamp")
    files = sorted((cache / "numba").rglob("*.nbc"))
    assert files
    data = files[0].read_bytes()
    files[0].write_bytes(data[:-7] + b"planted")
    planted = files[0].with_name("planted.nbi")
    planted.write_bytes(b"not numba's")
    sleeper = _sleeper()
    try:
        _hold_lock(src, env, sleeper.pid)  # no background compilation starts here
        out = json.loads(_run(PROBE, dict(env, ANTHROARM_JIT="auto"), src))
    finally:
        sleeper.kill()
    assert out["value"] == 5.0 and not out["compiled"]
    assert not files[0].exists() and not planted.exists()
    code = f"import sys; sys.path.insert(0, {src!r}); import tinypkg.k; from anthroarm import jit\n"
    code += "print(jit.verified())"
    assert _run(code, env).strip() == "False"


def test_the_warmup_reaches_every_kernel():
    """``python -m anthroarm.warmup`` reaches every kernel of the package through the public
    entry points (run on the reference path, where every kernel call passes its Kernel: none
    is left that a user's call would compile on the caller's clock)."""
    code = "from anthroarm import warmup, jit\njit.start()\nprint(warmup.run(n=2))"
    assert _run(code, {"ANTHROARM_JIT": "reference"}).strip() == "[]"


def test_numba_imported_first(tiny):
    """A program that imports Numba before anthroarm (without ``$NUMBA_CACHE_DIR``): its kernels
    still cache in anthroarm's folder (Numba's configuration reloaded), and the first call
    answers (it raised KeyError: 'NUMBA_CACHE_DIR' in every mode but reference)."""
    src, cache, env = tiny
    code = "import numba\n" + PROBE.replace(
        "from anthroarm import jit\n",
        "from anthroarm import jit\n"
        "assert numba.config.CACHE_DIR == str(jit.OWN_FOLDER), numba.config.CACHE_DIR\n",
    )
    environ = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environ.update(ANTHROARM_CACHE=str(cache), ANTHROARM_JIT="compile")
    p = subprocess.run(
        [sys.executable, "-c", code, src], capture_output=True, text=True, env=environ, timeout=600
    )
    assert p.returncode == 0, p.stderr[-3000:]
    out = json.loads(p.stdout)
    assert out["value"] == 5.0 and out["compiled"]
    assert list((cache / "numba").rglob("*.nbi")), "no kernel cached in anthroarm's folder"
