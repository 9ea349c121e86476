"""A 6R arm written as URDF from its standard Denavit–Hartenberg table.

Standard (distal) DH, as in Craig's and Corke's tables: link i's transform is
T_i = Rz(θi) · Tz(di) · Tx(ai) · Rx(αi), joint i turns about the z axis of frame i − 1, lengths
in m and angles in rad.  The URDF has one revolute joint per row (origin = the static part
Tz(d) Tx(a) Rx(α) of the row before it, axis z), a fixed joint ``jt`` to the link ``tool`` at
the last DH frame, and no inertias (a kinematic model: FK, Jacobians and IK, not dynamics).

:data:`PUMA560` is the PUMA 560 of Corke's Robotics Toolbox (``models/DH/Puma560``), the
textbook arm of the spherical-wrist + two-parallel class.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

#: PUMA 560 (Corke, Robotics Toolbox ``Puma560``, standard DH): α (rad), a (m), d (m)
PUMA560 = {
    "alpha": (math.pi / 2, 0.0, -math.pi / 2, math.pi / 2, -math.pi / 2, 0.0),
    "a": (0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0),
    "d": (0.6718, 0.0, 0.15005, 0.4318, 0.0, 0.0),
}


def standard_dh_urdf(name: str, alpha, a, d, limit: float = math.pi) -> str:
    """URDF text of the 6R arm with standard DH rows (``alpha`` rad, ``a`` m, ``d`` m, six
    each) and joint limits ±``limit`` rad; see the module docstring for the frames.  A
    :class:`~anthroarm.errors.ParameterError` unless there are six finite values of each and
    ``limit`` is finite and > 0."""
    try:
        rows = np.array([alpha, a, d], dtype=float)
        limit = float(limit)
    except (TypeError, ValueError):
        raise ParameterError(
            f"alpha, a, d must be six numbers each and limit a number, got {alpha!r}, {a!r}, "
            f"{d!r}, {limit!r}"
        ) from None
    if rows.shape != (3, 6) or not np.isfinite(rows).all():
        raise ParameterError(f"alpha, a, d must be six finite numbers each, got shape {rows.shape}")
    if not (math.isfinite(limit) and limit > 0.0):
        raise ParameterError(f"limit must be a finite angle > 0 (rad), got {limit}")
    if not name.replace("_", "").isalnum():
        raise ParameterError(f"name must be letters, digits and '_', got {name!r}")
    al, aa_, dd = (r.tolist() for r in rows)
    links = "".join(f'<link name="l{i}"/>' for i in range(7)) + '<link name="tool"/>'
    joints = []
    for i in range(6):
        xyz, rpy = (
            ("0 0 0", "0 0 0")
            if i == 0
            else (f"{aa_[i - 1]!r} 0 {dd[i - 1]!r}", f"{al[i - 1]!r} 0 0")
        )
        joints.append(
            f'<joint name="j{i + 1}" type="revolute"><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<parent link="l{i}"/><child link="l{i + 1}"/><axis xyz="0 0 1"/>'
            f'<limit lower="{-limit!r}" upper="{limit!r}" effort="10" velocity="1"/></joint>'
        )
    joints.append(
        f'<joint name="jt" type="fixed"><origin xyz="{aa_[5]!r} 0 {dd[5]!r}" rpy="{al[5]!r} 0 0"/>'
        '<parent link="l6"/><child link="tool"/></joint>'
    )
    return (
        f'<?xml version="1.0"?><robot name="{name}"><link name="base"/>'
        '<joint name="j0" type="fixed"><parent link="base"/><child link="l0"/></joint>'
        f"{links}{''.join(joints)}</robot>"
    )


__all__ = ["PUMA560", "standard_dh_urdf"]
