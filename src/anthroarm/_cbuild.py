"""Compiling generated C on first use: the system compiler, the on-disk cache, atomic writes.

Used by the optional compiled backends (:mod:`anthroarm.dynamics.ccode`,
:mod:`anthroarm.ik.analytic_c`).  Nothing here is needed when no compiler is present: the
callers fall back to numpy / pure Python.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path


def cache_dir(sub: str) -> Path:
    """``$ANTHROARM_CACHE/<sub>`` or ``~/.cache/anthroarm/<sub>``."""
    env = os.environ.get("ANTHROARM_CACHE")
    base = Path(env).expanduser() if env else Path.home() / ".cache" / "anthroarm"
    return base / sub


def compiler() -> str | None:
    """Path of the C compiler (``$CC``, default ``cc``), or None."""
    return shutil.which(os.environ.get("CC", "cc"))


def build_shared(src: str, so: Path, flags: list[str]) -> Path:
    """Compile C source ``src`` into the shared library ``so`` unless it already exists.

    The library is built in a temporary folder next to ``so`` and moved into place
    atomically, so a concurrent or interrupted build never leaves a half-written file.
    Raises RuntimeError (no compiler, or the compiler's first 500 characters of errors)."""
    from .urdf_io import atomic_write_text

    so = Path(so)
    if so.is_file():
        return so
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler ($CC or cc)")
    so.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=so.parent) as tmp:
        cpath = Path(tmp) / "src.c"
        cpath.write_text(src)
        opath = Path(tmp) / "lib.so"
        r = subprocess.run([cc, *flags, "-o", str(opath), str(cpath), "-lm"], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"C compilation failed: {r.stderr[:500]}")
        atomic_write_text(so, opath.read_bytes())
    return so
