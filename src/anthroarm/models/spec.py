"""Parameter tables of serial arms and their URDF.

A :class:`ChainSpec` is the single source of a catalog arm: joints (type, axis, placement in
the parent link, limits), links (mass, centre of mass, inertia) and the tool frame.  From it
:func:`to_urdf` writes the URDF that Pinocchio and yourdfpy load; nothing else writes URDF.

Two ways to fill a spec:
* :func:`from_dh` — the book's H-D table, Eq. (6-12): ``A = Rz(θ) Tz(s) Tx(h) Rx(α)`` (classic,
  distal DH).  URDF joint *j* sits at DH frame *j−1* with axis +z, its origin is the static
  part of row *j−1*, so every joint variable equals the book's θ_j (or s for a prismatic row)
  and constant offsets live in the joint origins.
* a list of :class:`JointSpec` written by hand (the 7-DOF human arm of §6-3, the planar 2R).

Units: metres, radians, kilograms.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ParameterError
from ..spatial.rotations import as_scalar, homogeneous, rotation_between

#: folder of the committed URDFs in a source checkout (``urdf/`` at the repository root); an
#: installed package does not need it: book models are loaded from the generator's text
REPO_URDF_DIR = Path(__file__).resolve().parents[3] / "urdf"

#: Default linear density (kg/m) and radius (m) of the book arms' links, which print no masses:
#: an aluminium tube Ø50 × 3 mm with its fittings weighs about 1.5 kg/m.
DEFAULT_LINEAR_DENSITY = 1.5
DEFAULT_LINK_RADIUS = 0.025
#: mass (kg) of a joint housing lumped at each joint origin, so that co-located wrist joints
#: still carry a positive-definite inertia.
DEFAULT_JOINT_MASS = 0.1


def rpy_from_matrix(R: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw (R = Rz(y) Ry(p) Rx(r)) of a rotation matrix."""
    sy = -R[2, 0]
    sy = min(1.0, max(-1.0, sy))
    pitch = float(np.arcsin(sy))
    if abs(sy) < 1.0 - 1e-12:
        roll = float(np.arctan2(R[2, 1], R[2, 2]))
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    else:  # gimbal lock: put everything in yaw
        roll = 0.0
        yaw = float(np.arctan2(-R[0, 1], R[1, 1]))
    return roll, pitch, yaw


@dataclass
class LinkSpec:
    """Rigid-body parameters of one link, in the link frame (the frame of its parent joint)."""

    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about the com
    #: vector from the link origin to the next joint (or tool); drawn as a capsule
    segment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    radius: float = DEFAULT_LINK_RADIUS
    #: visual geometry that replaces the default (a sphere at the origin and a cylinder along
    #: ``segment``): a tuple of :class:`Shape` (e.g. a palm box, phalanx capsules); ``None``
    #: keeps the default
    shapes: tuple | None = None


@dataclass
class Shape:
    """One URDF visual of a link: ``kind`` "box" (``size`` = x, y, z extents), "cylinder"
    (``size`` = radius, length; along the local z of ``origin``) or "sphere" (``size`` =
    (radius,)); ``origin`` is its 4×4 pose in the link frame (m); ``material`` and ``rgba``
    name and colour it."""

    kind: str
    size: tuple
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    material: str = "link"
    rgba: tuple = (0.75, 0.78, 0.82, 1.0)


