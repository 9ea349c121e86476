"""Collision shapes of the catalog arms: capsule radii per link, the palm and the torso.

The catalog's generated URDFs carry visuals only; :mod:`anthroarm.collision` builds their
collision bodies as capsules along the links (from each joint to the next joint or tip, the
segments of the parameter table) with the radii given here, and adds the boxes listed here
(a palm, a torso) on the named links.  A robot whose URDF has ``<collision>`` elements (panda,
ur5, talos_arm) uses those instead.

Sources: segment girths of the upper limb from de Leva (1996) / Dempster (1955) rounded to a
circumscribing capsule (upper arm r ≈ 0.045 m, forearm r ≈ 0.035 m for a 1.75 m male, scaled
with height); finger and thumb radii as fractions of hand breadth (Buchholz, Armstrong &
Goldstein 1992: finger width at the PIP joint ≈ 0.19 HB, thumb ≈ 0.24 HB); the palm a box
over the metacarpals (thickness ≈ 0.3 HB); the torso a box 0.26 × 0.20 × 0.50 m (1.75 m male)
medial to the right shoulder, 0.025 m of clearance from the hanging upper arm — a simplified
trunk, not an anthropometric one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: reference body height of the radii below (m)
REFERENCE_HEIGHT = 1.75


@dataclass(frozen=True)
class BoxShape:
    """A box of ``size`` (m, full edges x, y, z) centred at ``xyz`` in the frame of ``link``
    (``"universe"``: the world)."""

    link: str
    size: tuple
    xyz: tuple
    name: str


@dataclass(frozen=True)
class ShapeTable:
    """The collision shapes of one catalog arm.

    ``radius``: capsule radius per link (m); ``default_radius``: for links not listed;
    ``boxes``: boxes that replace the capsules of their link (a palm) or stand on the world (a
    torso); ``skip``: links with no collision body."""

    radius: dict = field(default_factory=dict)
    default_radius: float = 0.03
    boxes: tuple = ()
    skip: tuple = ()


def _human_arm(params: dict, with_hand: bool) -> ShapeTable:
    s = float(params.get("height", REFERENCE_HEIGHT)) / REFERENCE_HEIGHT
    radius = {"upper_arm": 0.045 * s, "forearm": 0.035 * s}
    boxes = [
        BoxShape("universe", (0.26 * s, 0.20 * s, 0.50 * s), (-0.2 * s, 0.0, -0.25 * s), "torso")
    ]
    if with_hand:
        hb = float(params["hand_breadth"])
        for digit in ("index", "middle", "ring", "little"):
            for ph in ("proximal", "middle", "distal"):
                radius[f"{digit}_{ph}"] = 0.095 * hb
        for ph in ("metacarpal", "proximal"):
            radius[f"thumb_{ph}"] = 0.12 * hb
        # every fingertip capsule has one radius: a grasp's contact offset is one number
        radius["thumb_distal"] = 0.095 * hb
        # palm over the four metacarpals: index MCP at x = +HB/4, little at x = -HB/2 (the
        # builder's layout), from the wrist to the shortest metacarpal
        mcp = 0.92 * float(params["l3"])
        boxes.append(
            BoxShape("hand", (0.94 * hb, 0.3 * hb, mcp), (-0.125 * hb, 0.0, -mcp / 2), "palm")
        )
    else:
        radius["hand"] = 0.03 * s
    return ShapeTable(radius=radius, default_radius=0.03 * s, boxes=tuple(boxes))


def _book_arm(r: float):
    def make(params: dict) -> ShapeTable:
        return ShapeTable(default_radius=r)

    return make


#: catalog name -> ShapeTable builder from the model's parameters
TABLES = {
    "human_upper_limb": lambda p: _human_arm(p, True),
    "human_arm7": lambda p: _human_arm(p, False),
    "human_right_arm": lambda p: _human_arm(p, False),
    "prosthetic_arm": _book_arm(0.035),
    "sixr_arm": _book_arm(0.05),
    "unimate5": _book_arm(0.06),
    "rrprr5": _book_arm(0.05),
    "planar2r": _book_arm(0.03),
    "care_robot": _book_arm(0.05),
    "prosthetic_hand": _book_arm(0.006),
}


def shape_table(name: str, params: dict | None = None) -> ShapeTable | None:
    """The :class:`ShapeTable` of catalog arm ``name`` built from its parameters (``None`` when
    the catalog has none: :mod:`anthroarm.collision` then uses a radius from the robot's
    length scale)."""
    make = TABLES.get(name)
    return None if make is None else make(dict(params or {}))


__all__ = ["BoxShape", "ShapeTable", "TABLES", "shape_table", "REFERENCE_HEIGHT"]
