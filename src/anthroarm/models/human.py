"""The 7-DOF human-like arm of §6-3 (Fig. 6-5/6-6) with anthropometric segments.

Kinematics (book §6-3, l. 3927–3989): shoulder S at the origin, joints about x, y, z at S;
elbow about x at E = (0, 0, −l1); wrist about z, y, x at W = E + (0, 0, −l2); hand point H at
W + (0, 0, −l3).  At q = 0 the arm hangs along −z; z is up, y points forward (anterior) and x
to the person's right (lateral for a right arm).  Orientations are Eq. (6-34)–(6-36):
C_E = Cx1 Cy2, C_W = C_E Cz3 Cx4, C_H = C_W Cz5 Cy6 Cx7.

Segment lengths, masses, centres of mass and radii of gyration come from de Leva (1996),
"Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters", J. Biomech. 29(9),
Table 4, scaled by body height (lengths, linearly) and body mass (masses, linearly):

======== ====== ======= ======= ====== =========================================
segment  sex    length  mass %  CoM %  radii of gyration % (sag, trans, long)
======== ====== ======= ======= ====== =========================================
upperarm male   281.7   2.71    57.72  28.5, 26.9, 15.8
forearm  male   268.9   1.62    45.74  27.6, 26.5, 12.1
hand     male   86.2    0.61    79.00  62.8, 51.3, 40.1
upperarm female 275.1   2.55    57.54  27.8, 26.0, 14.8
forearm  female 264.3   1.38    45.59  26.1, 25.7, 9.4
hand     female 78.0    0.56    74.74  53.1, 45.4, 33.5
======== ====== ======= ======= ====== =========================================

Lengths in mm for the reference statures 1741 mm (male) and 1735 mm (female); the hand segment
runs from the wrist joint centre to the 3rd metacarpale, and H is placed at its end.

Joint ranges (degrees), from the book's Table 2.2 (l. 527–534) where it has a row:

================== ==== ========= ==================================================
joint              axis range     source
================== ==== ========= ==================================================
shoulder_flexion   x    −50 … 180 Table 2.2 θ2 (+180, −(40…60): mid value −50)
shoulder_abduction y    −180 … 30 not in Table 2.2: AAOS abduction 180, adduction 30
shoulder_rotation  z    −90 … 90  Table 2.2 θ3 (upper-arm rotation ±90)
elbow_flexion      x    −5 … 145  Table 2.2 θ4
forearm_pronation  z    −90 … 90  Table 2.2 θ5
wrist_deviation    y    −30 … 20  not in Table 2.2 (book notes: missing row); AAOS
wrist_flexion      x    −70 … 55  Table 2.2 θ6 (+(50…60): mid value 55, −70)
================== ==== ========= ==================================================

For a right arm, abduction (hand moving to +x) is a negative rotation about +y; flexion moves
the hand forward (+y).  Table 2.2's θ1 (internal/external rotation +45/−90) overlaps its θ3;
we read θ3 as the humeral rotation and do not use θ1.
"""

from __future__ import annotations

import numpy as np

from ..errors import AnthropometryError, ParameterError
from ..spatial.rotations import homogeneous
from .spec import ChainSpec, JointSpec, PrintedForm, as_batch, finite_params, rod_link

deg = np.pi / 180.0

DE_LEVA_1996 = {
    # name: (length mm, mass fraction, com fraction from proximal, (r_sag, r_trans, r_long)
    # fractions)
    "male": {
        "stature": 1741.0,
        "upperarm": (281.7, 0.0271, 0.5772, (0.285, 0.269, 0.158)),
        "forearm": (268.9, 0.0162, 0.4574, (0.276, 0.265, 0.121)),
        "hand": (86.2, 0.0061, 0.7900, (0.628, 0.513, 0.401)),
    },
    "female": {
        "stature": 1735.0,
        "upperarm": (275.1, 0.0255, 0.5754, (0.278, 0.260, 0.148)),
        "forearm": (264.3, 0.0138, 0.4559, (0.261, 0.257, 0.094)),
        "hand": (78.0, 0.0056, 0.7474, (0.531, 0.454, 0.335)),
    },
}

