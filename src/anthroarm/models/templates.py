"""The four manipulator motion forms of Table 2.3 (book §2-4, l. 641–658, Fig. 2-10) as catalog
generators: Cartesian (直角坐标式, P-P-P), cylindrical (圆柱坐标式, R-P-P), spherical (球坐标式,
R-R-P) and articulated (多关节式, R-R-R).  Table 2.3 itself (workspace shape, space taken, ...)
is data: :func:`anthroarm.models.book_tables.robot_forms`.

Each generator returns the three positioning axes of its form (the book's "arm"; a wrist would
be added on top) as a :class:`~anthroarm.models.spec.ChainSpec`, with the tool frame at the
end of the last axis.  Joint variables are the form's coordinates, so the tool position is:

* Cartesian: ``p = (x0 + q1, q2, h0 + q3)`` — a box (Table 2.3: 立方体);
* cylindrical: azimuth q1, height ``h0 + q2``, radius q3 — a hollow cylinder (圆柱体);
* spherical: azimuth q1, elevation q2 about the shoulder at height h0, radius q3 — a spherical
  shell sector (球体); the Unimate is of this form (Fig. 2-11);
* articulated: azimuth q1, shoulder q2 and elbow q3 (relative) in the vertical plane, upper arm
  l2 and forearm l3 — a union of spherical shells ("球多球体" as printed).

Defaults follow the book's technical parameters of manipulators (§2-4, l. 799–843): arm rotation
over more than 180° (here ±135°), radial extension 500–1000 mm, vertical stroke within 2000 mm
(here 1000 mm), joint speeds up to about 1000 mm/s and 180°/s.  The rest (heights, the
elevation and elbow ranges) is our choice, said in each docstring.  Inertias: the default rods
of :func:`anthroarm.models.spec.rod_link` (not printed).

Units: metres, radians (the angular ranges ``base``, ``elevation``, ``shoulder``, ``elbow``
are in rad, the strokes and lengths in m).  A parameter out of range raises
:class:`~anthroarm.errors.ParameterError` naming it.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..spatial.rotations import homogeneous
from .spec import (
    DEFAULT_JOINT_MASS,
    DEFAULT_LINEAR_DENSITY,
    DEFAULT_LINK_RADIUS,
    ChainSpec,
    JointSpec,
    rod_link,
)
from .vector_loop import I, J, K, VectorLoop

deg = np.pi / 180.0
#: the book's usual maximum speeds (§2-4, l. 820-826): about 1000 mm/s and 180°/s
MAX_LINEAR_SPEED = 1.0
MAX_ANGULAR_SPEED = np.pi
#: default base rotation range (rad): more than 180° (§2-4, l. 836)
BASE_RANGE = (-135 * deg, 135 * deg)
#: default radial extension (m): 500-1000 mm (§2-4, l. 836)
REACH = (0.5, 1.0)
#: default vertical stroke (m): within 2000 mm (§2-4, l. 836)
LIFT = (0.0, 1.0)

X, Z, MINUS_Y = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)
#: the largest length or stroke a template takes (m): beyond it the link masses and inertias of
#: the default rods overflow (1e300 m gave an 'inf' mass reported against the committed URDF)
MAX_LENGTH = 1e3


def _length(model: str, name: str, v, positive: bool = False) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise ParameterError(f"{model}: {name} must be a length in m, got {v!r}") from None
    if not np.isfinite(x) or x < 0 or (positive and x == 0) or x > MAX_LENGTH:
        raise ParameterError(
            f"{model}: {name} must be a finite length {'> 0' if positive else '>= 0'} and at most "
            f"{MAX_LENGTH:g} m, got {v!r}"
        )
    return x


def _range(
    model: str,
    name: str,
    r,
    lo_min: float = -MAX_LENGTH,
    hi_max: float = MAX_LENGTH,
    unit: str = "m",
) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in r)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{model}: {name} must be a pair (lower, upper) in {unit}, got {r!r}"
        ) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi and lo >= lo_min and hi <= hi_max):
        raise ParameterError(
            f"{model}: {name} must be finite with lower < upper within [{lo_min:g}, {hi_max:g}] "
            f"{unit}, got {r!r}"
        )
    return lo, hi


def _joint(name, kind, origin, axis, rng, segment) -> JointSpec:
    return JointSpec(
        name,
        kind,
        homogeneous(r=list(origin)),
        axis=axis,
        lower=rng[0],
        upper=rng[1],
        velocity=MAX_ANGULAR_SPEED if kind == "revolute" else MAX_LINEAR_SPEED,
        link=rod_link(f"{name}_link", list(segment)),
    )


def _spec(name: str, form: str, joints: list[JointSpec], tool, params: dict) -> ChainSpec:
    return ChainSpec(
        name=name,
        description=(
            f"{form} manipulator template (book Table 2.3, Fig. 2-10): three positioning axes; "
            "tool = arm end."
        ),
        joints=joints,
        tool_name="tool",
        tool_origin=homogeneous(r=list(tool)),
        source="book 000 l.641-658 (Table 2.3, Fig. 2-10) and l.799-843 (technical parameters); "
        "dimensions chosen by anthroarm within the book's ranges",
        inertia_source=(
            f"not printed: uniform cylinders of {DEFAULT_LINEAR_DENSITY} kg/m, radius "
            f"{DEFAULT_LINK_RADIUS} m, plus {DEFAULT_JOINT_MASS} kg at each joint"
        ),
        params=params,
    )


def cartesian_robot(
    h0: float = 0.5, x0: float = 0.3, x_stroke=(0.0, 1.0), y_stroke=(-0.5, 0.5), z_stroke=LIFT
) -> ChainSpec:
    """Cartesian (直角坐标式) P-P-P template of Table 2.3.

    Slides along x, y, z; tool at ``(x0 + q1, q2, h0 + q3)`` (m).  Workspace: the box of the three
    strokes (Table 2.3: cube). Defaults (ours): gantry height h0 = 0.5 m, x offset 0.3 m, strokes 1
    m."""
    m = "cartesian_robot"
    h0, x0 = _length(m, "h0", h0), _length(m, "x0", x0)
    sx, sy, sz = (
        _range(m, n, r)
        for n, r in (("x_stroke", x_stroke), ("y_stroke", y_stroke), ("z_stroke", z_stroke))
    )
    joints = [
        _joint("slide_x", "prismatic", (x0, 0, h0), X, sx, (0, 0, 0)),
        _joint("slide_y", "prismatic", (0, 0, 0), (0.0, 1.0, 0.0), sy, (0, 0, 0)),
        _joint("slide_z", "prismatic", (0, 0, 0), Z, sz, (0, 0, 0)),
    ]
    return _spec(
        m,
        "Cartesian (P-P-P)",
        joints,
        (0, 0, 0),
        {"h0": h0, "x0": x0, "x_stroke": list(sx), "y_stroke": list(sy), "z_stroke": list(sz)},
    )


def cylindrical_robot(h0: float = 0.3, base=BASE_RANGE, lift=LIFT, reach=REACH) -> ChainSpec:
    """Cylindrical (圆柱坐标式) R-P-P template of Table 2.3 (the Versatran, Fig. 2-11).

    Azimuth q1 (rad) about z, height ``h0 + q2``, radius q3 (m).  Workspace: a hollow cylinder
    sector (Table 2.3). Defaults: base ±135°, lift 0–1 m, reach 0.5–1 m (§2-4); h0 = 0.3 m
    (ours)."""
    m = "cylindrical_robot"
    h0 = _length(m, "h0", h0)
    b = _range(m, "base", base, -np.pi, np.pi, "rad")
    lift = _range(m, "lift", lift)
    reach = _range(m, "reach", reach, 0.0)
    joints = [
        _joint("azimuth", "revolute", (0, 0, 0), Z, b, (0, 0, h0)),
        _joint("lift", "prismatic", (0, 0, h0), Z, lift, (0, 0, 0)),
        _joint("reach", "prismatic", (0, 0, 0), X, reach, (0, 0, 0)),
    ]
    return _spec(
        m,
        "Cylindrical (R-P-P)",
        joints,
        (0, 0, 0),
        {"h0": h0, "base": list(b), "lift": list(lift), "reach": list(reach)},
    )


def spherical_robot(
    h0: float = 0.8, base=BASE_RANGE, elevation=(-45 * deg, 60 * deg), reach=REACH
) -> ChainSpec:
    """Spherical (球坐标式) R-R-P template of Table 2.3 (the Unimate, Fig. 2-11).

    Azimuth q1 about z, elevation q2 (rad) of the boom about the shoulder at height h0 (positive
    up), boom length q3 (m) from the shoulder.  Workspace: a spherical shell sector (Table 2.3:
    球体; "can pick objects off the floor").  Defaults: base ±135°, reach 0.5–1 m (§2-4);
    h0 = 0.8 m, elevation −45°…60° (ours)."""
    m = "spherical_robot"
    h0 = _length(m, "h0", h0)
    b = _range(m, "base", base, -np.pi, np.pi, "rad")
    e = _range(m, "elevation", elevation, -np.pi / 2, np.pi / 2, "rad")
    reach = _range(m, "reach", reach, 0.0)
    joints = [
        _joint("azimuth", "revolute", (0, 0, 0), Z, b, (0, 0, h0)),
        _joint("elevation", "revolute", (0, 0, h0), MINUS_Y, e, (0, 0, 0)),
        _joint("boom", "prismatic", (0, 0, 0), X, reach, (0, 0, 0)),
    ]
    return _spec(
        m,
        "Spherical (R-R-P)",
        joints,
        (0, 0, 0),
        {"h0": h0, "base": list(b), "elevation": list(e), "reach": list(reach)},
    )


def articulated_robot(
    h0: float = 0.5,
    l2: float = 0.5,
    l3: float = 0.5,
    base=BASE_RANGE,
    shoulder=(-45 * deg, 90 * deg),
    elbow=(-150 * deg, 0.0),
) -> ChainSpec:
    """Articulated (多关节式) R-R-R template of Table 2.3.

    Azimuth q1 about z, shoulder q2 and elbow q3 (rad; the elbow relative, both positive up,
    about −y) in the vertical plane; upper arm l2, forearm l3 (m),
    shoulder at height h0.  Tool: ``r = l2 cos q2 + l3 cos(q2+q3)``, ``z = h0 + l2 sin q2 +
    l3 sin(q2+q3)`` at azimuth q1.  Defaults: base ±135° (§2-4); lengths 0.5 m, shoulder
    −45°…90°, elbow −150°…0 (ours)."""
    m = "articulated_robot"
    h0 = _length(m, "h0", h0)
    l2, l3 = _length(m, "l2", l2, True), _length(m, "l3", l3, True)
    b = _range(m, "base", base, -np.pi, np.pi, "rad")
    s = _range(m, "shoulder", shoulder, -np.pi, np.pi, "rad")
    e = _range(m, "elbow", elbow, -np.pi, np.pi, "rad")
    joints = [
        _joint("azimuth", "revolute", (0, 0, 0), Z, b, (0, 0, h0)),
        _joint("shoulder", "revolute", (0, 0, h0), MINUS_Y, s, (l2, 0, 0)),
        _joint("elbow", "revolute", (l2, 0, 0), MINUS_Y, e, (l3, 0, 0)),
    ]
    return _spec(
        m,
        "Articulated (R-R-R)",
        joints,
        (l3, 0, 0),
        {"h0": h0, "l2": l2, "l3": l3, "base": list(b), "shoulder": list(s), "elbow": list(e)},
    )


# ------------------------------------------------------------------ §6-4 vector-loop arms


def unimate2600_loop(
    c1: float = 0.5,
    c2: float = 0.3,
    boom=(0.3, 1.0),
    c4: float = 0.15,
    c5: float = 0.1,
    g6: float = 0.12,
):
    """The Unimate 2600 of Fig. 6-10 (a spherical-form robot, Table 2.3) in vector-loop form,
    characteristic equation (6-50): ``P = C₁ + E^{kθ₁}(C₂ + E^{jθ₂}(L₃ + E^{iθ₃}(C₄ + E^{jθ₄}(C₅
    + E^{iθ₅}(G₆*)))))``, joints θ₁ (k), θ₂ (j), the boom L (slide along i), θ₃ (i), θ₄ (j),
    θ₅ (i).  Directions (Fig. 6-10 is lost; read from the grouping of (6-51), ch6 notes §2.5):
    C₁, C₂ ∥ k; L₃, C₄ ∥ i; C₅, G₆ ∥ k (assumed).  Attitude vectors a₀ ∥ G₆ (k, the hand axis)
    and b₀ ∥ i (assumed).  No numbers are printed: the lengths (m) and the boom stroke are ours.

    Returns
    -------
    tuple
        ``(VectorLoop, limits)``: the loop and the joint ranges for
        :func:`anthroarm.kinematics.vector_loop.loop_spec`.
    """
    m = "unimate2600"
    c1, c2, c4, c5, g6 = (
        _length(m, n, v) for n, v in (("c1", c1), ("c2", c2), ("c4", c4), ("c5", c5), ("g6", g6))
    )
    stroke = _range(m, "boom", boom, 0.0)
    k, i = np.array(K), np.array(I)
    loop = VectorLoop(
        (
            ("C", c1 * k),
            ("R", K),
            ("C", c2 * k),
            ("R", J),
            ("L", I),
            ("R", I),
            ("C", c4 * i),
            ("R", J),
            ("C", c5 * k),
            ("R", I),
        ),
        G=g6 * k,
        a0=K,
        b0=I,
        name="unimate2600",
    )
    rng = (-np.pi, np.pi)
    return loop, [rng, (-np.pi / 2, np.pi / 2), stroke, rng, rng, rng]


def tensor6r_loop(
    c1: float = 0.3,
    c2: float = 0.2,
    c3: float = 0.05,
    c4: float = 0.4,
    c5: float = 0.2,
    c6: float = 0.15,
    c7: float = 0.05,
    G8: float = 0.1,
):
    """The 6R arm of Fig. 6-11 (an articulated-form robot) in vector-loop form, Eqs. (6-62)–(6-65)
    as reconstructed in the ch6 notes §2.6: ``P = C₁ᵏ + E^{kθ₁}(C₂ᵏ + C₃ⁱ + E^{jθ₂}(C₄ⁱ +
    E^{jθ₃}(C₅ⁱ + E^{iθ₄}(C₆ⁱ + E^{jθ₅}(C₇ⁱ + E^{iθ₆}(G₈ⁱ))))))``; attitude vectors a₀ ∥ i (the
    hand axis) and b₀ ∥ k (6-65).  In the initial state the arm is horizontal along +i.  No
    numbers are printed: the lengths (m) are ours.  Returns ``(VectorLoop, limits)``."""
    m = "tensor6r"
    c = [
        _length(m, n, v)
        for n, v in (
            ("c1", c1),
            ("c2", c2),
            ("c3", c3),
            ("c4", c4),
            ("c5", c5),
            ("c6", c6),
            ("c7", c7),
            ("G8", G8),
        )
    ]
    k, i = np.array(K), np.array(I)
    loop = VectorLoop(
        (
            ("C", c[0] * k),
            ("R", K),
            ("C", c[1] * k + c[2] * i),
            ("R", J),
            ("C", c[3] * i),
            ("R", J),
            ("C", c[4] * i),
            ("R", I),
            ("C", c[5] * i),
            ("R", J),
            ("C", c[6] * i),
            ("R", I),
        ),
        G=c[7] * i,
        a0=I,
        b0=K,
        name="tensor6r",
    )
    return loop, [(-np.pi, np.pi)] * 6


#: catalog name -> generator, in the order of Table 2.3
TEMPLATES = {
    "cartesian_robot": cartesian_robot,
    "cylindrical_robot": cylindrical_robot,
    "spherical_robot": spherical_robot,
    "articulated_robot": articulated_robot,
}

__all__ = [
    "TEMPLATES",
    "unimate2600_loop",
    "tensor6r_loop",
    "cartesian_robot",
    "cylindrical_robot",
    "spherical_robot",
    "articulated_robot",
    "MAX_LINEAR_SPEED",
    "MAX_ANGULAR_SPEED",
    "BASE_RANGE",
    "REACH",
    "LIFT",
]
