"""``anthroarm urdf``: the run (the parser: :mod:`.urdf`)."""

from __future__ import annotations

from pathlib import Path

from .._io import atomic_write_text
from ..errors import UnsupportedModelError
from .common import UserError
from .runtime import load_model, parse_params
from .urdf_osim import osim_urdf_text


def run(a) -> int:
    out = Path(a.out)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist")
    if out.is_dir():
        raise UserError(f"-o {a.out} is a folder; give a file name such as {out / 'robot.urdf'}")
    if str(a.model).lower().endswith(".osim"):  # an OpenSim model: its Pinocchio model written
        try:
            robot = load_model(a.model, parse_params(a.param, a.model, a))
            text = osim_urdf_text(robot)
        except UnsupportedModelError as e:
            raise UserError(str(e)) from None
        atomic_write_text(out, text)
        print(f"wrote {out}")
        g = " ".join(f"{x:g}" for x in robot.model.gravity.linear)
        print(
            f"gravity: the model's is ({g}) m/s^2 (OpenSim's y is up); a URDF has none: "
            "set robot.model.gravity after loading it"
        )
        return 0
    robot = load_model(
        a.model, parse_params(a.param, a.model, a), tool="universe"
    )  # any frame: only the text is written
    atomic_write_text(out, robot.info.text)
    print(f"wrote {out}")
    return 0
