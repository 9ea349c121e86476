"""The human upper limb of book Fig. 2-2 as a 27-DOF tree: the §6-3 arm plus a five-digit hand.

The arm is :func:`anthroarm.models.human.human_arm7` unchanged (7 joints, de Leva (1996)
segments, Table 2.2 ranges, hanging along −z; y forward, x to the person's right).  On its
``hand`` link (the palm) hang five digits of 4 joints each (:mod:`anthroarm.models.hand`:
Buchholz et al. (1992) segment lengths, AAOS ranges, phalanx masses): 7 + 20 = 27 joints,
the book's F = 27 of which 20 are the fingers' (``ch1-2.md`` §2.2; Eq. (2-1) on the graph
from :func:`anthroarm.design.structure.mechanism_of`).

With ``dip_coupling="2/3"`` the four DIP joints mimic their PIP (Rijpkema & Girard 1991):
the graph still has F = 27 pairs' freedoms, the couplings remove 4, so nq = 23.

Frames (stable names; all in the URDF):

* ``hand_point`` — the **default tool**: H of §6-3, the end of de Leva's hand segment (the
  3rd metacarpale = the middle-finger MCP), the same frame and place as ``human_arm7``'s tool
  at the default parameters, so arm-only code works unchanged;
* ``palm`` — the palm centre, half-way from the wrist joint centre to ``hand_point``, same
  orientation as the hand link;
* ``thumb_tip``, ``index_tip``, ``middle_tip``, ``ring_tip``, ``little_tip`` — the fingertips
  (ends of the distal phalanges), oriented like the distal phalanx (−z along it, +y palmar).

Load a fingertip as the tool with ``aa.load("human_upper_limb", tool="index_tip")``.
"""

from __future__ import annotations

from ..spatial.rotations import homogeneous
from .hand import (
    BREADTH_RATIO,
    BUCHHOLZ_1992,
    _number,
    hand_chain,
    hand_dimensions,
    palm_link,
    parse_coupling,
)
from .human import human_arm7, segment_parameters
from .spec import ChainSpec

#: the frames a user can rely on (see the module docstring)
FRAMES = ("hand_point", "palm", "thumb_tip", "index_tip", "middle_tip", "ring_tip", "little_tip")


def human_upper_limb(
    height: float = 1.75,
    mass: float = 75.0,
    sex: str = "male",
    hand_length: float | None = None,
    hand_breadth: float | None = None,
    dip_coupling: str = "none",
) -> ChainSpec:
    """The Fig. 2-2 upper limb (27 joints; right arm and hand) of a person of ``height`` m and
    ``mass`` kg.

    Parameters
    ----------
    height, mass, sex
        Body stature (m), mass (kg) and ``"male"``/``"female"``: de Leva (1996) arm segments.
    hand_length, hand_breadth
        Hand length (distal wrist crease to middle fingertip, m) and breadth (across the
        metacarpal heads, m); default: from the stature (see :mod:`anthroarm.models.hand`).
        A hand longer than the forearm, a breadth <= 0 or out of human proportions raises
        :class:`~anthroarm.errors.AnthropometryError`.
    dip_coupling
        ``"none"`` (20 independent finger joints) or the DIP/PIP ratio of a mimic coupling of
        fingers 2–5, e.g. ``"2/3"`` (Rijpkema & Girard 1991) or a number.

    Returns
    -------
    ChainSpec
        Joints in Pinocchio's q order (arm, then index, little, middle, ring, thumb — the
        order of the joint names, :data:`anthroarm.models.hand.Q_ORDER`; base abduction,
        base flexion, two hinges each), tool ``hand_point``, frames :data:`FRAMES`.
    """
    ratio = parse_coupling(dip_coupling)
    arm = human_arm7(height, mass, sex)
    seg = segment_parameters(height, mass, sex)
    l_forearm = seg["forearm"]["length"]
    l_hand_deleva = seg["hand"]["length"]
    HL = l_hand_deleva / BUCHHOLZ_1992["middle"][0] if hand_length is None else hand_length
    HL = _number("hand_length", HL)
    HB = BREADTH_RATIO * HL if hand_breadth is None else hand_breadth
    dims = hand_dimensions(HL, HB, forearm_length=l_forearm, stature=float(height))
    l_hand = (
        BUCHHOLZ_1992["middle"][0] * dims["hand_length"]
    )  # wrist -> MCP III; = de Leva's at the default
    joints, frames, comfort, finger_mass = hand_chain(
        dims, l_hand, parent="hand", dip_coupling=ratio
    )
    arm_joints = list(arm.joints)
    wrist = arm_joints[-1]
    palm = palm_link(dims, l_hand, seg["hand"]["mass"] - finger_mass, name="hand")
    arm_joints[-1] = type(wrist)(
        wrist.name,
        wrist.type,
        wrist.origin,
        axis=wrist.axis,
        lower=wrist.lower,
        upper=wrist.upper,
        effort=wrist.effort,
        velocity=wrist.velocity,
        link=palm,
    )
    frames = [("palm", "hand", homogeneous(r=[0.0, 0.0, -l_hand / 2]))] + frames
    params = {
        "height": height,
        "mass": mass,
        "sex": sex,
        "hand_length": dims["hand_length"],
        "hand_breadth": dims["hand_breadth"],
        "dip_coupling": "none" if ratio is None else ratio,
        **{k: arm.params[k] for k in ("l1", "l2")},
        "l3": l_hand,
    }
    return ChainSpec(
        name="human_upper_limb",
        description=(
            "Human upper limb of book Fig. 2-2 (F = 27): the 7-DOF §6-3 right arm (shoulder "
            "x-y-z, elbow x, wrist z-y-x, hanging along -z; y forward, x to the right) and a "
            "five-digit hand with 4 joints per digit (20 finger DOF); tool = hand point H; "
            "fingertip frames thumb_tip ... little_tip."
        ),
        joints=arm_joints + joints,
        tool_name="hand_point",
        tool_origin=homogeneous(r=[0.0, 0.0, -l_hand]),
        tool_parent="hand",
        frames=tuple(frames),
        source=(
            "book 000 l.540-552 (Fig. 2-2, F = 27, fingers 20), l.3927-3989 (§6-3 arm); limits "
            "Table 2.2 l.527-534 (arm), AAOS 1994 (fingers); finger lengths Buchholz, Armstrong & "
            "Goldstein 1992"
        ),
        inertia_source=(
            f"arm: de Leva (1996) Table 4, {sex}, height {height} m, mass {mass} kg; phalanges: "
            "solid cylinders of 1160 kg/m3 (Dempster 1955); palm: de Leva hand mass minus the "
            "phalanges, as a box"
        ),
        params=params,
        person=True,
        comfort={**(arm.comfort or {}), **comfort},
    )
