"""``anthroarm urdf model.osim``: the URDF of an OpenSim model where a plain URDF can represent
it (the run: :mod:`.urdf_run`).

The Pinocchio model the import built (:func:`anthroarm.osim.load_osim`) is written out: one
URDF joint per Pinocchio joint (``revolute``/``prismatic`` about its axis, placed by its joint
placement, its coordinate's range), one link per joint carrying the joint's body inertia, and
every OpenSim body, marker and offset frame as a massless link of the same name on a ``fixed``
joint (``<frame>_fixed``) — so ``aa.load`` of the URDF finds the same frames at the same poses.
A URDF joint is one value (or a linear ``mimic`` of another), so a model whose Pinocchio joints
are nonlinear functions of its coordinates (``robot.coupling``: a spline knee, a coupler
constraint, a scaled axis) cannot be written: :class:`~anthroarm.errors.UnsupportedModelError`
names the joints and the coordinates they follow.

A URDF has no gravity: OpenSim's (``<gravity>``, usually along −y) is the loaded model's
``model.gravity``, and ``anthroarm urdf`` prints it; set it on the URDF's robot after loading.

URDF: the ROS ``urdf`` XML specification (wiki.ros.org/urdf/XML); the inertia is given about
the centre of mass in the link frame, as Pinocchio's ``Inertia`` stores it.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

import numpy as np
import pinocchio as pin

from ..errors import UnsupportedModelError

KINDS = {
    "JointModelRevoluteUnaligned": "revolute",
    "JointModelRX": "revolute",
    "JointModelRY": "revolute",
    "JointModelRZ": "revolute",
    "JointModelPrismaticUnaligned": "prismatic",
    "JointModelPX": "prismatic",
    "JointModelPY": "prismatic",
    "JointModelPZ": "prismatic",
}
AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def _num(x: float) -> str:
    return repr(float(x))


def _origin(M: pin.SE3) -> str:
    xyz = " ".join(_num(v) for v in M.translation)
    rpy = " ".join(_num(v) for v in pin.rpy.matrixToRpy(M.rotation))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def _axis(jm) -> tuple:
    name = jm.shortname()
    if name.endswith("Unaligned"):
        return tuple(float(a) for a in jm.extract().axis)
    return AXES[name[-1]]


def osim_urdf_text(robot) -> str:
    """The URDF text of an imported OpenSim model without nonlinear couplings (see the module
    docstring).

    Raises
    ------
    UnsupportedModelError
        ``robot.coupling`` is set (the joints it makes functions of the coordinates are named),
        or a Pinocchio joint is of a kind a URDF joint cannot be (the kind is named).
    """
    c = getattr(robot, "coupling", None)
    if c is not None:
        raise UnsupportedModelError(
            f"{robot.name}: a plain URDF cannot represent this model: its {c.nq_full} "
            f"Pinocchio joints are functions phi(q) of its {c.nq} coordinates "
            f"({', '.join(_coupled(robot))} follow other coordinates through splines or "
            "couplers, and a URDF joint is one value or a linear mimic); use the .osim file "
            "itself (aa.load) or lock the coupled coordinates in OpenSim"
        )
    model = robot.model
    lines = [f"<robot name={quoteattr(robot.name)}>", '  <link name="root"/>']
    link = {0: "root"}
    for i in range(1, model.njoints):
        jm, name = model.joints[i], model.names[i]
        kind = KINDS.get(jm.shortname())
        if kind is None:
            raise UnsupportedModelError(
                f"{robot.name}: joint {name!r} is a Pinocchio {jm.shortname()}, which a URDF "
                "joint cannot be"
            )
        link[i] = f"{name}_link"
        Y = model.inertias[i]
        I = Y.inertia
        inertial = (
            f'<inertial><origin xyz="{" ".join(_num(v) for v in Y.lever)}" rpy="0 0 0"/>'
            f'<mass value="{_num(Y.mass)}"/><inertia ixx="{_num(I[0, 0])}" '
            f'ixy="{_num(I[0, 1])}" ixz="{_num(I[0, 2])}" iyy="{_num(I[1, 1])}" '
            f'iyz="{_num(I[1, 2])}" izz="{_num(I[2, 2])}"/></inertial>'
        )
        lines.append(f"  <link name={quoteattr(link[i])}>{inertial}</link>")
        q = jm.idx_q
        axis = " ".join(_num(a) for a in _axis(jm))
        lines.append(
            f"  <joint name={quoteattr(name)} type={quoteattr(kind)}>"
            f"<parent link={quoteattr(link[model.parents[i]])}/>"
            f"<child link={quoteattr(link[i])}/>{_origin(model.jointPlacements[i])}"
            f'<axis xyz="{axis}"/><limit lower="{_num(model.lowerPositionLimit[q])}" '
            f'upper="{_num(model.upperPositionLimit[q])}" '
            f'effort="{_num(model.effortLimit[jm.idx_v])}" '
            f'velocity="{_num(model.velocityLimit[jm.idx_v])}"/></joint>'
        )
    for f in model.frames:
        if f.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
            continue
        lines.append(f"  <link name={quoteattr(f.name)}/>")
        lines.append(
            f'  <joint name={quoteattr(f.name + "_fixed")} type="fixed">'
            f"<parent link={quoteattr(link[f.parentJoint])}/><child link={quoteattr(f.name)}/>"
            f"{_origin(f.placement)}</joint>"
        )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def _coupled(robot) -> list[str]:
    """The Pinocchio joints that are not one coordinate as it is (f(x) = x)."""
    c = robot.coupling
    q = np.array(c.default, dtype=float)
    phi, G = c.jacobian(q)
    out = []
    for k in range(c.nq_full):
        col = np.flatnonzero(np.abs(G[k]) > 0)
        i = int(col[0]) if len(col) == 1 else -1
        if not (i >= 0 and abs(G[k, i] - 1.0) < 1e-12 and abs(phi[k] - q[i]) < 1e-12):
            out.append(robot.model.names[k + 1])
    return out
