"""mypy passes on src/anthroarm at the level stated in pyproject.toml ([tool.mypy]).

The package ships ``py.typed``, so its annotations are part of the API: this keeps them
consistent (undefined names, bad imports, invalid annotations, missing returns, bad overrides).
The cache goes to a temporary folder: nothing is written into the repository.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.slow


def test_mypy_passes_on_src(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--config-file",
            str(ROOT / "pyproject.toml"),
            "--cache-dir",
            str(tmp_path / "mypy-cache"),
            "--no-error-summary",
            "--hide-error-context",
            str(ROOT / "src" / "anthroarm"),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        stdin=subprocess.DEVNULL,
    )
    errors = [line for line in proc.stdout.splitlines() if ": error:" in line]
    assert proc.returncode == 0, (
        f"mypy: {len(errors)} errors\n" + "\n".join(errors[:40]) + proc.stderr[-2000:]
    )