HUMAN_ARM7_LIMITS_DEG = {
    "shoulder_flexion": (-50.0, 180.0),
    "shoulder_abduction": (-180.0, 30.0),
    "shoulder_rotation": (-90.0, 90.0),
    "elbow_flexion": (-5.0, 145.0),
    "forearm_pronation": (-90.0, 90.0),
    "wrist_deviation": (-30.0, 20.0),
    "wrist_flexion": (-70.0, 55.0),
}


def segment_parameters(height: float = 1.75, mass: float = 75.0, sex: str = "male") -> dict:
    """Length (m), mass (kg), CoM distance from the proximal joint (m) and radii of gyration
    (m; sagittal, transverse, longitudinal) of upper arm, forearm and hand (de Leva 1996)."""
    if not isinstance(sex, str) or sex not in DE_LEVA_1996:
        raise ParameterError(f"sex must be 'male' or 'female' (de Leva 1996 tables), got {sex!r}")
    _NUM = (int, float, np.floating, np.integer)
    for pname, v, unit in (("height", height, "m"), ("mass", mass, "kg")):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, _NUM):
            raise AnthropometryError(
                f"body height and mass must be numbers (m, kg): {pname} got "
                f"{type(v).__name__} {v!r}",
                pname,
                v,
            )
    if not (0.5 <= height <= 2.6):  # also False for NaN
        raise AnthropometryError(
            f"body height {height} m is outside 0.5…2.6 m (height= in m, e.g. 1.75)",
            "height",
            height,
        )
    if not (10.0 <= mass <= 300.0):
        raise AnthropometryError(
            f"body mass {mass} kg is outside 10…300 kg (mass= in kg, e.g. 75)", "mass", mass
        )
    tab = DE_LEVA_1996[sex]
    k = height * 1000.0 / tab["stature"]
    out = {}
    for seg in ("upperarm", "forearm", "hand"):
        L_mm, mf, cf, radii = tab[seg]
        L = L_mm * k / 1000.0
        out[seg] = {
            "length": L,
            "mass": mf * mass,
            "com": cf * L,
            "radii": tuple(r * L for r in radii),
        }
    return out


#: Comfortable posture of the §6-3 arm (rad): upper arm 20° flexed and 15° abducted, humerus
#: unrotated, elbow flexed 80°, forearm mid-pronation, wrist straight — the centres of the
#: lowest-load ("score 1") bands of RULA (McAtamney & Corlett, Applied Ergonomics 24(2), 1993:
#: upper arm −20…20°, lower arm 60…100°, wrist 0°).
HUMAN_ARM7_COMFORT = {
    "shoulder_flexion": 20 * deg,
    "shoulder_abduction": -15 * deg,  # negative = abduction for this right arm
    "shoulder_rotation": 0.0,
    "elbow_flexion": 80 * deg,
    "forearm_pronation": 0.0,
    "wrist_deviation": 0.0,
    "wrist_flexion": 0.0,
}


