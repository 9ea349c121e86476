"""Hand anthropometry and the five digit chains of the human upper-limb model (Fig. 2-2).

The book's upper-limb graph (Fig. 2-2, l. 540–552; ``ch1-2.md`` §2.2) gives every finger a
two-axis base pair (MCP for fingers 2–5, CMC for the thumb) and two hinges: 4 DOF per digit,
F = 20 for the hand (Eq. (2-1) on the finger
graph, :func:`anthroarm.design.structure.human_fingers`). The book prints no finger dimensions and
no finger ranges; they come from the literature:

**Segment lengths** — Buchholz, Armstrong & Goldstein (1992), "Anthropometric data for
describing the kinematics of the human hand", *Ergonomics* 35(3):261–273: kinematic segment
length = coefficient × hand length HL (distal wrist crease to the tip of the middle finger):

======== ======================== ========= ========= =========
digit    segment 1                segment 2 segment 3 segment 4
======== ======================== ========= ========= =========
thumb    0.118 (wrist → CMC)      0.251     0.196     0.158
index    0.463 (wrist → MCP)      0.245     0.143     0.097
middle   0.446 (wrist → MCP)      0.266     0.170     0.108
ring     0.421 (wrist → MCP)      0.244     0.165     0.107
little   0.414 (wrist → MCP)      0.204     0.117     0.093
======== ======================== ========= ========= =========

For the thumb, segments 2–4 are the metacarpal, the proximal and the distal phalanx; for
fingers 2–5 the proximal, middle and distal phalanx.  The last segment ends at the fingertip.

**Hand length and breadth** from the body: by default HL makes the middle-finger MCP coincide
with the end of de Leva's (1996) hand segment (wrist joint centre → 3rd metacarpale, scaled
by stature, :func:`anthroarm.models.human.segment_parameters`): HL = l_hand / 0.446, i.e.
0.111 × stature for men and 0.101 × stature for women (Drillis & Contini's classic 0.108 ×
stature lies between).  The hand breadth (across the metacarpal heads) defaults to
0.45 × HL, a round adult ratio (e.g. Pheasant & Haslegrave, *Bodyspace*, 3rd ed. 2006: about
87/189 mm for men and 76/174 mm for women).  Either can be given instead.

**Our modelling choices** (no table prints them): the wrist joint centre is taken at the
distal wrist crease; the MCP joints of fingers 2–5 lie on a line across the palm, HB/4 apart,
the middle finger on the hand's long axis (index radial of it); the thumb CMC sits 0.118 HL
distal of the wrist, 0.22 HB radial and 0.12 HB palmar of the axis, and the thumb's rest
direction points distally, radially and palmar (:data:`THUMB_REST_DIRECTION`).  Each
phalanx is a solid cylinder of radius HB/8 (finger breadth HB/4; thumb 1.15×; middle
phalanges 0.925×, distal 0.85×) and density 1160 kg/m³ (hand density of Dempster (1955), as
tabulated by Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed. 2009,
Table 4.1); the palm carries the rest of de Leva's hand mass as a box HB wide, l_hand long
and 0.3 HB thick.

**Ranges of motion** (degrees, positive = flexion; the book's Table 2.2 has no finger rows):
AAOS (Greene & Heckman, *The Clinical Measurement of Joint Motion*, 1994) — finger MCP
−45…90, PIP 0…100, DIP −10…90; thumb CMC flexion −20…15 and abduction 0…70 (from the rest
direction), thumb MCP 0…50, IP −20…80.  AAOS lists no finger abduction: MCP abduction is
±20°, a round value of our choosing.

**DIP–PIP coupling** (optional mimic): θ_DIP = (2/3) θ_PIP, the ratio of Rijpkema & Girard
(1991), "Computer animation of knowledge-based human grasping", *SIGGRAPH '91*, 339–348.

Frames and signs (the hand hangs like the §6-3 arm at q = 0, anatomical position): the hand
link's origin is the wrist joint centre; −z points to the fingers, +y out of the palm, +x to
the radial (thumb) side of this right hand.  Each digit's base frame has the same convention
(local −z along the digit, +y its palmar side): ``{digit}_mcp_abduction`` (thumb:
``thumb_cmc_abduction``) turns about local y, positive toward the thumb for fingers 2–5 and
palmar for the thumb; ``{digit}_mcp_flexion`` / ``thumb_cmc_flexion``, ``{digit}_pip``,
``{digit}_dip``, ``thumb_mcp``, ``thumb_ip`` turn about local x, positive = flexion.
Units: m, kg, rad.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from numbers import Real
from pathlib import Path

import numpy as np

from ..errors import AnthropometryError, CouplingError, ParameterError
from ..spatial.rotations import homogeneous
from .spec import JointSpec, LinkSpec, Shape, capsule

deg = np.pi / 180.0

DIGITS = ("thumb", "index", "middle", "ring", "little")
FINGERS = DIGITS[1:]
#: order of the digits in q: Pinocchio's URDF reader visits the joints hanging on one link in
#: the order of their names, so the spec lists them that way and spec order = q order
Q_ORDER = tuple(sorted(DIGITS))

#: segment length / hand length, per digit, of Buchholz, Armstrong & Goldstein 1992 (the module
#: table)
BUCHHOLZ_1992 = {
    "thumb": (0.118, 0.251, 0.196, 0.158),
    "index": (0.463, 0.245, 0.143, 0.097),
    "middle": (0.446, 0.266, 0.170, 0.108),
    "ring": (0.421, 0.244, 0.165, 0.107),
    "little": (0.414, 0.204, 0.117, 0.093),
}

#: default hand breadth / hand length (adult, round value; see the module docstring)
BREADTH_RATIO = 0.45
#: density of the hand (kg/m³), Dempster (1955) via Winter (2009) Table 4.1
HAND_DENSITY = 1160.0
#: mass (kg) of the massless-in-reality link between the two axes of a base pair
VIRTUAL_MASS = 0.0005

#: joint ranges (degrees) per joint kind: AAOS (Greene & Heckman 1994); abduction ±20 ours
FINGER_ROM_DEG = {
    "mcp_abduction": (-20.0, 20.0),
    "mcp_flexion": (-45.0, 90.0),
    "pip": (0.0, 100.0),
    "dip": (-10.0, 90.0),
}
THUMB_ROM_DEG = {
    "cmc_abduction": (0.0, 70.0),
    "cmc_flexion": (-20.0, 15.0),
    "mcp": (0.0, 50.0),
    "ip": (-20.0, 80.0),
}

#: θ_DIP / θ_PIP of the physiological coupling, 2/3 after Rijpkema & Girard 1991
DIP_PIP_RATIO = 2.0 / 3.0

#: rest direction of the thumb metacarpal in the hand frame (distal, radial, palmar; unit)
THUMB_REST_DIRECTION = np.array([0.45, 0.35, -1.0]) / np.linalg.norm([0.45, 0.35, -1.0])
#: the linkage hand's tree and mimic fit at scale 1 (the catalog model ``prosthetic_hand`` is
#: made from it): written by :func:`anthroarm.mechanisms.linkage_hand.write_tree_table`
LINKAGE_HAND_TABLE = Path(__file__).resolve().parents[1] / "data" / "models" / "linkage_hand.json"


def check_hand_scale(scale, who: str) -> float:
    """``scale`` as a float: a number in 0.3…3 (a hand scaled as a whole), else
    :class:`~anthroarm.errors.ParameterError` naming ``who``."""
    if (
        isinstance(scale, bool)
        or not isinstance(scale, (int, float, np.floating, np.integer))
        or not np.isfinite(scale)
        or not (0.3 <= scale <= 3.0)
    ):
        raise ParameterError(f"{who}: scale must be a number in 0.3…3, got {scale!r}")
    return float(scale)


#: turn of the thumb's flexion axes about its rest direction (rad, our choice): flexion goes
#: ulnar and palmar
THUMB_PRONATION = 30.0 * np.pi / 180.0

#: plausible bounds: hand length / stature, hand breadth / hand length
HL_PER_STATURE = (0.085, 0.14)
HB_PER_HL = (0.30, 0.65)

#: comfortable (relaxed) hand posture, degrees: a lightly curled hand
RELAXED_DEG = {
    "mcp_abduction": 0.0,
    "mcp_flexion": 20.0,
    "pip": 30.0,
    "dip": 20.0,
    "cmc_abduction": 20.0,
    "cmc_flexion": 0.0,
    "mcp": 10.0,
    "ip": 10.0,
}


def joint_names(digit: str) -> tuple[str, str, str, str]:
    """The four joint names of a digit, base to tip (base abduction, base flexion, two hinges)."""
    if digit == "thumb":
        return ("thumb_cmc_abduction", "thumb_cmc_flexion", "thumb_mcp", "thumb_ip")
    if digit not in FINGERS:
        raise ParameterError(f"unknown digit {digit!r}; digits: {', '.join(DIGITS)}")
    return (f"{digit}_mcp_abduction", f"{digit}_mcp_flexion", f"{digit}_pip", f"{digit}_dip")


def _number(name, v):
    if isinstance(v, bool) or not isinstance(v, Real) or not np.isfinite(float(v)):
        raise AnthropometryError(f"{name} must be a finite number (m), got {v!r}", name, v)
    return float(v)


def parse_coupling(dip_coupling) -> float | None:
    """The DIP–PIP mimic ratio of ``dip_coupling``: ``None``/``"none"`` (independent DIP), a
    number in (0, 1.5], or a fraction string such as ``"2/3"`` (``"2/3"`` is
    :data:`DIP_PIP_RATIO`, Rijpkema & Girard 1991).  Anything else raises
    :class:`~anthroarm.errors.ParameterError`."""
    if dip_coupling is None:
        return None
    if isinstance(dip_coupling, str):
        t = dip_coupling.strip().lower()
        if t in ("none", "off", ""):
            return None
        try:
            r = float(Fraction(t))
        except (ValueError, ZeroDivisionError):
            raise ParameterError(
                "dip_coupling must be 'none', a ratio such as '2/3' or a number, got "
                f"{dip_coupling!r}"
            ) from None
    elif isinstance(dip_coupling, Real) and not isinstance(dip_coupling, bool):
        r = float(dip_coupling)
    else:
        raise ParameterError(
            f"dip_coupling must be None, 'none', '2/3' or a number, got {dip_coupling!r}"
        )
    if not (np.isfinite(r) and 0.0 < r <= 1.5):
        raise ParameterError(f"dip_coupling ratio must lie in (0, 1.5] (DIP/PIP), got {r}")
    return r


def hand_dimensions(
    hand_length: float,
    hand_breadth: float,
    forearm_length: float | None = None,
    stature: float | None = None,
) -> dict:
    """Validated hand length and breadth (m) and the Buchholz (1992) segment lengths (m).

    Raises :class:`~anthroarm.errors.AnthropometryError` for a non-finite or non-positive value,
    a hand longer than the forearm, a hand length outside 0.085…0.14 × stature, or a breadth
    outside 0.30…0.65 × hand length.  Returns ``{"hand_length", "hand_breadth", "segments":
    {digit: (s1, s2, s3, s4)}}``."""
    HL = _number("hand_length", hand_length)
    HB = _number("hand_breadth", hand_breadth)
    if HL <= 0:
        raise AnthropometryError(f"hand_length must be positive (m), got {HL}", "hand_length", HL)
    if HB <= 0:
        raise AnthropometryError(f"hand_breadth must be positive (m), got {HB}", "hand_breadth", HB)
    if forearm_length is not None and HL >= forearm_length:
        raise AnthropometryError(
            f"hand_length {HL:.4g} m is not shorter than the forearm ({forearm_length:.4g} m): "
            "outside human proportions (a hand is about 0.7 forearm lengths)",
            "hand_length",
            HL,
        )
    if stature is not None and not (
        HL_PER_STATURE[0] * stature <= HL <= HL_PER_STATURE[1] * stature
    ):
        raise AnthropometryError(
            f"hand_length {HL:.4g} m is {HL / stature:.3g} × the stature {stature} m; human hands "
            f"lie within {HL_PER_STATURE[0]}…{HL_PER_STATURE[1]} × stature",
            "hand_length",
            HL,
        )
    if not (HB_PER_HL[0] * HL <= HB <= HB_PER_HL[1] * HL):
        raise AnthropometryError(
            f"hand_breadth {HB:.4g} m is {HB / HL:.3g} × the hand length; human hands lie within "
            f"{HB_PER_HL[0]}…{HB_PER_HL[1]} × hand length",
            "hand_breadth",
            HB,
        )
    return {
        "hand_length": HL,
        "hand_breadth": HB,
        "segments": {d: tuple(c * HL for c in BUCHHOLZ_1992[d]) for d in DIGITS},
    }


def _thumb_rotation() -> np.ndarray:
    """Base frame of the thumb in the hand frame (columns x, y, z): local −z along
    :data:`THUMB_REST_DIRECTION`; the flexion axis x starts as the palm normal (+y of the hand,
    made perpendicular to the digit), so that flexion sweeps the thumb ulnarly across the palm,
    and is then turned by :data:`THUMB_PRONATION` about the digit so that flexion also moves it
    palmar (toward the fingers' pads), as the pronated thumb does in opposition."""
    d = THUMB_REST_DIRECTION
    z = -d
    x = np.array([0.0, 1.0, 0.0]) - z * z[1]
    x /= np.linalg.norm(x)
    y = np.cross(z, x)  # the flexion direction: ulnar (-x of the hand)
    c, s = np.cos(THUMB_PRONATION), np.sin(THUMB_PRONATION)
    x, y = c * x - s * y, s * x + c * y  # turn about z: flexion now also goes palmar (+y)
    return np.column_stack([x, y, z])


def _phalanx_link(name, length, radius, rgba=(0.93, 0.78, 0.68, 1.0)) -> LinkSpec:
    """A phalanx along local −z: a solid cylinder of ``HAND_DENSITY`` (mass, com, inertia about
    the com) drawn as a capsule."""
    m = HAND_DENSITY * np.pi * radius**2 * length
    i_perp = m * (3 * radius**2 + length**2) / 12.0
    i_ax = m * radius**2 / 2.0
    I = np.diag([i_perp, i_perp, i_ax])
    seg = np.array([0.0, 0.0, -length])
    return LinkSpec(
        name=name,
        mass=m,
        com=seg / 2,
        inertia=I,
        segment=seg,
        radius=radius,
        shapes=capsule(np.zeros(3), seg, radius, material="skin", rgba=rgba),
    )


def _virtual_link(name, radius) -> LinkSpec:
    I = 0.4 * VIRTUAL_MASS * radius**2 * np.eye(3)
    return LinkSpec(name=name, mass=VIRTUAL_MASS, inertia=I, radius=radius, shapes=())


def digit_bases(dims: dict, l_hand: float) -> dict:
    """4×4 pose of each digit's base frame (MCP / thumb CMC) in the hand frame (m): see the
    module docstring for the layout."""
    HB = dims["hand_breadth"]
    seg = dims["segments"]
    z_shift = (
        l_hand - seg["middle"][0]
    )  # wrist joint centre -> crease offset that puts MCP III at l_hand
    x_of = {"index": HB / 4, "middle": 0.0, "ring": -HB / 4, "little": -HB / 2}
    out = {f: homogeneous(r=[x_of[f], 0.0, -(seg[f][0] + z_shift)]) for f in FINGERS}
    out["thumb"] = homogeneous(
        _thumb_rotation(), [0.22 * HB, 0.12 * HB, -(seg["thumb"][0] + z_shift)]
    )
    return out


def hand_chain(dims: dict, l_hand: float, parent: str = "hand", dip_coupling: float | None = None):
    """Joints (tree, each with its parent link), tip frames and relaxed posture of the 5 digits.

    Returns ``(joints, frames, comfort, masses)``: :class:`JointSpec` s (4 per digit, digits in
    :data:`Q_ORDER`), ``(name, parent_link, 4×4)`` fingertip frames ``{digit}_tip``, a dict joint ->
    rad (:data:`RELAXED_DEG`), and the total phalanx + virtual mass (kg)."""
    bases = digit_bases(dims, l_hand)
    r_f = dims["hand_breadth"] / 8
    joints, frames, comfort, mass = [], [], {}, 0.0
    for d in Q_ORDER:
        names = joint_names(d)
        lengths = dims["segments"][d][1:]
        radius = (1.15 if d == "thumb" else 1.0) * r_f
        radii = (radius, radius * 0.925, radius * 0.85)
        rom = THUMB_ROM_DEG if d == "thumb" else FINGER_ROM_DEG
        kinds = tuple(n[len(d) + 1 :] for n in names)
        links = [
            _virtual_link(f"{d}_base_link", radii[0]),
            _phalanx_link(
                f"{d}_{'metacarpal' if d == 'thumb' else 'proximal'}", lengths[0], radii[0]
            ),
            _phalanx_link(f"{d}_{'proximal' if d == 'thumb' else 'middle'}", lengths[1], radii[1]),
            _phalanx_link(f"{d}_distal", lengths[2], radii[2]),
        ]
        origins = [
            bases[d],
            homogeneous(),
            homogeneous(r=[0, 0, -lengths[0]]),
            homogeneous(r=[0, 0, -lengths[1]]),
        ]
        # base abduction about -y: toward +x (the thumb side) for fingers 2-5, palmar for the thumb
        axes = [(0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.0, 0.0)]
        for k, (n, kind) in enumerate(zip(names, kinds)):
            lo, hi = rom[kind]
            mimic = None
            if k == 3 and d != "thumb" and dip_coupling is not None:
                mimic = (names[2], float(dip_coupling), 0.0)
            joints.append(
                JointSpec(
                    n,
                    "revolute",
                    origins[k],
                    axis=axes[k],
                    lower=lo * deg,
                    upper=hi * deg,
                    effort=2.0,
                    velocity=5.0,
                    link=links[k],
                    parent=parent if k == 0 else links[k - 1].name,
                    mimic=mimic,
                )
            )
            comfort[n] = RELAXED_DEG[kind] * deg
            mass += links[k].mass
        frames.append((f"{d}_tip", links[3].name, homogeneous(r=[0, 0, -lengths[2]])))
    return joints, frames, comfort, mass


def palm_link(dims: dict, l_hand: float, mass: float, name: str = "hand") -> LinkSpec:
    """The palm (carpus + metacarpals) as a box HB wide (x), ``l_hand`` long (z) and 0.3 HB thick
    (y), centred on the hand axis at −l_hand/2 (to be drawn from the wrist to the MCP row),
    carrying ``mass`` kg; inertia of the solid box about its centre."""
    HB = dims["hand_breadth"]
    if not mass > 0:
        raise AnthropometryError(
            f"the fingers ({-mass:.3g} kg more than the hand) leave no mass for the palm: "
            "the hand is too long or broad for the body mass",
            "hand_length",
            dims["hand_length"],
        )
    a, b, c = HB, 0.3 * HB, l_hand
    I = mass / 12.0 * np.diag([b**2 + c**2, a**2 + c**2, a**2 + b**2])
    centre = np.array([-HB / 8, 0.0, -l_hand / 2])  # the MCP row spans x in [-HB/2, HB/4]
    box = Shape(
        "box", (a, b, c), homogeneous(r=centre), material="skin", rgba=(0.93, 0.78, 0.68, 1.0)
    )
    wrist = Shape(
        "sphere", (0.3 * HB,), homogeneous(), material="joint", rgba=(0.85, 0.45, 0.2, 1.0)
    )
    return LinkSpec(
        name=name,
        mass=mass,
        com=centre,
        inertia=I,
        segment=np.array([0.0, 0.0, -l_hand]),
        radius=0.3 * HB,
        shapes=(wrist, box),
    )


def configuration(spec, angles: dict, *, tol: float = 1e-9) -> np.ndarray:
    """Configuration vector q (rad, the spec's variables in joint order, mimic joints left out)
    from named joint angles; joints not named take 0 (their mimic value for a mimic joint).

    A mimic joint may be named only with the value its coupling gives (within ``tol`` rad):
    anything else raises :class:`~anthroarm.errors.CouplingError` (with attributes ``joint``,
    ``expected`` and ``given``, rad); an unknown name or a
    non-finite value raises :class:`~anthroarm.errors.ParameterError`.  The q order is the
    order of ``spec.joints`` without the mimic joints, which is Pinocchio's for these trees."""
    if not isinstance(angles, Mapping):
        raise ParameterError(
            f"{spec.name}: angles must be a dict joint name -> rad, got {type(angles).__name__}"
        )
    by_name = {j.name: j for j in spec.joints}
    unknown = [n for n in angles if n not in by_name]
    if unknown:
        raise ParameterError(
            f"{spec.name}: unknown joint(s) {unknown}; joints: {', '.join(by_name)}"
        )
    vals = {}
    for n, v in angles.items():
        if isinstance(v, bool) or not isinstance(v, Real) or not np.isfinite(float(v)):
            raise ParameterError(f"{spec.name}: joint {n} needs a finite angle (rad), got {v!r}")
        vals[n] = float(v)
    q = []
    for j in spec.joints:
        if j.mimic is None:
            q.append(vals.get(j.name, 0.0))
    for j in spec.joints:
        if j.mimic is not None and j.name in vals:
            src, mult, off = j.mimic
            expected = mult * vals.get(src, 0.0) + off
            if abs(vals[j.name] - expected) > tol:
                err = CouplingError(
                    f"{spec.name}: {j.name} = {vals[j.name]:.6g} rad contradicts its coupling "
                    f"{j.name} = {mult:.6g} × {src} + {off:.6g} = {expected:.6g} rad; give {src} "
                    "only"
                )
                err.joint, err.expected, err.given = j.name, expected, vals[j.name]
                raise err
    return np.array(q)
