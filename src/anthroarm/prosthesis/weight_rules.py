"""The book's weight rules for a powered full-arm prosthesis (book notes ch1-2 / ch9 §2.2 R4).

Printed in the book (line numbers of the OCR source ``000_f79f72c676d090fb.txt``):

* L274 (§1, direct devices): the power unit and reduction gearing are usually **50–60 %** of a
  prosthesis's weight (通常假手动力装置和减速机构部分的重量往往要占重量的50~60%);
* L7298 (§9-2 一 4, weight and output): a person's (two) arms weigh about **12.6 %** of the body,
  so a full-arm prosthesis could weigh about 4–5 kg (人的(双)臂重约为本身体重的12.6%, …
  全臂假手的重可为4~5 kg左右); one arm is taken as half of it, 6.3 %;
* L7445 (§9-2 三 3, conditions for a practical full-arm prosthesis): the arm must be light,
  **not more than 2 kg** (臂重要轻，要求不大于2 kg), with at least **7 DOF** (shoulder 3, elbow 1,
  forearm 2, hand 1; L7441).

The sizing gives the drive mass (motors + gearboxes).  The prosthesis mass it implies follows
from the 50–60 % share: between drive / 0.6 and drive / 0.5; the rules are checked on the lighter
end (drive / 0.6), the most favourable reading, and the range is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

DRIVE_SHARE = (0.50, 0.60)  # L274
ARMS_FRACTION = 0.126  # both arms / body mass, L7298
MAX_FULL_ARM_MASS = 2.0  # kg, L7445
MIN_DOF = 7  # L7441


@dataclass(frozen=True)
class RuleCheck:
    """One rule: ``value`` and ``limit`` in ``unit``; ``ok`` True/False (None: information only)."""

    rule: str
    source: str
    value: float
    limit: float
    unit: str
    ok: bool | None
    note: str = ""


def prosthesis_mass_range(drive_mass: float) -> tuple[float, float]:
    """(lightest, heaviest) prosthesis mass (kg) for a drive of ``drive_mass`` kg that is 60 % or
    50 % of it (L274)."""
    return drive_mass / DRIVE_SHARE[1], drive_mass / DRIVE_SHARE[0]


def check(
    drive_mass: float, body_mass: float | None, dof: int, unsized_joints: int = 0
) -> list[RuleCheck]:
    """The rules of the module docstring for a drive of ``drive_mass`` kg on an arm with ``dof``
    joints, for a person of ``body_mass`` kg (``None``: unknown, the 12.6 % rule is left out).
    ``unsized_joints`` > 0 (joints without a motor) makes the masses lower bounds (said in the
    notes).  Bad masses raise :class:`~anthroarm.errors.ParameterError`."""
    try:
        if isinstance(drive_mass, bool) or isinstance(body_mass, bool):
            raise TypeError  # True is not a mass
        drive = float(drive_mass)
        body = float("nan") if body_mass is None else float(body_mass)
    except (TypeError, ValueError):
        drive = body = float("nan")
    for name, v in (("dof", dof), ("unsized_joints", unsized_joints)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise ParameterError(f"weight rules need {name} as a whole number >= 0, got {v!r}")
    if not (
        np.isfinite(drive)
        and drive >= 0
        and (body_mass is None or (np.isfinite(body) and body > 0))
    ):
        raise ParameterError(
            f"weight rules need drive_mass >= 0 kg and body_mass > 0 kg (or None), got "
            f"{drive_mass!r}, {body_mass!r}"
        )
    drive_mass = drive
    lo, hi = prosthesis_mass_range(drive_mass)
    partial = f" (lower bound: {unsized_joints} joint(s) without a motor)" if unsized_joints else ""
    rows = [
        RuleCheck(
            "drive (motors + gearboxes) is 50-60 % of the prosthesis",
            "L274",
            lo,
            hi,
            "kg",
            None,
            f"implied prosthesis mass {lo:.2f}-{hi:.2f} kg from a drive of {drive_mass:.3f} kg{partial}",
        ),
        RuleCheck(
            "full-arm prosthesis not more than 2 kg",
            "L7445",
            lo,
            MAX_FULL_ARM_MASS,
            "kg",
            bool(lo <= MAX_FULL_ARM_MASS),
            f"lightest implied mass (drive / 0.6){partial}",
        ),
        RuleCheck(
            "at least 7 DOF (shoulder 3, elbow 1, forearm 2, hand 1)",
            "L7441",
            float(dof),
            float(MIN_DOF),
            "DOF",
            bool(dof >= MIN_DOF),
            "joints of the sized arm model (a hand's grip is not in it)",
        ),
    ]
    if body_mass is not None:
        one_arm = ARMS_FRACTION / 2 * body
        rows.insert(
            2,
            RuleCheck(
                "not heavier than the person's own arm (both arms 12.6 % of the body; book: 4-5 kg)",
                "L7298",
                lo,
                one_arm,
                "kg",
                bool(lo <= one_arm),
                f"6.3 % of {body:g} kg{partial}",
            ),
        )
    return rows
