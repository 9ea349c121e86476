"""Cross-check rows of the kinematics (a provider of :mod:`anthroarm.crosscheck`).

For every model, on random configurations inside the joint limits:
* the book's closed forms (H-D chain Eq. (6-12)–(6-14); the printed hand poses (6-16)/(6-17),
  (6-21)–(6-23), 002 (4-52)–(4-54), the human arm (6-34)–(6-39); Fig. 7-14) against
  ``pin.framesForwardKinematics``;
* their Jacobians ((6-24)–(6-29) in vector form) against ``pin.computeFrameJacobian``
  (LOCAL_WORLD_ALIGNED);
* the generic batched chain (:class:`~anthroarm.kinematics.batched.SerialChain`) for every model;
* yourdfpy's FK of every link against Pinocchio's, joints mapped by name.

Positions and the linear Jacobian rows are divided by the model's length scale (errors are
relative to arm length); rotations and angular rows are absolute.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..crosscheck import CheckRow
from . import closed_forms as cf
from .batched import SerialChain
from .dh import dh_fk, dh_jacobian

TOL = 1e-12


def _pose_err(Ta, Tb, scale) -> float:
    dp = np.abs(Ta[..., :3, 3] - Tb[..., :3, 3]).max() / scale
    dR = np.abs(Ta[..., :3, :3] - Tb[..., :3, :3]).max()
    return float(max(dp, dR))


def _jac_err(Ja, Jb, scale) -> float:
    return float(max(np.abs(Ja[..., :3, :] - Jb[..., :3, :]).max() / scale, np.abs(Ja[..., 3:, :] - Jb[..., 3:, :]).max()))


def _closed_forms(robot):
    """(quantity, fk(q) -> T batch, jac(q) -> J batch or None) of the book's closed forms."""
    p = robot.spec.params if robot.spec is not None else {}
    name = robot.name
    out = []
    if robot.spec is not None and robot.spec.dh is not None:
        rows, tool = robot.spec.dh, robot.spec.tool_dh
        out.append(("fk H-D chain (6-12)-(6-14)", lambda q: dh_fk(rows, q, tool), lambda q: dh_jacobian(rows, q, tool)))
    if name == "sixr_arm":
        out.append(("fk printed (6-16)/(6-17)", lambda q: cf.sixr_hand_pose(q, p["s0"], p["h2"], p["s3"], p["P"]), None))
    if name == "unimate5":
        out.append(("fk printed (6-21)-(6-23)", lambda q: cf.unimate_hand_pose(q, p["s0"], p["h2"], p["P"]), None))
    if name == "rrprr5":
        out.append(("fk printed 002 (4-52)-(4-54)", lambda q: cf.rrprr_hand_pose(q, p["s0"], p["h2"], p["p"]), None))
    if name == "human_arm7":
        L = (p["l1"], p["l2"], p["l3"])
        out.append(("fk printed (6-34)-(6-39)", lambda q: cf.human_arm7_hand_pose(q, *L), lambda q: cf.human_arm7_jacobian(q, *L)))
    if name == "planar2r":
        def tip(q):
            # printed position (y, z); both hinges are about x, so the tip frame is Rx(θ1+θ2)
            yz = cf.planar2r_tip(q, p["l1"], p["l2"])
            t = np.atleast_2d(q).sum(axis=-1)
            T = np.zeros(t.shape + (4, 4))
            T[..., 0, 0] = T[..., 3, 3] = 1.0
            T[..., 1, 1] = T[..., 2, 2] = np.cos(t)
            T[..., 2, 1], T[..., 1, 2] = np.sin(t), -np.sin(t)
            T[..., 1, 3], T[..., 2, 3] = np.atleast_2d(yz)[..., 0], np.atleast_2d(yz)[..., 1]
            return T
        out.append(("fk printed Fig. 7-14 (y, z)", tip, None))
    return out


def _yourdfpy_rows(robot, Q, scale) -> CheckRow:
    u = robot.urdf
    model, data = robot.model, robot.data
    names = [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.name in u.link_map]
    fids = [model.getFrameId(n) for n in names]
    err = 0.0
    for q in Q:
        u.update_cfg(robot.yourdfpy_cfg(q))
        pin.framesForwardKinematics(model, data, q)
        for n, fid in zip(names, fids):
            err = max(err, _pose_err(u.get_transform(n, u.base_link), data.oMf[fid].homogeneous, scale))
    note = f"{len(names)} links" + ("; mimic joints modelled by both" if robot.has_mimic else "")
    return CheckRow(robot.name, "fk yourdfpy (all links)", err, TOL, len(Q), "pinocchio", note)


def rows(models, samples, rng) -> list[CheckRow]:
    import anthroarm as aa

    out = []
    for name in models:
        robot = aa.load(name)
        scale = robot.length_scale
        Q = robot.random_q(samples, rng)
        T_pin = robot.fk(Q)
        J_pin = robot.jacobian(Q)
        for quantity, fk, jac in _closed_forms(robot):
            out.append(CheckRow(name, quantity, _pose_err(fk(Q), T_pin, scale), TOL, samples))
            if jac is not None:
                out.append(CheckRow(name, quantity.replace("fk", "jacobian", 1) + " LWA", _jac_err(jac(Q), J_pin, scale), TOL, samples))
        chain = SerialChain.of(robot)
        T_c, J_c = chain.fk_jacobian(Q)
        out.append(CheckRow(name, "fk serial chain (batched)", _pose_err(T_c, T_pin, scale), TOL, samples))
        out.append(CheckRow(name, "jacobian serial chain LWA", _jac_err(J_c, J_pin, scale), TOL, samples))
        out.append(_yourdfpy_rows(robot, Q, scale))
    return out
