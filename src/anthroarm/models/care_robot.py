"""The bedridden-patient care manipulator of §9-3 (Univ. of Tokyo et al., from 1978), Table 9.5.

What the book prints (000 l. 7556–7617, ch9 notes §2.2 R1):

* Table 9.5 (l. 7568–7572): segment lengths 基部 base 115 mm, 上臂 upper arm 295 mm, 前臂
  forearm 280 mm, 指掌 finger-palm 186 mm, 全长 total **856 mm**; masses 2.38, 1.82, 1.16,
  0.57 kg, total 5.93 kg.  The masses add up; the lengths add up to **876 mm**, not the printed
  856 mm (``docs/errata.md``; :data:`TABLE_9_5`, :func:`table_9_5_length_sum_mm`).  The text
  cannot tell which number is misprinted, so the model keeps the four printed segment lengths.
* 9 DOF: 6 in the arm's joints (flexion and rotation) and a 3-finger gripper; a pair of arms
  (18 motors); coreless DC motors with an optical encoder and a worm reduction.
* Position control by the spatial cell method (§7-3) on a lattice every **10 cm** in x, y, z,
  the motor pulses from the origin to every lattice point stored in ROM, accuracy **1 cm**
  (l. 7589): :data:`CELL_D`, :data:`CELL_ACCURACY`; the spec declares the table
  (``spec.cells``, a :class:`~anthroarm.models.spec.CellRecipe`: orientation, box, branch, the
  wrist centre as its point, the pulse scale) and :func:`anthroarm.ik.cells.cell_table` builds
  it.

**Assumed** (the joint layout and the ranges were in Fig. 9-28, which is lost):

* the arm is the 6R arm with a spherical wrist of Fig. 6-3 (the book's own anthropomorphic
  template, H-D table α01 = α23 = α34 = α45 = 90°, α12 = α56 = 0): waist yaw, shoulder and elbow
  pitch, a three-axis wrist.  The segments map onto its symbols: base → s0 = l_AB (shoulder
  height), upper arm → h2 = l_BC, forearm → s3 = l_CD, finger-palm → P = l_DP (wrist centre to
  the grip point).  The arm therefore has the closed-form IK of Eqs. (7-1)–(7-15);
* every joint ranges over ±180° (no ranges printed);
* the three finger DOF are not in the kinematic chain (the tool frame is the grip point); their
  mass is part of the finger-palm segment;
* the mass of each printed segment is a uniform cylinder along it (radius 25 mm); the two
  zero-length links of the H-D table (elbow housing, wrist housing) carry 0.10 kg taken from the
  forearm and the finger-palm respectively, so the model's total mass is the printed 5.93 kg.

Units: metres, kilograms, radians.
"""

from __future__ import annotations

from ..spatial.rotations import homogeneous
from .book import _lengths, sixr_arm
from .spec import CellRecipe, ChainSpec, encoder_pulses_per_rad, from_dh, rod_link

#: Table 9.5 as printed: segment -> (length mm, mass kg); "total" is the printed 全长 row
TABLE_9_5 = {
    "base": (115.0, 2.38),
    "upper_arm": (295.0, 1.82),
    "forearm": (280.0, 1.16),
    "finger_palm": (186.0, 0.57),
    "total": (856.0, 5.93),
}
#: cell size of the care robot's lattice, m (l. 7589: "every 10 cm in x, y, z")
CELL_D = 0.10
#: stated positioning accuracy of the cell method, m per axis (l. 7589: 1 cm)
CELL_ACCURACY = 0.01
#: mass (kg) given to each zero-length housing link (elbow, wrist): an assumption, see above
HOUSING_MASS = 0.10
#: encoder counts per motor turn (assumed, the book prints none): a 500-line optical shaft
#: encoder (e.g. the HEDS-5500 class, Avago/Broadcom datasheet) read in quadrature, 4 × 500
ENCODER_COUNTS = 2000
#: motor turns per joint turn of the worm reduction (assumed, the book prints none)
GEAR_RATIO = 200.0
#: the hand orientation of the care robot's cell table (assumed): grip axis z6 horizontal and
#: forward (+x, towards the patient), x6 down; the columns are x6, y6, z6 in the base frame
R_FORWARD = ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0))
#: the box (m, base frame) of wrist positions the table covers (assumed): in front of the arm
CELL_BOUNDS = ((0.1, -0.4, -0.3), (0.5, 0.4, 0.4))
#: the IK branch stored in the table (one branch, so that the 8 corners of a cell agree): the
#: book's shoulder front, elbow up, wrist no-flip of Eqs. (7-2), (7-6), (7-8) — θ1 facing the
#: wrist centre (|θ1| ≤ 90° in front of the arm), θ3 = asin k in [−90°, 90°], θ5 ≥ 0 — which is
#: branch (1, 0, 1) of the spherical-wrist + two-parallel class solver (aa.ik.analytic's labels)
CELL_BRANCH = "q1=1,q3=0,q5=1"
#: degrees of freedom printed (6 arm joints + 3 fingers) and the motor count of the pair of arms
DOF_PRINTED = 9
MOTORS_PRINTED = 18