#: Skin markers of the human arm model at the bony landmarks the ISB recommendation names (Wu et
#: al. 2005, "ISB recommendation on definitions of joint coordinate systems ... Part II: shoulder,
#: elbow, wrist and hand", J. Biomech. 38(5), 981-992): acromion AC, lateral/medial epicondyle
#: EL/EM, radial/ulnar styloid RS/US, heads of the 2nd, 3rd and 5th metacarpals MC2/MC3/MC5, plus
#: a technical marker on the lateral upper arm (UA) and one on the dorsal forearm (FA).
#: name -> (link, (x, y, z) as fractions of that link's segment length, weight, description), in
#: the links' frames of :func:`human_arm7` (x lateral, y anterior, z up; at q = 0 the arm hangs
#: along -z with the palm forward, so the styloids and metacarpal heads lie on +-x).  Markers on
#: ``base_link`` (the trunk) scale with :data:`HUMAN_ARM_TRUNK_SCALE_LINK`.  The fractions are
#: typical skin-surface offsets from the joint centres (epicondylar width ~70 mm, wrist width
#: ~57 mm, metacarpal breadth ~60 mm for a 1.75 m man: segment lengths 283, 270, 87 mm), not
#: measured on a person.  Read by :func:`anthroarm.motion.markers.default_marker_set`.
HUMAN_ARM_LANDMARKS = {
    "AC": (
        "base_link",
        (0.106, 0.0, 0.159),
        1.0,
        "acromion (on the trunk: fixed, used for scaling)",
    ),
    "UA": (
        "upper_arm",
        (0.160, 0.0, -0.50),
        1.0,
        "lateral upper arm, mid-shaft (technical marker)",
    ),
    "EL": ("upper_arm", (0.113, 0.0, -1.0), 1.0, "lateral epicondyle of the humerus"),
    "EM": ("upper_arm", (-0.134, 0.0, -1.0), 1.0, "medial epicondyle of the humerus"),
    "FA": ("forearm", (0.0, -0.130, -0.50), 1.0, "dorsal forearm, mid-shaft (technical marker)"),
    "RS": ("forearm", (0.111, 0.0, -1.0), 1.0, "radial styloid"),
    "US": ("forearm", (-0.100, 0.0, -1.0), 1.0, "ulnar styloid"),
    "MC2": ("hand", (0.280, -0.120, -0.97), 1.0, "head of the 2nd metacarpal (dorsal)"),
    "MC3": ("hand", (0.0, -0.120, -1.0), 1.0, "head of the 3rd metacarpal (dorsal)"),
    "MC5": ("hand", (-0.400, -0.120, -0.88), 1.0, "head of the 5th metacarpal (dorsal)"),
}

#: the link whose segment length scales the trunk (``base_link``) markers of
#: :data:`HUMAN_ARM_LANDMARKS`
HUMAN_ARM_TRUNK_SCALE_LINK = "upper_arm"


#: the segments of :data:`DE_LEVA_1996` and the links of :func:`human_arm7` that carry them
SEGMENT_LINKS = {"upperarm": "upper_arm", "forearm": "forearm", "hand": "hand"}


def _segment_lengths(segment_lengths) -> dict:
    """``segment_lengths`` keyed by the de Leva segment names (a link's name is accepted for its
    segment); bad keys or values raise :class:`~anthroarm.errors.ParameterError`."""
    if not isinstance(segment_lengths, dict):
        raise ParameterError(
            f"segment_lengths is a dict segment -> length (m) with keys {list(SEGMENT_LINKS)}, "
            f"got {segment_lengths!r}"
        )
    by_link = {link: key for key, link in SEGMENT_LINKS.items()}
    lengths = {}
    for name, L in segment_lengths.items():
        key = by_link.get(name, name)
        if key not in SEGMENT_LINKS:
            raise ParameterError(
                f"segment_lengths: unknown segment {name!r}; known: {list(SEGMENT_LINKS)} "
                f"(or the links {list(by_link)})"
            )
        if key in lengths:
            raise ParameterError(
                f"segment_lengths: {key!r} given twice (as {key!r} and {SEGMENT_LINKS[key]!r})"
            )
        if (
            isinstance(L, bool)
            or not isinstance(L, (int, float, np.floating, np.integer))
            or not (0.02 <= L <= 1.0)
        ):
            raise ParameterError(
                f"segment_lengths[{name!r}] must be a length in 0.02 ... 1.0 m, got {L!r}"
            )
        lengths[key] = float(L)
    return lengths


def _measured_lengths(seg: dict, lengths: dict) -> dict:
    """``seg`` with the lengths of ``lengths`` (:func:`_segment_lengths`, m; the centre of mass
    and the radii of gyration keep their de Leva fractions of the length, the masses stay)."""
    out = {k: dict(v) for k, v in seg.items()}
    for key, L in lengths.items():
        k = float(L) / out[key]["length"]
        out[key]["length"] = float(L)
        out[key]["com"] *= k
        out[key]["radii"] = tuple(r * k for r in out[key]["radii"])
    return out