def capsule(p0, p1, radius: float, material: str = "link", rgba=(0.75, 0.78, 0.82, 1.0)) -> tuple:
    """A capsule from ``p0`` to ``p1`` (link frame, m) of ``radius`` (m), as URDF 1.0 visuals
    can draw it: a cylinder between the points and a sphere at each end."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    L = float(np.linalg.norm(d))
    out = [Shape("sphere", (radius,), homogeneous(r=p0), material, rgba)]
    if L > 1e-12:
        T = homogeneous(rotation_between([0.0, 0.0, 1.0], d), (p0 + p1) / 2)
        out.append(Shape("cylinder", (radius, L), T, material, rgba))
        out.append(Shape("sphere", (radius,), homogeneous(r=p1), material, rgba))
    return tuple(out)


@dataclass
class JointSpec:
    """One joint and the link it moves.  ``origin`` places the joint frame in the parent link."""

    name: str
    type: str  # "revolute" | "prismatic"
    origin: np.ndarray
    axis: tuple = (0.0, 0.0, 1.0)
    lower: float = -np.pi
    upper: float = np.pi
    effort: float = 100.0
    velocity: float = 3.0
    link: LinkSpec | None = None
    #: name of the parent link (a tree); ``None``: the link of the joint before (a serial chain)
    parent: str | None = None
    #: ``(joint, multiplier, offset)``: this joint copies θ = multiplier · θ_joint + offset
    #: (URDF ``<mimic>``); it has no variable of its own
    mimic: tuple | None = None


@dataclass
class DHRow:
    """One row of the book's H-D table, Eq. (6-12): ``A = Rz(θ) Tz(s) Tx(h) Rx(α)``.

    ``kind`` is "R" (variable θ = q + offset) or "P" (variable s = q + offset).  For an "R" row
    ``theta`` is ignored and ``offset`` is added to q; for a "P" row ``s`` is ignored.
    """

    kind: str
    alpha: float
    s: float = 0.0
    h: float = 0.0
    theta: float = 0.0
    offset: float = 0.0
    lower: float = -np.pi
    upper: float = np.pi

    def static(self) -> np.ndarray:
        """Static part S of the row, (4, 4): ``A(q) = Rz(q) S`` (R) or ``A(q) = Tz(q) S`` (P)."""
        return dh_matrix(self, 0.0)


@dataclass(frozen=True)
class PrintedForm:
    """One printed closed form of a book model: ``pose(q, params)`` → (N, 4, 4) of the tool,
    ``jacobian(q, params)`` → (N, 6, n) LOCAL_WORLD_ALIGNED or None, ``length_jacobian(q,
    params)`` → (N, 3, 3) the §6-6 coefficients ∂P/∂l or None; ``params`` is the model's
    ``spec.params`` (SI units).  The builder of the model declares its forms in
    :attr:`ChainSpec.printed`; ``anthroarm check`` compares them with Pinocchio."""

    equations: str
    pose: Callable
    jacobian: Callable | None = None
    length_jacobian: Callable | None = None


@dataclass(frozen=True)
class ReachPosture:
    """The three-link arm of Fig. 2-6 inside a catalog arm, for its reach Eq. (2-3)/(2-4):
    ``lengths`` (l1, l2, l3) shoulder–elbow, elbow–wrist, wrist–tool (m), and ``bend``, the
    indices in q of the two parallel swing joints that (2-4) bends by the same angle θ3.  The
    joints before ``bend[0]`` (the shoulder) are free; every other joint is 0 in that posture,
    and q = 0 stretches the arm to l1 + l2 + l3 (2-3)."""

    lengths: tuple[float, float, float]
    bend: tuple[int, int]


def encoder_pulses_per_rad(encoder_counts: float, gear_ratio: float) -> float:
    """Motor pulses per joint radian: ``encoder_counts · gear_ratio / 2π`` (encoder counts per
    motor turn, motor turns per joint turn).  :class:`~anthroarm.errors.ParameterError` unless
    both are finite and > 0."""
    try:
        c, g = float(encoder_counts), float(gear_ratio)
    except (TypeError, ValueError):
        raise ParameterError(
            f"encoder_counts and gear_ratio must be numbers, got {encoder_counts!r}, {gear_ratio!r}"
        ) from None
    if not (np.isfinite(c) and np.isfinite(g) and c > 0 and g > 0):
        raise ParameterError(f"encoder_counts and gear_ratio must be finite and > 0, got {c}, {g}")
    return c * g / (2.0 * np.pi)


@dataclass(frozen=True)
class CellRecipe:
    """The spatial cell table (§7-3) an arm's source describes, declared by its builder
    (``ChainSpec.cells``) and built by :func:`anthroarm.ik.cells.cell_table`.

    ``rotation``: the hand orientation of the table (3×3, base frame); ``bounds``: the box
    ``(lo, hi)`` of lattice positions (m, base frame); ``D``: the cell size (m); ``branch``:
    the IK branch label stored at every lattice point; ``point``: the point of the tool frame
    whose positions the lattice holds (m, tool frame); ``encoder_counts`` (per motor turn) and
    ``gear_ratio`` (motor turns per joint turn): the scale of the stored motor pulses."""

    rotation: tuple
    bounds: tuple
    D: float
    branch: str
    point: tuple
    encoder_counts: float
    gear_ratio: float

    def pulses_per_rad(self, encoder_counts=None, gear_ratio=None) -> float:
        """:func:`encoder_pulses_per_rad` of this arm's encoder and gear, or of the values
        given."""
        return encoder_pulses_per_rad(
            self.encoder_counts if encoder_counts is None else encoder_counts,
            self.gear_ratio if gear_ratio is None else gear_ratio,
        )


@dataclass
class ChainSpec:
    """A catalog arm: its joints (each carrying the link it moves), the tool frame placed by
    ``tool_origin`` in the last link, provenance strings, and for H-D arms the table ``dh``
    with the tool pose ``tool_dh`` in the last DH frame.  ``params`` are the builder's
    arguments (SI units).  ``person``: the limb of a person (the viewer draws a torso around
    its shoulder); ``comfort``: its comfortable posture, joint name -> rad (the default
    reference of posture objectives, see :func:`anthroarm.ik.qp.comfortable_posture`).

    What the book knows about this arm beyond its table, declared by its builder so that no
    algorithm has to recognise the arm by name: ``printed``, the book's printed closed forms
    of its forward kinematics (:class:`PrintedForm`), ``reach``, the three-link arm of the
    reach formulas (:class:`ReachPosture`) or None, and ``cells``, the spatial cell table of
    its source (:class:`CellRecipe`) or None."""

    name: str
    description: str
    joints: list[JointSpec]
    tool_name: str = "tool"
    tool_origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    base_link: str = "base_link"
    source: str = ""
    inertia_source: str = ""
    dh: list[DHRow] | None = None
    tool_dh: np.ndarray | None = None  # tool pose in the last DH frame (for closed forms)
    params: dict = field(default_factory=dict)
    person: bool = False
    comfort: dict | None = None
    #: link that carries the tool frame; ``None``: the link of the last joint
    tool_parent: str | None = None
    #: extra fixed frames ``(name, parent link, 4×4 origin)``, e.g. the fingertips of a hand
    frames: tuple = ()
    #: the book's printed closed forms of this arm (:class:`PrintedForm`)
    printed: tuple = field(default=(), repr=False, compare=False)
    #: the arm of the reach formulas (2-3)/(2-4), or None
    reach: ReachPosture | None = None
    #: the spatial cell table its source describes (:class:`CellRecipe`), or None
    cells: CellRecipe | None = None

    @property
    def nq(self) -> int:
        """How many configuration variables the chain has (its joints that are neither fixed nor
        mimic joints)."""
        return sum(1 for j in self.joints if j.mimic is None and j.type != "fixed")


def dh_matrix(row: DHRow, q) -> np.ndarray:
    """The book's A matrix, Eq. (6-12), of one row at joint value q: shape (4, 4), or
    ``np.shape(q) + (4, 4)`` for an array of joint values."""
    q = np.asarray(q, dtype=float)
    if row.kind == "R":
        theta, s = q + row.offset, row.s
    else:
        theta, s = row.theta, q + row.offset
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(row.alpha), np.sin(row.alpha)
    A = np.zeros(q.shape + (4, 4))
    A[..., 0, 0] = ct
    A[..., 0, 1] = -st * ca
    A[..., 0, 2] = st * sa
    A[..., 0, 3] = row.h * ct
    A[..., 1, 0] = st
    A[..., 1, 1] = ct * ca
    A[..., 1, 2] = -ct * sa
    A[..., 1, 3] = row.h * st
    A[..., 2, 1] = sa
    A[..., 2, 2] = ca
    A[..., 2, 3] = s
    A[..., 3, 3] = 1.0
    return A


def as_batch(q, n: int) -> tuple[np.ndarray, bool]:
    """Joint values ``q`` of shape (n,) or (N, n) as a finite (N, n) float array, and whether
    one configuration was given; ``ValueError`` naming the shape or the first joint that is not
    finite."""
    q = np.asarray(q, dtype=float)
    single = q.ndim == 1
    q2 = q[None, :] if single else q
    if q2.ndim != 2 or q2.shape[1] != n:
        raise ValueError(f"q must have shape ({n},) or (N, {n}), got {q.shape}")
    if not np.isfinite(q2).all():
        j = int(np.argwhere(~np.isfinite(q2))[0, 1])
        raise ValueError(f"q[{j}] is not finite")
    return q2, single


def finite_params(**values) -> list[float]:
    """The named scalar parameters (link lengths in m, angles in rad) as floats; ``ValueError``
    naming the first one that is not a finite number."""
    return [as_scalar(v, name) for name, v in values.items()]


def dh_static(row: DHRow) -> np.ndarray:
    """Static part S of a row: ``A(q) = Rz(q) S`` (R) or ``A(q) = Tz(q) S`` (P)."""
    return dh_matrix(row, 0.0)


def rod_link(
    name: str,
    segment,
    mass: float | None = None,
    radius: float = DEFAULT_LINK_RADIUS,
    joint_mass: float = DEFAULT_JOINT_MASS,
    com_fraction: float = 0.5,
    radii_of_gyration: tuple | None = None,
) -> LinkSpec:
    """A link modelled as a uniform solid cylinder along ``segment`` plus a point-ish sphere
    (radius ``radius``) of ``joint_mass`` at the link origin.

    ``radii_of_gyration`` (k_perp1, k_perp2, k_axial) in metres override the cylinder formula
    (used for anthropometric segments).  Returns mass, com and inertia about the com.
    """
    seg = np.asarray(segment, float)
    L = float(np.linalg.norm(seg))
    m_rod = DEFAULT_LINEAR_DENSITY * L if mass is None else float(mass)
    u = seg / L if L > 1e-12 else np.array([0.0, 0.0, 1.0])
    c_rod = com_fraction * seg
    if radii_of_gyration is None:
        i_perp = m_rod * (3 * radius**2 + L**2) / 12.0
        i_ax = m_rod * radius**2 / 2.0
        I_rod = i_perp * (np.eye(3) - np.outer(u, u)) + i_ax * np.outer(u, u)
    else:
        k1, k2, ka = radii_of_gyration
        # two perpendicular directions to u
        e1 = np.cross(u, [1.0, 0, 0])
        if np.linalg.norm(e1) < 1e-6:
            e1 = np.cross(u, [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(u, e1)
        I_rod = m_rod * (
            k1**2 * np.outer(e1, e1) + k2**2 * np.outer(e2, e2) + ka**2 * np.outer(u, u)
        )
    m_j = float(joint_mass)
    I_j = 0.4 * m_j * radius**2 * np.eye(3)
    m = m_rod + m_j
    com = (m_rod * c_rod) / m if m > 0 else np.zeros(3)

    # parallel-axis theorem to the common com
    def shift(mass, c):
        d = c - com
        return mass * (d @ d * np.eye(3) - np.outer(d, d))

    I = I_rod + shift(m_rod, c_rod) + I_j + shift(m_j, np.zeros(3))
    return LinkSpec(name=name, mass=m, com=com, inertia=0.5 * (I + I.T), segment=seg, radius=radius)


def from_dh(
    name: str,
    description: str,
    rows: list[DHRow],
    tool: np.ndarray,
    *,
    source: str,
    joint_names=None,
    link_masses=None,
    params=None,
    tool_name="tool",
    inertia_source: str | None = None,
    printed: tuple = (),
    reach: ReachPosture | None = None,
) -> ChainSpec:
    """Build a :class:`ChainSpec` from an H-D table (Eq. (6-12)) and the tool pose in the last
    DH frame.  Joint j's origin in link j−1 is the static part S_{j−1} of row j−1 (S_0 = I);
    ``printed`` and ``reach`` go to the spec as they are."""
    n = len(rows)
    joint_names = joint_names or [f"joint{j + 1}" for j in range(n)]
    statics = [dh_static(r) for r in rows]
    joints = []
    for j, row in enumerate(rows):
        origin = np.eye(4) if j == 0 else statics[j - 1]
        nxt = statics[j] @ tool if j == n - 1 else statics[j]
        seg = nxt[:3, 3]
        m = None if link_masses is None else link_masses[j]
        link = rod_link(f"link{j + 1}", seg, mass=m)
        joints.append(
            JointSpec(
                name=joint_names[j],
                type="revolute" if row.kind == "R" else "prismatic",
                origin=origin,
                lower=row.lower,
                upper=row.upper,
                velocity=2.0 if row.kind == "R" else 0.5,
                link=link,
            )
        )
    return ChainSpec(
        name=name,
        description=description,
        joints=joints,
        tool_name=tool_name,
        tool_origin=statics[-1] @ tool,
        source=source,
        inertia_source=inertia_source
        or (
            f"not printed in the book: each link is a uniform cylinder of {DEFAULT_LINEAR_DENSITY} "
            f"kg/m, radius {DEFAULT_LINK_RADIUS} m, plus a {DEFAULT_JOINT_MASS} kg joint housing "
            "at its origin"
        ),
        dh=rows,
        tool_dh=tool,
        params=dict(params or {}),
        printed=tuple(printed),
        reach=reach,
    )


# ----------------------------------------------------------------------------------------
# URDF writer


def _num(x: float) -> str:
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def _vec(v) -> str:
    return " ".join(_num(x) for x in v)


def _origin(T: np.ndarray, indent: str) -> str:
    r, p, y = rpy_from_matrix(T[:3, :3])
    return f'{indent}<origin xyz="{_vec(T[:3, 3])}" rpy="{_vec((r, p, y))}"/>\n'


def _shape(s: Shape, indent: str) -> str:
    if s.kind == "box":
        geom = f'<box size="{_vec(s.size)}"/>'
    elif s.kind == "cylinder":
        geom = f'<cylinder radius="{_num(s.size[0])}" length="{_num(s.size[1])}"/>'
    elif s.kind == "sphere":
        geom = f'<sphere radius="{_num(s.size[0])}"/>'
    else:
        raise ParameterError(f"shape kind must be box, cylinder or sphere, got {s.kind!r}")
    return (
        f"{indent}<visual>\n{_origin(np.asarray(s.origin, float), indent + '  ')}"
        f"{indent}  <geometry>{geom}</geometry>\n"
        f'{indent}  <material name="{s.material}"><color '
        f'rgba="{_vec(s.rgba)}"/></material>\n{indent}</visual>\n'
    )


def _visuals(link: LinkSpec, indent: str) -> str:
    if link.shapes is not None:
        return "".join(_shape(s, indent) for s in link.shapes)
    out = []
    # sphere at the joint centre
    out.append(
        f'{indent}<visual>\n{indent}  <origin xyz="0 0 0" rpy="0 0 0"/>\n'
        f'{indent}  <geometry><sphere radius="{_num(1.3 * link.radius)}"/></geometry>\n'
        f'{indent}  <material name="joint"><color rgba="0.85 0.45 0.2 '
        f'1"/></material>\n{indent}</visual>\n'
    )
    L = float(np.linalg.norm(link.segment))
    if L > 1e-9:
        # the URDF cylinder is along +z: turn +z onto the segment
        T = homogeneous(rotation_between([0.0, 0.0, 1.0], link.segment), link.segment / 2)
        out.append(
            f"{indent}<visual>\n{_origin(T, indent + '  ')}"
            f'{indent}  <geometry><cylinder radius="{_num(link.radius)}" '
            f'length="{_num(L)}"/></geometry>\n'
            f'{indent}  <material name="link"><color rgba="0.75 0.78 0.82 '
            f'1"/></material>\n{indent}</visual>\n'
        )
    return "".join(out)


def _inertial(link: LinkSpec, indent: str) -> str:
    if link.mass <= 0:
        return ""
    I = link.inertia
    return (
        f'{indent}<inertial>\n{indent}  <origin xyz="{_vec(link.com)}" rpy="0 0 0"/>\n'
        f'{indent}  <mass value="{_num(link.mass)}"/>\n'
        f'{indent}  <inertia ixx="{_num(I[0, 0])}" ixy="{_num(I[0, 1])}" ixz="{_num(I[0, 2])}" '
        f'iyy="{_num(I[1, 1])}" iyz="{_num(I[1, 2])}" '
        f'izz="{_num(I[2, 2])}"/>\n{indent}</inertial>\n'
    )


def to_urdf(spec: ChainSpec) -> str:
    """URDF text of a chain.  Deterministic: the same spec always gives the same bytes."""
    lines = ['<?xml version="1.0"?>\n']
    lines.append("<!-- Generated by anthroarm.models from its parameter table; do not edit.\n")
    lines.append(
        f"     {spec.description}\n     Source: {spec.source}\n     Inertia: "
        f"{spec.inertia_source}\n"
    )
    if spec.params:
        lines.append(
            "     Parameters: " + ", ".join(f"{k}={v}" for k, v in spec.params.items()) + "\n"
        )
    lines.append("-->\n")
    lines.append(f'<robot name="{spec.name}">\n')
    lines.append(f'  <link name="{spec.base_link}"/>\n')
    parent = spec.base_link
    for j in spec.joints:
        link = j.link or LinkSpec(name=f"{j.name}_link")
        if j.parent is not None:
            parent = j.parent
        lines.append(f'  <joint name="{j.name}" type="{j.type}">\n')
        lines.append(f'    <parent link="{parent}"/>\n    <child link="{link.name}"/>\n')
        lines.append(_origin(j.origin, "    "))
        lines.append(f'    <axis xyz="{_vec(j.axis)}"/>\n')
        lines.append(
            f'    <limit lower="{_num(j.lower)}" upper="{_num(j.upper)}" effort="{_num(j.effort)}" '
            f'velocity="{_num(j.velocity)}"/>\n'
        )
        if j.mimic is not None:
            src, mult, off = j.mimic
            lines.append(
                f'    <mimic joint="{src}" multiplier="{_num(mult)}" offset="{_num(off)}"/>\n'
            )
        lines.append("  </joint>\n")
        lines.append(f'  <link name="{link.name}">\n')
        lines.append(_inertial(link, "    "))
        lines.append(_visuals(link, "    "))
        lines.append("  </link>\n")
        parent = link.name
    lines.append(f'  <joint name="{spec.tool_name}_joint" type="fixed">\n')
    lines.append(
        f'    <parent link="{spec.tool_parent or parent}"/>\n    <child link="{spec.tool_name}"/>\n'
    )
    lines.append(_origin(spec.tool_origin, "    "))
    lines.append("  </joint>\n")
    lines.append(f'  <link name="{spec.tool_name}"/>\n')
    for name, frame_parent, T in spec.frames:
        lines.append(f'  <joint name="{name}_joint" type="fixed">\n')
        lines.append(f'    <parent link="{frame_parent}"/>\n    <child link="{name}"/>\n')
        lines.append(_origin(np.asarray(T, float), "    "))
        lines.append("  </joint>\n")
        lines.append(f'  <link name="{name}"/>\n')
    lines.append("</robot>\n")
    return "".join(lines)
