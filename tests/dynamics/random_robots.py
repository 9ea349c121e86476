"""Random robots as URDF text for the property tests: trees of revolute, prismatic, continuous
and mimic joints on random axes and placements, with random physical inertias.

Every robot comes with what the test needs to build its oracles *without* anthroarm: for each
joint its name, kind and mimic relation (source name, multiplier, offset), so the test can map
a configuration of Pinocchio's mimic model to the model without mimic relations (q_full) and
build the coupling G (q̇_full = G q̇) by hand.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: integral multipliers are drawn often on purpose: a constant 2.0 once collided with node id 2
#: in the expression graph's hash-consing (issue 30)
MULTIPLIERS = (2.0, -1.0, 3.0, -2.0, 1.0)


@dataclass
class RJoint:
    name: str
    kind: str  # revolute, continuous, prismatic
    parent_link: str
    child_link: str
    mimic: tuple | None  # (source joint name, multiplier, offset)


@dataclass
class RandomRobot:
    name: str
    urdf: str
    joints: list  # RJoint in file order (parents before children)
    tool: str  # a leaf link

    @property
    def n_mimic(self) -> int:
        return sum(j.mimic is not None for j in self.joints)


def _f(x) -> str:
    return " ".join(f"{v:.17g}" for v in np.atleast_1d(x))


def _unit(rng) -> np.ndarray:
    if rng.random() < 0.3:  # a coordinate axis, either sign
        a = np.zeros(3)
        a[rng.integers(3)] = rng.choice([-1.0, 1.0])
        return a
    a = rng.standard_normal(3)
    return a / np.linalg.norm(a)


def _inertial(rng) -> str:
    """Mass, CoM and a physical rotational inertia (principal moments obey the triangle
    inequality), given in a rotated inertial frame."""
    m = rng.uniform(0.2, 2.0)
    c = rng.uniform(-0.15, 0.15, 3)
    rpy = rng.uniform(-np.pi, np.pi, 3)
    d = rng.uniform(0.3, 1.0, 3) * m * 0.01
    d[2] = min(d[2], d[0] + d[1] - 1e-4 * m)
    A = np.diag(d)
    # a random rotation on top of the rpy one: full off-diagonal entries
    U, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    In = U @ A @ U.T
    return (
        f'<inertial><origin xyz="{_f(c)}" rpy="{_f(rpy)}"/><mass value="{m:.17g}"/>'
        f'<inertia ixx="{In[0, 0]:.17g}" ixy="{In[0, 1]:.17g}" ixz="{In[0, 2]:.17g}" '
        f'iyy="{In[1, 1]:.17g}" iyz="{In[1, 2]:.17g}" izz="{In[2, 2]:.17g}"/></inertial>'
    )


def random_robot(rng, n: int, p_mimic: float = 0.3, name: str = "rand") -> RandomRobot:
    """:func:`draw_robot` until Pinocchio can build it: its URDF parser numbers the joints depth
    first and refuses a mimic joint numbered before the joint it copies (on another branch)."""
    import pinocchio as pin

    for _ in range(100):
        rr = draw_robot(rng, n, p_mimic, name)
        try:
            pin.buildModelFromXML(rr.urdf, mimic=True)
        except Exception as exc:  # noqa: BLE001 - Pinocchio raises a plain ValueError/RuntimeError
            if "mimic" not in str(exc):
                raise
            continue
        return rr
    raise RuntimeError("no buildable random robot in 100 draws")


def draw_robot(rng, n: int, p_mimic: float = 0.3, name: str = "rand") -> RandomRobot:
    """A tree of ``n`` joints (``n >= 2``).  The first joint is independent; a mimic joint copies
    an earlier independent joint with the same number of configuration entries (Pinocchio's
    rule: revolute/prismatic copy revolute/prismatic, continuous copies continuous).  Joints are
    written parents first, each child link hung on the previous link (60 %) or on a random
    earlier link (a tree)."""
    links = ["base"]
    joints: list[RJoint] = []
    parts = []
    for k in range(n):
        parent = links[-1] if (rng.random() < 0.6 or len(links) == 1) else str(rng.choice(links))
        child = f"link{k}"
        jname = f"j{k}"
        sources = [j for j in joints if j.mimic is None]
        mimic = None
        if k > 0 and sources and rng.random() < p_mimic:
            src = sources[rng.integers(len(sources))]
            if src.kind == "continuous":
                kind = "continuous"
            else:
                kind = str(rng.choice(["revolute", "revolute", "prismatic"]))
            if rng.random() < 0.4:
                mult = float(rng.choice(MULTIPLIERS))
            else:
                mult = float(rng.choice([-1.0, 1.0]) * rng.uniform(0.3, 2.5))
            mimic = (src.name, mult, float(rng.uniform(-0.5, 0.5)))
        else:
            kind = str(rng.choice(["revolute", "revolute", "continuous", "prismatic"]))
        xyz = rng.uniform(-0.3, 0.3, 3)
        rpy = rng.uniform(-np.pi, np.pi, 3) if rng.random() < 0.7 else np.zeros(3)
        axis = _unit(rng)
        if kind == "revolute":
            lo, hi = -rng.uniform(0.5, 3.0), rng.uniform(0.5, 3.0)
            lim = f'<limit lower="{lo:.6f}" upper="{hi:.6f}" effort="50" velocity="5"/>'
        elif kind == "prismatic":
            lo, hi = -rng.uniform(0.05, 0.3), rng.uniform(0.05, 0.3)
            lim = f'<limit lower="{lo:.6f}" upper="{hi:.6f}" effort="50" velocity="1"/>'
        else:
            lim = '<limit effort="50" velocity="5"/>'
        mim = ""
        if mimic is not None:
            mim = (
                f'<mimic joint="{mimic[0]}" multiplier="{mimic[1]:.17g}" offset="{mimic[2]:.17g}"/>'
            )
        parts.append(f'<link name="{child}">{_inertial(rng)}</link>')
        parts.append(
            f'<joint name="{jname}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/><axis xyz="{_f(axis)}"/>{lim}{mim}</joint>'
        )
        joints.append(RJoint(jname, kind, parent, child, mimic))
        links.append(child)
    leaves = [ln for ln in links[1:] if not any(j.parent_link == ln for j in joints)]
    urdf = (
        f'<?xml version="1.0"?>\n<robot name="{name}">\n<link name="base"/>\n'
        + "\n".join(parts)
        + "\n</robot>\n"
    )
    return RandomRobot(name, urdf, joints, tool=leaves[-1])
