"""The book's data tables that are data, read from package files (``anthroarm/data/book``).

* Table 2.3 (l. 652–658): the four manipulator motion forms and how they compare
  (:func:`robot_forms`; their kinematic templates are :mod:`anthroarm.models.templates`);
* Table 2.4 (l. 849–858): the ranges of motion of the human lower limb (:func:`lower_limb_rom`,
  :func:`lower_limb_limits`);
* Table 9.6 (l. 7625–7642): the melody codes of the care robot's communication device (§9-3)
  (:func:`melody_codes`, :func:`melody_lookup`).

The CSV files hold the printed values verbatim (Chinese text as printed, with an English gloss
of ours); what the print leaves blank stays blank.  Angles in degrees in the files, radians
from :func:`lower_limb_limits`.
"""

from __future__ import annotations

import csv
import functools
import io
import math
from dataclasses import dataclass
from importlib import resources

from ..errors import UnknownCodeError

#: melody codes the device prepares with 3 and with 4 notes (l. 7621)
MELODY_CODES_3_NOTES = 104
MELODY_CODES_4_NOTES = 405


def _rows(name: str) -> list[dict]:
    text = resources.files("anthroarm").joinpath("data", "book", name).read_text(encoding="utf-8")
    return list(csv.DictReader(io.StringIO(text)))


@dataclass(frozen=True)
class MelodyCode:
    """One row of Table 9.6: number, the display code (two hex digits), the spoken output as
    printed and an English gloss (ours).  The melody pattern (图形) was a figure and is lost."""

    no: int
    display: str
    output_zh: str
    output_en: str


@functools.cache
def melody_codes() -> tuple[MelodyCode, ...]:
    """The 36 rows of Table 9.6 in the printed order (No. 1–36)."""
    return tuple(
        MelodyCode(int(r["no"]), r["display"], r["output_zh"], r["output_en"])
        for r in _rows("table_9_6_melody.csv")
    )


def melody_lookup(display: str) -> MelodyCode:
    """The Table 9.6 row of a display code (two hex digits, case-insensitive, e.g. ``"5D"``).

    Raises
    ------
    UnknownCodeError
        The code is not in the table; the message lists the printed codes.
    """
    key = str(display).strip().upper()
    for row in melody_codes():
        if row.display == key:
            return row
    raise UnknownCodeError(
        f"display code {display!r} is not in Table 9.6; printed codes: "
        f"{', '.join(r.display for r in melody_codes())}"
    )


@dataclass(frozen=True)
class RangeOfMotion:
    """One row of Table 2.4: joint, motion, the range in degrees (``None`` where the print is
    blank) and the printed cell ("约 120°" = about 120°)."""

    joint: str
    joint_zh: str
    motion: str
    motion_zh: str
    range_deg: float | None
    printed: str


@functools.cache
def lower_limb_rom() -> tuple[RangeOfMotion, ...]:
    """Table 2.4, the ranges of motion of the human lower limb, row by row as printed.  The
    knee-extension cell is blank in the print (``range_deg`` None)."""
    return tuple(
        RangeOfMotion(
            r["joint"],
            r["joint_zh"],
            r["motion"],
            r["motion_zh"],
            float(r["range_deg"]) if r["range_deg"] else None,
            r["printed"],
        )
        for r in _rows("table_2_4_lower_limb_rom.csv")
    )


def lower_limb_limits() -> dict[str, tuple[float, float]]:
    """Joint limits (lower, upper) in rad from Table 2.4, flexion positive:
    ``hip_flexion`` (−30°, 120°), ``hip_rotation`` (−45°, 45°), ``knee_flexion`` (0°, 120°),
    ``ankle_flexion`` (−45° plantar, 45° dorsal).  The blank knee-extension cell is read as 0°
    (no hyperextension), an assumption (ch1-2 notes §7 item 15)."""
    rom = {(r.joint, r.motion): r.range_deg for r in lower_limb_rom()}
    d = math.radians
    knee_ext = rom[("knee", "extension")] or 0.0
    return {
        "hip_flexion": (-d(rom[("hip", "extension")]), d(rom[("hip", "flexion")])),
        "hip_rotation": (
            -d(rom[("hip", "internal_external_rotation")]),
            d(rom[("hip", "internal_external_rotation")]),
        ),
        "knee_flexion": (-d(knee_ext) if knee_ext else 0.0, d(rom[("knee", "flexion")])),
        "ankle_flexion": (-d(rom[("ankle", "plantarflexion")]), d(rom[("ankle", "dorsiflexion")])),
    }


@dataclass(frozen=True)
class RobotForm:
    """One row of Table 2.3 (printed Chinese): workspace shape, space taken, relative working
    range, intuitiveness, how often used, remark."""

    form: str
    form_zh: str
    workspace_shape_zh: str
    footprint_zh: str
    relative_workspace_zh: str
    intuitiveness_zh: str
    use_zh: str
    remark_zh: str


@functools.cache
def robot_forms() -> tuple[RobotForm, ...]:
    """Table 2.3: Cartesian, cylindrical, spherical, articulated, as printed ("球多球体" of
    the articulated row is printed so; read 多球体, a union of spheres)."""
    return tuple(RobotForm(**r) for r in _rows("table_2_3_robot_forms.csv"))


__all__ = [
    "MELODY_CODES_3_NOTES",
    "MELODY_CODES_4_NOTES",
    "MelodyCode",
    "melody_codes",
    "melody_lookup",
    "RangeOfMotion",
    "lower_limb_rom",
    "lower_limb_limits",
    "RobotForm",
    "robot_forms",
]
