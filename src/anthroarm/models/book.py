"""The book's serial arms as parameter tables, with the book's printed closed forms of them.

Each builder returns a :class:`~anthroarm.models.spec.ChainSpec`; its keyword arguments are
the book's symbols (SI units).  Where the book prints no numbers the defaults are our choice,
stated in the docstring and in the generated URDF's header.

The printed closed forms of these arms' hand poses (corrected where recomputation proves a
misprint, see ``docs/errata.md``) follow the builders, vectorised over a batch: each takes joint
values ``q`` of shape ``(n,)`` or ``(N, n)`` (rad; m for prismatic joints) and link lengths in m,
and returns the hand pose as a 4×4 homogeneous matrix (or a batch) in the book's base frame 0.
In the book's notation the hand frame has its x axis b = (u, v, w), its z axis a = (l, m, n) and
its origin at the hand point (x, y, z); y = a × b.  Each builder declares its arm's forms in
``spec.printed`` (:class:`~anthroarm.models.spec.PrintedForm`), which ``anthroarm check``
compares with Pinocchio.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..spatial.rotations import as_scalar, homogeneous
from .spec import (
    DEFAULT_JOINT_MASS,
    DEFAULT_LINEAR_DENSITY,
    DEFAULT_LINK_RADIUS,
    ChainSpec,
    DHRow,
    JointSpec,
    PrintedForm,
    ReachPosture,
    as_batch,
    dh_matrix,
    finite_params,
    from_dh,
    rod_link,
)

deg = np.pi / 180.0


def _lengths(model: str, **values) -> None:
    """:class:`~anthroarm.errors.ParameterError` (a ``ValueError``) naming the first length (m)
    that is not a finite number >= 0."""
    for name, v in values.items():
        if v is None or isinstance(v, (bool, np.bool_, str, bytes)):
            ok = False
        else:
            try:
                ok = as_scalar(v, name) >= 0.0
            except (TypeError, ValueError):
                ok = False
        if not ok:
            raise ParameterError(
                f"{model}: {name} must be a finite length >= 0 (m), e.g. {name}=0.3; "
                f"got {type(v).__name__} {v!r}"
            )


def _stroke(model: str, name: str, stroke) -> tuple[float, float]:
    """A prismatic range (lo, hi) in m with lo < hi, both finite."""
    try:
        if isinstance(stroke, (str, bytes)):
            raise TypeError("a string")
        lo, hi = (float(x) for x in stroke)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{model}: {name} must be a pair (lower, upper) in m, got {stroke!r}"
        ) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ParameterError(
            f"{model}: {name} must be finite with lower < upper (m), got {stroke!r}"
        )
    return lo, hi


def prosthetic_arm(L1: float = 0.340, L2: float = 0.260, L3: float = 0.130) -> ChainSpec:
    """Anthropomorphic prosthetic arm, Ch. 7 Fig. 7-2 / Table 7.1 (6R, R-P-R-P-R-P).

    H-D table (Table 7.1): α = 90°, 90°, 90°, −90°, 90°, −90°; s = 0, 0, L1, 0, L2, 0; h = 0.
    The printed A23 is (6-12) at θ3 + 90° (ch7 notes §3 M2): the +90° lives in the joint
    origin, so the joint variable is the book's θ3.  Ranges (l. 4925): θ1 ∈ [−180°, 0],
    θ2 ∈ [0, 180°], θ3 ∈ ±90°, θ4 ∈ [0, 150°], θ5, θ6 ∈ ±90°.

    The tool frame has the axes of frame 6 at the palm centre C = W + L3·z6.  L2 defaults to
    260 mm: Table 7.2 reproduces only with 260 mm, the caption's 240 mm is a misprint
    (``docs/errata.md``); pass ``L2=0.240`` for the printed value.
    """
    _lengths("prosthetic_arm", L1=L1, L2=L2, L3=L3)
    rows = [
        DHRow("R", 90 * deg, lower=-180 * deg, upper=0.0),
        DHRow("R", 90 * deg, lower=0.0, upper=180 * deg),
        DHRow("R", 90 * deg, s=L1, offset=90 * deg, lower=-90 * deg, upper=90 * deg),
        DHRow("R", -90 * deg, lower=0.0, upper=150 * deg),
        DHRow("R", 90 * deg, s=L2, lower=-90 * deg, upper=90 * deg),
        DHRow("R", -90 * deg, lower=-90 * deg, upper=90 * deg),
    ]
    names = [
        "shoulder_rotation",
        "shoulder_elevation",
        "humeral_rotation",
        "elbow_flexion",
        "forearm_rotation",
        "wrist_flexion",
    ]
    return from_dh(
        "prosthetic_arm",
        "Anthropomorphic 6R prosthetic arm (book Ch.7 Fig. 7-2, Table 7.1); tool = palm centre C.",
        rows,
        homogeneous(r=[0, 0, L3]),
        source=(
            "book 000 l.4906-4941 (Table 7.1, Fig. 7-2); L2=260 mm per Table 7.2 "
            "(caption prints 240)"
        ),
        joint_names=names,
        params={"L1": L1, "L2": L2, "L3": L3},
        tool_name="palm",
        # Fig. 2-6 is this arm (R-P-R-P-R-P): elbow and wrist flexion bend in one plane when
        # the forearm rotation is 0
        reach=ReachPosture((L1, L2, L3), (3, 5)),
    )


def sixr_arm(s0: float = 0.5, h2: float = 0.4, s3: float = 0.35, P: float = 0.1) -> ChainSpec:
    """6R manipulator of Fig. 6-3 (l. 3769–3847): α01 = α23 = α34 = α45 = 90°, α12 = α56 = 0;
    l_AB = s0, l_BC = h2, l_CD = s3, l_DP = P.  The book prints no lengths or ranges: the
    defaults (0.5, 0.4, 0.35, 0.1 m) are ours, and every joint ranges over ±180° so that all
    eight IK branches of Fig. 7-1 are admissible."""
    _lengths("sixr_arm", s0=s0, h2=h2, s3=s3, P=P)
    rows = [
        DHRow("R", 90 * deg, s=s0),
        DHRow("R", 0.0, h=h2),
        DHRow("R", 90 * deg),
        DHRow("R", 90 * deg, s=s3),
        DHRow("R", 90 * deg),
        DHRow("R", 0.0),
    ]
    return from_dh(
        "sixr_arm",
        "6R manipulator with spherical wrist (book Fig. 6-3); tool = hand point P on z6.",
        rows,
        homogeneous(r=[0, 0, P]),
        source="book 000 l.3769-3847 (Fig. 6-3, Eq. (6-14)-(6-17)); lengths chosen by anthroarm",
        params={"s0": s0, "h2": h2, "s3": s3, "P": P},
        tool_name="hand",
        printed=(PrintedForm("(6-16)/(6-17)", _sixr_pose),),
    )


def _rrprr_rows(s0: float, h2: float, stroke) -> list[DHRow]:
    """The R-R-P-R-R H-D table shared by Fig. 6-4 and the 002 text §4-4: α01 = α12 = α34 =
    α45 = 90°, α23 = θ3 = 0, l_AB = s0, l_BC = h2, the third joint the prismatic s2."""
    return [
        DHRow("R", 90 * deg, s=s0),
        DHRow("R", 90 * deg, h=h2, lower=-90 * deg, upper=90 * deg),
        DHRow("P", 0.0, lower=stroke[0], upper=stroke[1]),
        DHRow("R", 90 * deg),
        DHRow("R", 90 * deg),
    ]


def unimate5(s0: float = 0.7, h2: float = 0.1, P: float = 0.15, boom=(0.3, 1.0)) -> ChainSpec:
    """Unimate-type robot of Fig. 6-4 (l. 3849–3893): R-R-P-R-R with α01 = α12 = α34 = α45 = 90°,
    α23 = θ3 = 0; the third joint is the prismatic boom s2.  No numbers are printed: s0, h2, P
    and the boom stroke (0.3–1.0 m) are ours; revolute ranges are ±180° (θ2 ±90°)."""
    _lengths("unimate5", s0=s0, h2=h2, P=P)
    _stroke("unimate5", "boom", boom)
    return from_dh(
        "unimate5",
        "Unimate-type 5-DOF robot with a prismatic boom (book Fig. 6-4); tool = hand point P on "
        "z5.",
        _rrprr_rows(s0, h2, boom),
        homogeneous(r=[0, 0, P]),
        source="book 000 l.3849-3893 (Fig. 6-4, Eq. (6-19)-(6-23)); lengths chosen by anthroarm",
        joint_names=["waist", "shoulder", "boom", "wrist_pitch", "wrist_roll"],
        params={"s0": s0, "h2": h2, "P": P, "boom": list(boom)},
        tool_name="hand",
        printed=(PrintedForm("(6-21)-(6-23)", _unimate_pose),),
    )


def rrprr5(s0: float = 0.4, h2: float = 0.08, p: float = 0.12, stroke=(0.2, 0.6)) -> ChainSpec:
    """R-R-P-R-R manipulator of the 002 text §4-4 (l. 355–409), Eq. (4-50)–(4-54):
    l_AB = s0, l_BC = h2, l_DP = p, α01 = α12 = α34 = α45 = 90°, α23 = θ3 = 0, s2 = l_CD is
    the prismatic variable — the same chain as the Unimate of Fig. 6-4.  The text prints no
    numbers: ours are a bench-top size."""
    _lengths("rrprr5", s0=s0, h2=h2, p=p)
    _stroke("rrprr5", "stroke", stroke)
    return from_dh(
        "rrprr5",
        "RRPRR 5-DOF manipulator (002 text §4-4); tool = gripper centroid P on z5.",
        _rrprr_rows(s0, h2, stroke),
        homogeneous(r=[0, 0, p]),
        source="002 l.355-409 (Eq. (4-50)-(4-54)); lengths chosen by anthroarm",
        params={"s0": s0, "h2": h2, "p": p, "stroke": list(stroke)},
        tool_name="gripper",
        printed=(PrintedForm("002 (4-52)-(4-54)", _rrprr_pose),),
    )


def planar2r(l1: float = 1.0, l2: float = 1.0) -> ChainSpec:
    """Two-link planar mechanism of Fig. 7-14 (l. 5637/5645): two parallel hinges about x,
    links of 1 m, y = l1 cos θ1 + l2 cos(θ1+θ2), z = l1 sin θ1 + l2 sin(θ1+θ2)."""
    _lengths("planar2r", l1=l1, l2=l2)
    j1 = JointSpec(
        "joint1", "revolute", homogeneous(), axis=(1.0, 0, 0), link=rod_link("link1", [0, l1, 0])
    )
    j2 = JointSpec(
        "joint2",
        "revolute",
        homogeneous(r=[0, l1, 0]),
        axis=(1.0, 0, 0),
        link=rod_link("link2", [0, l2, 0]),
    )
    return ChainSpec(
        name="planar2r",
        description="Planar two-link mechanism with 1 m links (book Fig. 7-14, Table 7.3).",
        joints=[j1, j2],
        tool_name="tip",
        tool_origin=homogeneous(r=[0, l2, 0]),
        source="book 000 l.5637-5663 (Fig. 7-14, Table 7.3)",
        inertia_source=(
            f"not printed: uniform cylinders of {DEFAULT_LINEAR_DENSITY} kg/m, radius "
            f"{DEFAULT_LINK_RADIUS} m, plus {DEFAULT_JOINT_MASS} kg at each joint"
        ),
        params={"l1": l1, "l2": l2},
        printed=(PrintedForm("Fig. 7-14 (y, z)", _planar2r_pose),),
    )


# ---------------------------------------------------------------- the book's printed closed forms


def _pose(x, y, z, l, m, n, u, v, w) -> np.ndarray:
    N = np.shape(x)[0]
    T = np.zeros((N, 4, 4))
    b = np.stack([u, v, w], axis=-1)
    a = np.stack([l, m, n], axis=-1)
    T[:, :3, 0] = b
    T[:, :3, 2] = a
    T[:, :3, 1] = np.cross(a, b)
    T[:, :3, 3] = np.stack([x, y, z], axis=-1)
    T[:, 3, 3] = 1.0
    return T


def sixr_hand_pose(q, s0: float, h2: float, s3: float, P: float) -> np.ndarray:
    """6R arm of Fig. 6-3: hand position Eq. (6-16) and attitude Eq. (6-17).

    (6-16) is printed correctly; in (6-17) the printed u, v, w carry θ5 where θ6 belongs
    (errata): here u = [(C6C5C4 + S6S4)C23 + C6S5S23]C1 + (C6C5S4 − S6C4)S1, etc."""
    q2, single = as_batch(q, 6)
    s0, h2, s3, P = finite_params(s0=s0, h2=h2, s3=s3, P=P)
    t1, t2, t3, t4, t5, t6 = q2.T
    C1, S1, C2, S2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    C4, S4, C5, S5, C6, S6 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5), np.cos(t6), np.sin(t6)
    C23, S23 = np.cos(t2 + t3), np.sin(t2 + t3)
    r = P * S5 * C4 * C23 + (s3 - P * C5) * S23 + h2 * C2  # Eq. (6-16)
    x = r * C1 + P * S5 * S4 * S1
    y = r * S1 - P * S5 * S4 * C1
    z = P * S5 * C4 * S23 - (s3 - P * C5) * C23 + h2 * S2 + s0
    k = S5 * C4 * C23 - C5 * S23  # Eq. (6-17)
    l = k * C1 + S5 * S4 * S1
    m = k * S1 - S5 * S4 * C1
    n = S5 * C4 * S23 + C5 * C23
    g = (C6 * C5 * C4 + S6 * S4) * C23 + C6 * S5 * S23
    f = C6 * C5 * S4 - S6 * C4
    u = g * C1 + f * S1
    v = g * S1 - f * C1
    w = (C6 * C5 * C4 + S6 * S4) * S23 - C6 * S5 * C23
    T = _pose(x, y, z, l, m, n, u, v, w)
    return T[0] if single else T


def unimate_hand_pose(q, s0: float, h2: float, P: float) -> np.ndarray:
    """R-R-P-R-R arm: the Unimate of Fig. 6-4, Eq. (6-21)–(6-23), which is the same chain
    as the 002 text's RRPRR manipulator, Eq. (4-52)–(4-54).  ``q = (θ1, θ2, s2, θ4, θ5)``.

    Corrected misprints (errata): (6-23) v ends in −C5 S4 C1 (printed S1); (4-52) x has C2
    where the 002 text prints C3; (4-54) v as (6-23)."""
    q2, single = as_batch(q, 5)
    s0, h2, P = finite_params(s0=s0, h2=h2, P=P)
    t1, t2, s2, t4, t5 = q2.T
    C1, S1, C2, S2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    C4, S4, C5, S5 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    k = S5 * C4 * C2 - C5 * S2
    r = P * k + s2 * S2 + h2 * C2  # Eq. (6-21)
    x = r * C1 + P * S5 * S4 * S1
    y = r * S1 - P * S5 * S4 * C1
    z = P * (S5 * C4 * S2 + C5 * C2) - s2 * C2 + h2 * S2 + s0
    l = k * C1 + S5 * S4 * S1  # Eq. (6-22)
    m = k * S1 - S5 * S4 * C1
    n = S5 * C4 * S2 + C5 * C2
    g = C5 * C4 * C2 + S5 * S2  # Eq. (6-23)
    u = g * C1 + C5 * S4 * S1
    v = g * S1 - C5 * S4 * C1
    w = C5 * C4 * S2 - S5 * C2
    T = _pose(x, y, z, l, m, n, u, v, w)
    return T[0] if single else T


#: the 002 text's (4-52)–(4-54) are the same formulas as (6-21)–(6-23)
rrprr_hand_pose = unimate_hand_pose


def planar2r_tip(q, l1: float = 1.0, l2: float = 1.0) -> np.ndarray:
    """Fig. 7-14: tip (y, z) = (l1 cos θ1 + l2 cos(θ1+θ2), l1 sin θ1 + l2 sin(θ1+θ2)), shape (N,
    2)."""
    q2, single = as_batch(q, 2)
    l1, l2 = finite_params(l1=l1, l2=l2)
    t1, t12 = q2[:, 0], q2[:, 0] + q2[:, 1]
    yz = np.stack([l1 * np.cos(t1) + l2 * np.cos(t12), l1 * np.sin(t1) + l2 * np.sin(t12)], -1)
    return yz[0] if single else yz


def planar2r_tip_pose(q, l1: float = 1.0, l2: float = 1.0) -> np.ndarray:
    """Fig. 7-14 as a pose, (N, 4, 4): the printed tip (y, z) of :func:`planar2r_tip`; both
    hinges turn about x, so the tip frame is Rx(θ1 + θ2)."""
    q2, _ = as_batch(q, 2)
    yz = np.atleast_2d(planar2r_tip(q2, l1, l2))
    t = q2.sum(axis=-1)
    T = np.zeros(t.shape + (4, 4))
    T[:, 0, 0] = T[:, 3, 3] = 1.0
    T[:, 1, 1] = T[:, 2, 2] = np.cos(t)
    T[:, 2, 1], T[:, 1, 2] = np.sin(t), -np.sin(t)
    T[:, 1, 3], T[:, 2, 3] = yz[:, 0], yz[:, 1]
    return T


def prosthetic_arm_points(q, L1: float, L2: float, L3: float):
    """Elbow E, wrist W and palm centre C of the Ch. 7 prosthetic arm (m, base frame 0).

    E = L1 (c1 s2, s1 s2, −c2) (Eq. (7-17)); W = E + L2 z4; C = W + L3 z6 (Fig. 7-2), with the
    frames of Table 7.1 / Eq. (7-16) (the products of the rows' A matrices, Eq. (6-14)), θ3
    carrying the printed A23's hidden +90°."""
    q2, single = as_batch(q, 6)
    L1, L2, L3 = finite_params(L1=L1, L2=L2, L3=L3)
    F, frames = np.eye(4), []
    for j, row in enumerate(prosthetic_arm(L1, L2, L3).dh):
        F = F @ dh_matrix(row, q2[:, j])
        frames.append(F)
    E = frames[2][:, :3, 3]
    W = frames[4][:, :3, 3]
    C = W + L3 * frames[5][:, :3, 2]
    return (E[0], W[0], C[0]) if single else (E, W, C)


# the forms as the specs declare them: (q, spec.params) -> pose; the functions are looked up
# when called


def _sixr_pose(q, p):
    return sixr_hand_pose(q, p["s0"], p["h2"], p["s3"], p["P"])


def _unimate_pose(q, p):
    return unimate_hand_pose(q, p["s0"], p["h2"], p["P"])


def _rrprr_pose(q, p):
    return rrprr_hand_pose(q, p["s0"], p["h2"], p["p"])


def _planar2r_pose(q, p):
    return planar2r_tip_pose(q, p["l1"], p["l2"])