def human_arm7(
    height: float = 1.75, mass: float = 75.0, sex: str = "male", segment_lengths: dict | None = None
) -> ChainSpec:
    """The §6-3 7-DOF arm (right arm) scaled to a person of ``height`` m and ``mass`` kg.

    ``segment_lengths`` (optional): measured lengths in m of ``"upperarm"`` (shoulder to elbow
    joint centre; also accepted as ``"upper_arm"``, the link's name), ``"forearm"`` (elbow to
    wrist) and ``"hand"`` (wrist to the 3rd metacarpale), any subset (on the command line:
    ``--segment-lengths upperarm=0.30,forearm=0.26``); they replace de Leva's height-scaled
    lengths (centres of mass and radii of gyration keep their fractions of the length, masses
    stay those of the body mass).  From a static marker trial:
    :func:`anthroarm.motion.scaling.scale_from_static`."""
    seg = segment_parameters(height, mass, sex)
    if segment_lengths is not None:
        segment_lengths = _segment_lengths(segment_lengths)
        seg = _measured_lengths(seg, segment_lengths)
    l1, l2, l3 = (seg[s]["length"] for s in ("upperarm", "forearm", "hand"))
    X, Y, Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
    lim = {k: (a * deg, b * deg) for k, (a, b) in HUMAN_ARM7_LIMITS_DEG.items()}
    tiny = 0.02  # kg: virtual links between co-located joints

    def virtual(name):
        return rod_link(name, [0, 0, 0], mass=0.0, joint_mass=tiny, radius=0.03)

    def anthropo(name, s, key, radius):
        p = seg[key]
        r_sag, r_trans, r_long = p["radii"]
        return rod_link(
            name,
            s,
            mass=p["mass"],
            radius=radius,
            joint_mass=0.0,
            com_fraction=p["com"] / p["length"],
            radii_of_gyration=(r_sag, r_trans, r_long),
        )

    joints = [
        JointSpec(
            "shoulder_flexion",
            "revolute",
            homogeneous(),
            axis=X,
            link=virtual("shoulder_link1"),
            lower=lim["shoulder_flexion"][0],
            upper=lim["shoulder_flexion"][1],
            effort=80.0,
        ),
        JointSpec(
            "shoulder_abduction",
            "revolute",
            homogeneous(),
            axis=Y,
            link=virtual("shoulder_link2"),
            lower=lim["shoulder_abduction"][0],
            upper=lim["shoulder_abduction"][1],
            effort=80.0,
        ),
        JointSpec(
            "shoulder_rotation",
            "revolute",
            homogeneous(),
            axis=Z,
            link=anthropo("upper_arm", [0, 0, -l1], "upperarm", 0.045),
            lower=lim["shoulder_rotation"][0],
            upper=lim["shoulder_rotation"][1],
            effort=40.0,
        ),
        JointSpec(
            "elbow_flexion",
            "revolute",
            homogeneous(r=[0, 0, -l1]),
            axis=X,
            link=rod_link("elbow_link", [0, 0, 0], mass=0.0, joint_mass=tiny, radius=0.04),
            lower=lim["elbow_flexion"][0],
            upper=lim["elbow_flexion"][1],
            effort=60.0,
        ),
        JointSpec(
            "forearm_pronation",
            "revolute",
            homogeneous(),
            axis=Z,
            link=anthropo("forearm", [0, 0, -l2], "forearm", 0.035),
            lower=lim["forearm_pronation"][0],
            upper=lim["forearm_pronation"][1],
            effort=10.0,
        ),
        JointSpec(
            "wrist_deviation",
            "revolute",
            homogeneous(r=[0, 0, -l2]),
            axis=Y,
            link=virtual("wrist_link"),
            lower=lim["wrist_deviation"][0],
            upper=lim["wrist_deviation"][1],
            effort=10.0,
        ),
        JointSpec(
            "wrist_flexion",
            "revolute",
            homogeneous(),
            axis=X,
            link=anthropo("hand", [0, 0, -l3], "hand", 0.03),
            lower=lim["wrist_flexion"][0],
            upper=lim["wrist_flexion"][1],
            effort=10.0,
        ),
    ]
    return ChainSpec(
        name="human_arm7",
        description=(
            "7-DOF human-like right arm (book §6-3, Fig. 6-5/6-6): shoulder x-y-z, elbow x, wrist "
            "z-y-x, hanging along -z; y forward, x to the right; tool = hand point H."
        ),
        joints=joints,
        tool_name="hand_point",
        tool_origin=homogeneous(r=[0, 0, -l3]),
        source="book 000 l.3927-3989 (§6-3, Eq. (6-30)-(6-39)); limits Table 2.2 l.527-534",
        inertia_source=(
            f"de Leva (1996) Table 4, {sex}, scaled to height {height} m and mass {mass} kg"
        )
        + (
            ""
            if segment_lengths is None
            else f"; measured segment lengths {sorted(segment_lengths)}"
        ),
        params={"height": height, "mass": mass, "sex": sex, "l1": l1, "l2": l2, "l3": l3},
        person=True,
        comfort=dict(HUMAN_ARM7_COMFORT),
        printed=(PrintedForm("(6-34)-(6-39)", _hand_pose, _jacobian, _length_jacobian),),
    )


