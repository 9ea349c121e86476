"""``anthroarm urdf``: the run (the parser: :mod:`.urdf`)."""

from __future__ import annotations

from pathlib import Path

from .._io import atomic_write_text
from .common import UserError
from .runtime import load_model, parse_params


def run(a) -> int:
    out = Path(a.out)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist")
    if out.is_dir():
        raise UserError(f"-o {a.out} is a folder; give a file name such as {out / 'robot.urdf'}")
    robot = load_model(
        a.model, parse_params(a.param, a.model, a), tool="universe"
    )  # any frame: only the text is written
    atomic_write_text(out, robot.info.text)
    print(f"wrote {out}")
    return 0
