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


@dataclass(frozen=True)
class RuleText:
    """A weight rule in words: what it asks, why, and the book's line (Chinese, as printed, and
    in English; line numbers of the OCR source ``000_f79f72c676d090fb.txt``)."""

    source: str
    words: str
    quote: str
    english: str


#: Every rule id of :func:`check`, explained (the report prints these next to the numbers).
RULE_TEXTS = {
    "L274": RuleText(
        "L274",
        "The motors and gearboxes of a powered prosthesis usually make up half or more of its "
        "weight, so the drive's mass sets the whole prosthesis's: between drive / 0.6 and "
        "drive / 0.5.  Information only: it turns the sized drive into a prosthesis mass the "
        "other rules are checked on (the lighter end, the most favourable reading).",
        "通常假手动力装置和减速机构部分的重量往往要占重量的50~60%。",
        "The power unit and reduction gearing usually take 50-60 % of a prosthesis's weight "
        "(§1, direct devices).",
    ),
    "L7445": RuleText(
        "L7445",
        "A practical full-arm prosthesis must be light: not more than 2 kg.  Checked on the "
        "lightest prosthesis mass the drive implies (L274).",
        "(1) 臂重要轻,要求不大于2 kg;",
        "(1) The arm must be light: not more than 2 kg (§9-2, conditions for a practical "
        "full-arm prosthesis).",
    ),
    "L7298": RuleText(
        "L7298",
        "A person's two arms weigh about 12.6 % of the body, so one arm about 6.3 %; a prosthesis "
        "heavier than the arm it replaces is felt as a burden (the book adds that even the same "
        "mass is felt, since the sense of the arm's weight fades after amputation).  Checked on "
        "the lightest implied prosthesis mass against 6.3 % of the person's body mass.",
        "人的(双)臂重约为本身体重的12.6%,若从这点出发,全臂假手的重可为4~5 kg左右。",
        "A person's (two) arms weigh about 12.6 % of the body; from this, a full-arm prosthesis "
        "could weigh about 4-5 kg (§9-2, weight and output).",
    ),
    "L7441": RuleText(
        "L7441",
        "To handle an object with its six degrees of freedom the way a hand does, a full-arm "
        "prosthesis needs at least seven: shoulder 3, elbow 1, forearm 2, hand 1.  Checked on "
        "the joints of the sized arm model.",
        "必须确保假手至少有七个自由度,即肩部3个、肘部1个、前臂2个、手部1个。",
        "The prosthesis must have at least seven degrees of freedom: shoulder 3, elbow 1, "
        "forearm 2, hand 1 (§9-2).",
    ),
}
