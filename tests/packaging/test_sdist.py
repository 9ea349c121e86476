"""The sdist carries what is needed to rebuild, test and document the package (the tests, the
notebooks, the docs sources, ``urdf/``, the benchmarks) and nothing generated: no page that
docs/conf.py writes at build time, no build output, no quick benchmark run.

Judged against git: every tracked file under those folders is in the sdist, and no file of the
sdist is one git ignores (the sdist's own ``*.egg-info`` metadata aside).  Built with setuptools'
PEP 517 hook, offline.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CARRIED = [
    "src",
    "tests",
    "notebooks",
    "docs",
    "urdf",
    "benchmarks",
    "LICENSE",
    "README.md",
    "CHANGELOG.md",
    "pyproject.toml",
    "MANIFEST.in",
]


def git(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, timeout=60)


def test_sdist_carries_the_sources_and_nothing_generated(tmp_path):
    if (
        shutil.which("git") is None
        or git("rev-parse", "--is-inside-work-tree").stdout.strip() != "true"
    ):
        pytest.skip("not a git checkout: nothing to compare the sdist with")
    import anthroarm

    out = subprocess.run(
        [
            sys.executable,
            "-c",
            f"from setuptools import build_meta as b; print(b.build_sdist({str(tmp_path)!r}))",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    sdist = tmp_path / out.stdout.strip().splitlines()[-1]
    assert sdist.name == f"anthroarm-{anthroarm.__version__}.tar.gz"
    prefix = f"anthroarm-{anthroarm.__version__}/"
    with tarfile.open(sdist) as tar:
        files = {m.name.removeprefix(prefix) for m in tar.getmembers() if m.isfile()}

    tracked = set(git("ls-files", "--", *CARRIED).stdout.splitlines())
    tracked = {f for f in tracked if (ROOT / f).is_file() and not Path(f).name.startswith(".")}
    missing = sorted(tracked - files)
    assert not missing, f"tracked files missing from the sdist: {missing[:20]}"
    for must in [
        "LICENSE",
        "src/anthroarm/py.typed",
        "tests/docs/test_docs_build.py",
        "docs/conf.py",
        "notebooks/quickstart.ipynb",
        "urdf/human_arm7.urdf",
    ]:
        assert must in files, must

    candidates = sorted(
        f for f in files if ".egg-info/" not in f and f not in ("PKG-INFO", "setup.cfg")
    )
    ignored = subprocess.run(
        ["git", "check-ignore", "--no-index", "--stdin"],
        cwd=ROOT,
        input="\n".join(candidates),
        capture_output=True,
        text=True,
        timeout=60,
    )
    generated = ignored.stdout.split()
    assert not generated, f"files git ignores (generated) are in the sdist: {generated[:20]}"