def table_9_5_length_sum_mm() -> float:
    """Sum of the four printed segment lengths of Table 9.5 (mm): 876, not the printed 856."""
    return float(sum(TABLE_9_5[k][0] for k in ("base", "upper_arm", "forearm", "finger_palm")))


def table_9_5_mass_sum_kg() -> float:
    """Sum of the four printed segment masses of Table 9.5 (kg): 5.93, as printed."""
    return float(sum(TABLE_9_5[k][1] for k in ("base", "upper_arm", "forearm", "finger_palm")))


def pulses_per_rad(encoder_counts: float = ENCODER_COUNTS, gear_ratio: float = GEAR_RATIO) -> float:
    """Motor pulses per joint radian: ``encoder_counts · gear_ratio / 2π`` (both assumed, see
    :data:`ENCODER_COUNTS`, :data:`GEAR_RATIO`).  :class:`~anthroarm.errors.ParameterError` unless
    both are finite and > 0."""
    return encoder_pulses_per_rad(encoder_counts, gear_ratio)


def care_robot(
    s0: float = 0.115, h2: float = 0.295, s3: float = 0.280, P: float = 0.186
) -> ChainSpec:
    """Care manipulator of §9-3, Table 9.5, on the assumed layout of the 6R arm of Fig. 6-3.

    Parameters
    ----------
    s0, h2, s3, P : float
        Base (shoulder height), upper arm, forearm and finger-palm lengths, m (Table 9.5:
        115, 295, 280, 186 mm).  The segment masses stay the printed ones whatever the lengths.

    Returns
    -------
    ChainSpec
        Six revolute joints (waist, shoulder, elbow, three wrist axes), ±180° each (assumed);
        tool frame ``grip`` at the grip point, axes of H-D frame 6.  See the module docstring
        for what is printed and what is assumed (the layout: Fig. 9-28 is lost).
    """
    _lengths("care_robot", s0=s0, h2=h2, s3=s3, P=P)
    rows = sixr_arm(s0=s0, h2=h2, s3=s3, P=P).dh  # the one H-D table of Fig. 6-3
    spec = from_dh(
        "care_robot",
        "Bedridden-patient care manipulator (book §9-3, Table 9.5) on the assumed 6R layout of "
        "Fig. 6-3 (Fig. 9-28 is lost); tool = grip point.",
        rows,
        homogeneous(r=[0, 0, P]),
        source="book 000 l.7556-7617 (Table 9.5: lengths 115/295/280/186 mm, printed total 856 but "
        "the parts sum to 876; masses 2.38/1.82/1.16/0.57 kg = 5.93); joint layout assumed "
        "(6R of Fig. 6-3), ranges assumed +-180 deg",
        joint_names=["waist", "shoulder", "elbow", "wrist_roll", "wrist_pitch", "wrist_yaw"],
        params={"s0": s0, "h2": h2, "s3": s3, "P": P},
        tool_name="grip",
        inertia_source=(
            "Table 9.5 segment masses (base 2.38, upper arm 1.82, forearm 1.16, finger-palm "
            "0.57 kg) as uniform cylinders of radius 25 mm; elbow and wrist housings "
            f"{HOUSING_MASS} kg each taken from the forearm and finger-palm (assumed)"
        ),
    )
    m = {k: v[1] for k, v in TABLE_9_5.items()}
    masses = [
        m["base"],
        m["upper_arm"],
        HOUSING_MASS,
        m["forearm"] - HOUSING_MASS,
        HOUSING_MASS,
        m["finger_palm"] - HOUSING_MASS,
    ]
    for j, mass in zip(spec.joints, masses):
        j.link = rod_link(j.link.name, j.link.segment, mass=mass, joint_mass=0.0)
        # coreless DC motors through a worm reduction: slow joints (rad/s) -- an assumption
        j.velocity = 1.0
    # the §9-3 table of wrist-centre positions: the point (0, 0, -P) of the grip frame
    spec.cells = CellRecipe(
        rotation=R_FORWARD,
        bounds=CELL_BOUNDS,
        D=CELL_D,
        branch=CELL_BRANCH,
        point=(0.0, 0.0, -float(P)),
        encoder_counts=ENCODER_COUNTS,
        gear_ratio=GEAR_RATIO,
    )
    return spec


__all__ = [
    "care_robot",
    "pulses_per_rad",
    "ENCODER_COUNTS",
    "GEAR_RATIO",
    "R_FORWARD",
    "CELL_BOUNDS",
    "CELL_BRANCH",
    "TABLE_9_5",
    "CELL_D",
    "CELL_ACCURACY",
    "HOUSING_MASS",
    "DOF_PRINTED",
    "MOTORS_PRINTED",
    "table_9_5_length_sum_mm",
    "table_9_5_mass_sum_kg",
]
