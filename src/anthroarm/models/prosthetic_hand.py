"""A prosthetic hand built from the book's linkages (§2-3, Fig. 2-8 / 2-9; analysed in §6-5),
as a catalog model: ``aa.load("prosthetic_hand")``.

Index, middle, ring and little finger are the planar six-bar of Fig. 2-8, the thumb the RRSS
spatial four-bar plus the planar four-bar of Fig. 2-9: five mechanisms, five motors, 5 DOF.
The exact model of the hand — the five mechanisms on one palm with their loop closures, the
solver that closes them, the fingertip paths — is
:mod:`anthroarm.mechanisms.linkage_hand` (:func:`~anthroarm.mechanisms.linkage_hand.closed_loop`,
:func:`~anthroarm.mechanisms.linkage_hand.solve`).

This module is the hand's plain URDF (``urdf/prosthetic_hand.urdf``): the spanning tree of the
exact model (links, bars and all) with every passive joint a ``<mimic>`` of its finger's
driver, θ_j ≈ a_j θ_driver + b_j, fitted by least squares on the exact closed-loop solution over
the driver range (:func:`anthroarm.mechanisms.linkage_hand.mimic_fit` reports each fit's largest
joint error and the largest fingertip error).  The tree and the fit are read from the table the
mechanism analysis writes (``anthroarm/data/models/linkage_hand.json``,
:func:`~anthroarm.mechanisms.linkage_hand.tree_table`; a test proves the committed table equals
the analysis), so that the catalog does not run the mechanisms: at scale s every length is s
times the table's, the angles and the mimic lines are the table's.  Use it where only a plain
URDF is possible (a viewer, a simulator without loop constraints); use the closed loop for exact
kinematics.

Palm frame (the URDF's ``palm``, the base): −z toward the fingers, +y out of the palm, +x to
the thumb side (a right hand), origin at the wrist.  Driver variables (rad): ``{finger}_mcp``
∈ [−0.2236, 0] and ``thumb_r1`` ∈ [0, 30°]; frames ``{digit}_tip`` are the fingertips.
Units: m, rad, kg.
"""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np

from .._io import atomic_write_text
from ..spatial.rotations import homogeneous, rot_axis
from .hand import DIGITS, LINKAGE_HAND_TABLE, check_hand_scale
from .spec import REPO_URDF_DIR, ChainSpec, JointSpec, LinkSpec, Shape, capsule, to_urdf

#: finger breadth of the prosthesis (m) at scale 1: the visual capsule radius and the mass model
PHALANX_RADIUS = 0.008
#: density of the phalanges and bars (kg/m³): a polyamide print (our assumption; the book gives
#: none)
DENSITY = 1150.0


@lru_cache(maxsize=1)
def tree_table() -> dict:
    """The linkage hand's spanning tree and mimic fit at scale 1, as the mechanism analysis
    wrote it (:func:`anthroarm.mechanisms.linkage_hand.tree_table`)."""
    return json.loads(LINKAGE_HAND_TABLE.read_text(encoding="utf-8"))


def _scaled(T, s: float) -> np.ndarray:
    """A 4×4 placement (16 numbers, row by row) with its translation times ``s``."""
    T = np.array(T, float).reshape(4, 4)
    T[:3, 3] *= s
    return T


def _cyl_link(name, seg, radius, rgba, material):
    """Solid cylinder of :data:`DENSITY` along ``seg`` (link frame), drawn as a capsule."""
    seg = np.asarray(seg, float)
    L = float(np.linalg.norm(seg))
    m = DENSITY * np.pi * radius**2 * max(L, 2 * radius)
    u = seg / L if L > 1e-12 else np.array([0.0, 0.0, 1.0])
    i_perp = m * (3 * radius**2 + max(L, 2 * radius) ** 2) / 12.0
    I = i_perp * (np.eye(3) - np.outer(u, u)) + m * radius**2 / 2.0 * np.outer(u, u)
    shapes = capsule(np.zeros(3), seg, radius, material=material, rgba=rgba) if L > 1e-12 else ()
    return LinkSpec(
        name=name, mass=m, com=seg / 2, inertia=I, segment=seg, radius=radius, shapes=shapes
    )


