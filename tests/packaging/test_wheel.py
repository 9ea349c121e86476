"""The wheel: built from the sources offline, it holds the package (and ``py.typed``) and nothing
else, and once installed into a fresh venv it works outside a source checkout.

The build copies the files a release is built from (pyproject.toml, README, LICENSE, MANIFEST.in,
CHANGELOG, src/) into a temporary folder first, so no ``build/`` or stale module of the working
tree can leak into the wheel.  ``pip wheel --no-deps --no-build-isolation --no-index``: no network
(setuptools >= 77 comes from the ``test`` extra).  The fresh venv (``--without-pip``; the project
venv's pip installs into it with ``--python``) gets the dependencies by adding the project venv's
site-packages *after* its own, and drops the checkout's ``src/`` that the editable install would
put on ``sys.path``: ``anthroarm`` can only come from the wheel, which the test asserts.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RELEASE_FILES = ["pyproject.toml", "README.md", "LICENSE", "MANIFEST.in", "CHANGELOG.md"]

pytestmark = pytest.mark.slow


def run(cmd, cwd, env=None, timeout=180):
    proc = subprocess.run(
        [str(c) for c in cmd],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
    )
    assert proc.returncode == 0, (
        f"{' '.join(map(str, cmd))} failed "
        f"({proc.returncode}):\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    )
    return proc.stdout


def build_wheel(tmp: Path) -> Path:
    src = tmp / "src-copy"
    src.mkdir()
    for name in RELEASE_FILES:
        shutil.copy2(ROOT / name, src / name)
    shutil.copytree(
        ROOT / "src",
        src / "src",
        ignore=shutil.ignore_patterns("__pycache__", "*.py[cod]", "*.egg-info", ".mypy_cache"),
    )
    dist = tmp / "dist"
    run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "-q",
            "-w",
            dist,
            src,
        ],
        cwd=tmp,
    )
    wheels = list(dist.glob("anthroarm-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


def test_wheel_contents_and_install_outside_the_checkout(tmp_path):
    import anthroarm

    wheel = build_wheel(tmp_path)
    assert wheel.name == f"anthroarm-{anthroarm.__version__}-py3-none-any.whl"

    # ------------------------------------------------------------------ contents
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        dist_info = f"anthroarm-{anthroarm.__version__}.dist-info"
        meta = z.read(f"{dist_info}/METADATA").decode()
        entry_points = z.read(f"{dist_info}/entry_points.txt").decode()
    tops = {n.split("/")[0] for n in names}
    assert tops == {"anthroarm", dist_info}, f"unexpected top-level entries: {sorted(tops)}"
    assert "anthroarm/py.typed" in names
    assert not [n for n in names if "/tests/" in n or n.startswith("tests/") or "/test_" in n]
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
    # every module of the source tree is in the wheel
    modules = {
        p.relative_to(ROOT / "src").as_posix() for p in (ROOT / "src" / "anthroarm").rglob("*.py")
    }
    missing = modules - set(names)
    assert not missing, f"modules missing from the wheel: {sorted(missing)[:10]}"
    assert any(n.endswith("/LICENSE") for n in names), "LICENSE not in the wheel's metadata"
    assert "anthroarm = anthroarm.cli:main" in entry_points
    for field in [
        "License-Expression: BSD-3-Clause",
        "Requires-Python: >=3.10",
        "Classifier: Typing :: Typed",
        "Provides-Extra: docs",
    ]:
        assert field in meta, f"METADATA has no {field!r}"
    # the dependencies pinned to their tested ranges (pyproject.toml), in whatever order pip
    # normalises the bounds
    requires = [line for line in meta.splitlines() if line.startswith("Requires-Dist: ")]
    for name, bounds in (("pin", (">=4", "<5")), ("numba", (">=0.68", "<0.69"))):
        line = [
            r
            for r in requires
            if r.split()[1].startswith(name + "<") or r.split()[1].startswith(name + ">")
        ]
        assert line and all(b in line[0] for b in bounds), (name, requires)

    # ------------------------------------------------------------------ a fresh venv
    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", "--without-pip", venv], cwd=tmp_path)
    py = venv / "bin" / "python"
    run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            py,
            "install",
            "--no-deps",
            "--no-index",
            "-q",
            wheel,
        ],
        cwd=tmp_path,
    )
    site_new = Path(
        run(
            [py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=tmp_path
        ).strip()
    )
    deps = sysconfig.get_paths()["purelib"]  # the project venv: the dependencies, already installed
    src = str(ROOT / "src")
    (site_new / "zz_project_deps.pth").write_text(
        f"import site, sys; site.addsitedir({deps!r}); sys.path[:] = [p for p in sys.path if p != "
        f"{src!r}]\n"
    )

    outside = tmp_path / "elsewhere"
    outside.mkdir()
    env = {
        k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")
    }
    env["ANTHROARM_CACHE"] = str(tmp_path / "cache")
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"

    out = run(
        [
            py,
            "-c",
            "import sys, anthroarm; print(anthroarm.__file__); "
            "print(anthroarm.models.urdf_path('human_arm7')); print(src_on_path := "
            f"any(p in ({src!r}, {str(ROOT)!r}) for p in sys.path))",
        ],
        cwd=outside,
        env=env,
    ).split("\n")
    installed, urdf, on_path = Path(out[0]), Path(out[1]), out[2]
    assert installed.is_relative_to(venv), (
        f"anthroarm was imported from {installed}, not the installed wheel"
    )
    assert on_path == "False", "the source checkout is on sys.path of the fresh venv"
    assert urdf.is_file() and urdf.is_relative_to(tmp_path / "cache"), urdf
    assert urdf.read_text() == (ROOT / "urdf" / "human_arm7.urdf").read_text(), (
        "installed URDF differs from the committed one"
    )

    # the console script of the wheel: the cross-check and the URDF writer, outside the checkout
    exe = venv / "bin" / "anthroarm"
    assert exe.is_file()
    assert run([exe, "--version"], cwd=outside, env=env).split()[-1] == anthroarm.__version__
    check = run([exe, "check", "--models", "planar2r", "--samples", "50"], cwd=outside, env=env)
    assert " 0 failed" in check and "passed" in check, check[-2000:]
    run([exe, "urdf", "planar2r", "-o", outside / "p.urdf"], cwd=outside, env=env)
    assert (outside / "p.urdf").read_text() == (ROOT / "urdf" / "planar2r.urdf").read_text()