# ---------------------------------------------------------------- the book's printed closed forms
# Eq. (6-34)-(6-39) and (6-119) of this arm, vectorised over a batch of configurations q of
# shape (7,) or (N, 7) (rad); lengths l1, l2, l3 in m (the spec's params).


def human_arm7_rotations(q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C_E, C_W, C_H of the §6-3 arm, Eq. (6-34)–(6-36), each (N, 3, 3) (or (3, 3)).

    C_E = Cx1 Cy2 (printed elementwise, (6-34)); C_W = Cx1 Cy2 Cz3 Cx4 (6-35); C_H = C_W Cz5
    Cy6 Cx7 written column-wise with the columns W1, W2, W3 of C_W (6-36; the printed h21, h31
    read s6c6 where s5c6 belongs)."""
    q2, single = as_batch(q, 7)
    c = np.cos(q2)
    s = np.sin(q2)
    c1, c2, c3, c4, c5, c6, c7 = c.T
    s1, s2, s3, s4, s5, s6, s7 = s.T
    N = q2.shape[0]
    CE = np.empty((N, 3, 3))
    CE[:, 0] = np.stack([c2, np.zeros(N), s2], -1)
    CE[:, 1] = np.stack([s1 * s2, c1, -s1 * c2], -1)
    CE[:, 2] = np.stack([-c1 * s2, s1, c1 * c2], -1)
    W1 = np.stack([c2 * c3, s1 * s2 * c3 + c1 * s3, -c1 * s2 * c3 + s1 * s3], -1)
    W2 = np.stack(
        [
            -c2 * s3 * c4 + s2 * s4,
            -s1 * s2 * s3 * c4 + c1 * c3 * c4 - s1 * c2 * s4,
            c1 * s2 * s3 * c4 + s1 * c3 * c4 + c1 * c2 * s4,
        ],
        -1,
    )
    W3 = np.stack(
        [
            c2 * s3 * s4 + s2 * c4,
            s1 * s2 * s3 * s4 - c1 * c3 * s4 - s1 * c2 * c4,
            -c1 * s2 * s3 * s4 - s1 * c3 * s4 + c1 * c2 * c4,
        ],
        -1,
    )
    CW = np.stack([W1, W2, W3], axis=-1)
    H1 = W1 * (c5 * c6)[:, None] + W2 * (s5 * c6)[:, None] - W3 * s6[:, None]
    H2 = (
        W1 * (c5 * s6 * s7 - s5 * c7)[:, None]
        + W2 * (s5 * s6 * s7 + c5 * c7)[:, None]
        + W3 * (c6 * s7)[:, None]
    )
    H3 = (
        W1 * (c5 * s6 * c7 + s5 * s7)[:, None]
        + W2 * (s5 * s6 * c7 - c5 * s7)[:, None]
        + W3 * (c6 * c7)[:, None]
    )
    CH = np.stack([H1, H2, H3], axis=-1)
    if single:
        return CE[0], CW[0], CH[0]
    return CE, CW, CH


def human_arm7_points(q, l1: float, l2: float, l3: float):
    """Elbow, wrist and hand points P_E, P_W, P_H of the §6-3 arm, Eq. (6-37)–(6-39), in the
    shoulder frame (m), and C_H.  Returns (PE, PW, PH, CH)."""
    l1, l2, l3 = finite_params(l1=l1, l2=l2, l3=l3)
    CE, CW, CH = human_arm7_rotations(q)
    PE = -l1 * CE[..., :, 2]
    PW = PE - l2 * CW[..., :, 2]
    PH = PW - l3 * CH[..., :, 2]
    return PE, PW, PH, CH


def human_arm7_hand_pose(q, l1: float, l2: float, l3: float) -> np.ndarray:
    """Hand pose of the §6-3 arm: orientation C_H (6-36) at the hand point P_H (6-39)."""
    _, _, PH, CH = human_arm7_points(q, l1, l2, l3)
    T = np.zeros(PH.shape[:-1] + (4, 4))
    T[..., :3, :3] = CH
    T[..., :3, 3] = PH
    T[..., 3, 3] = 1.0
    return T


def human_arm7_jacobian(q, l1: float, l2: float, l3: float) -> np.ndarray:
    """Jacobian of the hand point of the §6-3 arm, LOCAL_WORLD_ALIGNED, rows (v; ω), (6, 7).

    Joint axes from the printed rotations: x0; Cx1·y; C_E·z; C_E Cz3·x (= column 1 of C_W);
    C_W·z; C_W Cz5·y; C_W Cz5 Cy6·x (= column 1 of C_H).  Shoulder joints turn about S,
    the elbow about P_E and the wrist joints about P_W; column k is (a_k × (P_H − c_k); a_k)."""
    q2, single = as_batch(q, 7)
    PE, PW, PH, CH = human_arm7_points(q2, l1, l2, l3)
    CE, CW, _ = human_arm7_rotations(q2)
    N = q2.shape[0]
    c1, s1 = np.cos(q2[:, 0]), np.sin(q2[:, 0])
    c5, s5 = np.cos(q2[:, 4]), np.sin(q2[:, 4])
    axes = np.empty((N, 7, 3))
    axes[:, 0] = [1.0, 0.0, 0.0]
    axes[:, 1] = np.stack([np.zeros(N), c1, s1], -1)  # Cx1 · e_y
    axes[:, 2] = CE[:, :, 2]
    axes[:, 3] = CW[:, :, 0]
    axes[:, 4] = CW[:, :, 2]
    axes[:, 5] = CW[:, :, 0] * (-s5)[:, None] + CW[:, :, 1] * c5[:, None]  # C_W Cz5 · e_y
    axes[:, 6] = CH[:, :, 0]
    centres = np.stack([np.zeros((N, 3))] * 3 + [PE] + [PW] * 3, axis=1)
    J = np.empty((N, 6, 7))
    J[:, :3, :] = np.cross(axes, PH[:, None, :] - centres).transpose(0, 2, 1)
    J[:, 3:, :] = axes.transpose(0, 2, 1)
    return J[0] if single else J


def human_arm7_length_jacobian(q) -> np.ndarray:
    """The book's Eq. (6-119) for the §6-3 arm: the 3 × 3 matrix [−e_{·3}, −w_{·3}, −h_{·3}]
    mapping (Δl₁, Δl₂, Δl₃) to (Δx_H, Δy_H, Δz_H), with C_E, C_W, C_H of (6-34)–(6-36).
    (:mod:`anthroarm.kinematics.error_propagation` computes the same coefficients for any
    robot.)"""
    CE, CW, CH = human_arm7_rotations(np.asarray(q, float))
    return -np.stack([CE[..., :, 2], CW[..., :, 2], CH[..., :, 2]], axis=-1)


# the forms as the spec declares them: (q, spec.params) -> ...; looked up when called


def _hand_pose(q, p):
    return human_arm7_hand_pose(q, p["l1"], p["l2"], p["l3"])


def _jacobian(q, p):
    return human_arm7_jacobian(q, p["l1"], p["l2"], p["l3"])


def _length_jacobian(q, p):
    return human_arm7_length_jacobian(q)