def prosthetic_hand(scale: float = 1.0) -> ChainSpec:
    """The linkage hand as a plain-URDF parameter table: the spanning tree of
    :func:`anthroarm.mechanisms.linkage_hand.loop_spec` with the passive joints as ``<mimic>``
    lines of their drivers (:func:`anthroarm.mechanisms.linkage_hand.mimic_fit`), read from
    :func:`tree_table` and scaled by ``scale`` (0.3…3); base ``palm``, tool ``index_tip``,
    frames ``{digit}_tip``.

    Masses (our assumption, the book prints none): each link a solid polyamide cylinder
    (1150 kg/m³) of radius 8 mm × ``scale`` along its longest site or child offset; the palm a
    box of the same material, half hollow.  nq = 5 (one driver per digit)."""
    s = check_hand_scale(scale, "prosthetic_hand")
    table = tree_table()
    fit_joints = table["fit"]["joints"]
    tip_error = {d: s * e for d, e in table["fit"]["tip_error"].items()}
    ranges = {d: tuple(v) for d, v in table["driver_ranges"].items()}
    tree = [(n, p, c, t, _scaled(T, s), tuple(a)) for n, p, c, t, T, a in table["joints"]]
    sites = [(n, p, _scaled(T, s)) for n, p, T in table["sites"]]
    r = PHALANX_RADIUS * s
    # every link's drawn segment: to its farthest child joint or site
    offsets: dict = {}
    for _, parent, _, _, origin, _ in tree:
        offsets.setdefault(parent, []).append(origin[:3, 3])
    for n, p, T in sites:
        offsets.setdefault(p, []).append(T[:3, 3])
    skin, metal = (0.93, 0.78, 0.68, 1.0), (0.6, 0.62, 0.66, 1.0)
    joints = []
    expanded = []
    for name, parent, child, kind, origin, axis in tree:
        # a ball joint is three revolute joints about x, y, z (as LoopSpec.urdf)
        if kind == "ball":
            bx, by = f"{name}__bx", f"{name}__by"
            expanded += [
                (f"{name}_x", parent, bx, origin, (1.0, 0, 0)),
                (f"{name}_y", bx, by, np.eye(4), (0, 1.0, 0)),
                (f"{name}_z", by, child, np.eye(4), (0, 0, 1.0)),
            ]
        else:
            expanded.append((name, parent, child, origin, axis))
    inputs = set(table["inputs"])
    for name, parent, child, origin, axis in expanded:
        segs = offsets.get(child, [])
        seg = max(segs, key=np.linalg.norm) if segs else np.zeros(3)
        is_bar = "bar" in child or "rocker" in child
        link = _cyl_link(
            child,
            seg,
            r * (0.5 if is_bar else 1.0),
            metal if is_bar else skin,
            "bar" if is_bar else "skin",
        )
        digit = name.split("_")[0]
        if name in inputs:
            lo, hi = ranges[digit]
            mimic = None
        else:
            src, a, b, _ = fit_joints[name]
            lo_d, hi_d = ranges[digit]
            v = sorted((a * lo_d + b, a * hi_d + b))
            lo, hi = v[0] - 1e-6, v[1] + 1e-6
            mimic = (src, a, b)
        if mimic is not None and abs(mimic[1]) < 1e-9:
            # a joint that does not move with its driver (the S-S bar's spin: least-norm keeps it
            # constant) is fixed at its value
            joints.append(
                JointSpec(
                    name,
                    "fixed",
                    origin @ homogeneous(rot_axis(axis, mimic[2])),
                    axis=axis,
                    link=link,
                    parent=parent,
                )
            )
            continue
        joints.append(
            JointSpec(
                name,
                "revolute",
                origin,
                axis=axis,
                lower=lo,
                upper=hi,
                effort=1.0,
                velocity=3.0,
                link=link,
                parent=parent,
                mimic=mimic,
            )
        )
    B, L = (s * x for x in table["palm_size"])
    mp = DENSITY * 0.5 * B * 0.3 * B * L
    box = Shape(
        "box", (B, 0.3 * B, L), homogeneous(r=[-B / 8, 0.0, -L / 2]), material="skin", rgba=skin
    )
    palm_I = mp / 12.0 * np.diag([(0.3 * B) ** 2 + L**2, B**2 + L**2, B**2 + (0.3 * B) ** 2])
    palm = LinkSpec(
        name="palm", mass=mp, com=np.array([-B / 8, 0.0, -L / 2]), inertia=palm_I, shapes=(box,)
    )
    palm_mount = JointSpec("palm_mount", "fixed", homogeneous(), link=palm, parent="world")
    tips = {n: (p, T) for n, p, T in sites if n.endswith("_tip")}
    frames = tuple((f"{d}_tip", *tips[f"{d}_tip"]) for d in DIGITS if d != "index")
    # the closure points of both sides: their distance shows the mimic approximation's gap
    frames += tuple((n, p, T) for n, p, T in sites if not n.endswith("_tip"))
    err = ", ".join(f"{d} {1000 * tip_error[d]:.2f} mm" for d in DIGITS)
    return ChainSpec(
        name="prosthetic_hand",
        description=(
            "Prosthetic hand of the book's linkages (Fig. 2-8 six-bar fingers, Fig. 2-9 RRSS + "
            "four-bar thumb; §6-5): spanning tree with the passive joints as mimic lines of the 5 "
            f"drivers (largest fingertip error of the approximation: {err}); exact model: "
            "anthroarm.mechanisms.linkage_hand.closed_loop()"
        ),
        joints=[palm_mount] + joints,
        tool_name="index_tip",
        tool_origin=tips["index_tip"][1],
        tool_parent=tips["index_tip"][0],
        base_link="world",
        frames=frames,
        source=(
            "book §2-3 Fig. 2-8/2-9 (l.557-639), §6-5 (Fig. 6-14, 6-17), §4-5 thumb geometry "
            "(l.2037-2133); finger dimensions fitted to the Chapter 3 curve f(x) "
            "(mechanisms.finger), scaled by Buchholz 1992"
        ),
        inertia_source=(
            f"not in the book: polyamide ({DENSITY:g} kg/m3) cylinders of radius {r:g} m; "
            "palm a half-filled box"
        ),
        params={"scale": s},
    )


def urdf_text(scale: float = 1.0) -> str:
    """The plain URDF of :func:`prosthetic_hand` (mimic approximations;
    ``urdf/prosthetic_hand.urdf`` is the default, committed and tested equal to this text)."""
    return to_urdf(prosthetic_hand(scale))


def write_urdf(path=None, scale: float = 1.0) -> Path:
    """Write :func:`urdf_text` to ``path`` (default: ``urdf/prosthetic_hand.urdf`` of a source
    checkout)."""
    p = Path(path) if path is not None else REPO_URDF_DIR / "prosthetic_hand.urdf"
    atomic_write_text(p, urdf_text(scale))
    return p
