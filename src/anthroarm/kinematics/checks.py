"""Cross-check rows of the kinematics (robot providers of :mod:`anthroarm.crosscheck`).

:func:`rows`, for any robot, on random configurations inside the limits:

* the batched chain (``robot.fk(Q)`` / ``robot.jacobian(Q)`` with Q of shape (N, nq), i.e.
  :class:`~anthroarm.kinematics.batched.SerialChain`) against Pinocchio one configuration at a
  time (``pin.framesForwardKinematics``, ``pin.computeFrameJacobian`` LOCAL_WORLD_ALIGNED);
* yourdfpy's FK of every link against Pinocchio's, joints mapped by name (robots with a URDF;
  the first :data:`YOURDFPY_SAMPLES` configurations);
* for a book model as generated: the H-D chain Eq. (6-12)–(6-14) and the printed forms its
  spec declares (:func:`anthroarm.kinematics.book_fk.printed_forms`, defined in
  :mod:`anthroarm.models.printed`: (6-16)/(6-17), (6-21)–(6-23), 002 (4-52)–(4-54), the human
  arm (6-34)–(6-39) with its Jacobian, Fig. 7-14).

:func:`error_rows`, for any robot: §6-6 J_L (6-118) against finite differences over
Pinocchio models with perturbed placements, the batched perturbed FK
(:class:`~anthroarm.kinematics.error_propagation.PerturbedChain`) against Pinocchio on a
perturbed model, and (6-119) where the book prints it.

Positions and the linear Jacobian rows are divided by the robot's length scale (errors are
relative to arm length); rotations and angular rows are absolute.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..check_rows import CheckRow
from . import error_propagation as ep
from .book_fk import book_spec, printed_forms
from .dh import dh_fk, dh_jacobian

TOL = 1e-12
#: configurations of the yourdfpy row (the first of the check's): it checks how the URDF was read
#: (every joint's axis, origin and mimic), which a wrong reading fails on any configuration;
#: yourdfpy's own FK (trimesh's scene graph) takes ~0.3 ms a link, 2 s for 200 samples of the
#: 35-link limb
YOURDFPY_SAMPLES = 50
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _pose_err(Ta, Tb, scale) -> float:
    dp = np.abs(Ta[..., :3, 3] - Tb[..., :3, 3]).max() / scale
    dR = np.abs(Ta[..., :3, :3] - Tb[..., :3, :3]).max()
    return float(max(dp, dR))


def _jac_err(Ja, Jb, scale) -> float:
    return float(
        max(
            np.abs(Ja[..., :3, :] - Jb[..., :3, :]).max() / scale,
            np.abs(Ja[..., 3:, :] - Jb[..., 3:, :]).max(),
        )
    )


def _pinocchio(robot, Q):
    """Tool poses (N, 4, 4) and LWA Jacobians (N, 6, nv), one Pinocchio call per configuration."""
    model, data, fid = robot.model, robot.model.createData(), robot.tool_id
    T = np.empty((len(Q), 4, 4))
    J = np.empty((len(Q), 6, robot.nv))
    for i, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        T[i] = data.oMf[fid].homogeneous
        # Pinocchio gives (6,) for a one-joint model (Tug_of_War): keep (6, nv)
        J[i] = pin.computeFrameJacobian(model, data, q, fid, LWA).reshape(6, -1)
    return T, J


def _book_forms(robot):
    """(quantity, fk(Q) -> T batch, jac(Q) -> J batch or None) of the book's closed forms."""
    spec = book_spec(robot)
    if spec is None:
        return []
    out = []
    if spec.dh is not None:
        dh, tool = spec.dh, spec.tool_dh
        out.append(
            (
                "fk H-D chain (6-12)-(6-14)",
                lambda q: dh_fk(dh, q, tool),
                lambda q: dh_jacobian(dh, q, tool),
            )
        )
    p = spec.params
    for f in printed_forms(robot):
        jac = (lambda q, f=f: f.jacobian(q, p)) if f.jacobian is not None else None
        out.append((f"fk printed {f.equations}", lambda q, f=f: f.pose(q, p), jac))
    return out


def _yourdfpy_row(robot, Q, scale) -> CheckRow:
    if robot.info is None:
        return CheckRow.unsupported(
            robot.name, "fk yourdfpy (all links)", "loaded from a pin.Model: no URDF"
        )
    u = robot.urdf
    model, data = robot.model, robot.model.createData()
    links = {}  # link name -> its body frame (a joint frame may share the name: z1)
    for fid, f in enumerate(model.frames):
        if f.type == pin.FrameType.BODY and f.name in u.link_map:
            links.setdefault(f.name, fid)
    names = list(links)
    err = 0.0
    for q in Q:
        u.update_cfg(robot.yourdfpy_cfg(q))
        pin.framesForwardKinematics(model, data, q)
        for n, fid in links.items():
            err = max(
                err, _pose_err(u.get_transform(n, u.base_link), data.oMf[fid].homogeneous, scale)
            )
    note = f"{len(names)} links" + ("; mimic joints modelled by both" if robot.has_mimic else "")
    return CheckRow(robot.name, "fk yourdfpy (all links)", err, TOL, len(Q), "pinocchio", note)


def rows(robot, samples, rng) -> list[CheckRow]:
    """FK and Jacobian rows of one robot (see the module docstring)."""
    name, scale = robot.name, robot.length_scale
    Q = robot.random_q(samples, rng)
    T_pin, J_pin = _pinocchio(robot, Q)
    out = []
    for quantity, fk, jac in _book_forms(robot):
        out.append(CheckRow(name, quantity, _pose_err(fk(Q), T_pin, scale), TOL, samples))
        if jac is not None:
            out.append(
                CheckRow(
                    name,
                    quantity.replace("fk", "jacobian", 1) + " LWA",
                    _jac_err(jac(Q), J_pin, scale),
                    TOL,
                    samples,
                )
            )
    out.append(
        CheckRow(
            name, "fk batched chain robot.fk(Q)", _pose_err(robot.fk(Q), T_pin, scale), TOL, samples
        )
    )
    out.append(
        CheckRow(
            name,
            "jacobian batched chain LWA",
            _jac_err(robot.jacobian(Q), J_pin, scale),
            TOL,
            samples,
        )
    )
    out.append(_yourdfpy_row(robot, Q[:YOURDFPY_SAMPLES], scale))
    return out


def error_rows(robot, samples, rng) -> list[CheckRow]:
    """§6-6 error-propagation rows of one robot (see the module docstring)."""
    n = max(1, min(int(samples), 5))
    name, scale = robot.name, robot.length_scale
    Q = robot.random_q(n, rng)
    e_jl = max(
        np.abs(
            ep.length_jacobian(robot, q, mode="components")
            - ep.length_jacobian_fd(robot, q, mode="components")
        ).max()
        for q in Q
    )
    out = [CheckRow(name, "J_L (6-118) vs FD of perturbed placements", float(e_jl), 1e-10, n)]
    chain = ep.PerturbedChain(robot, mode="components")
    dL = 0.01 * scale * rng.standard_normal((n, len(chain.params)))
    R, x = chain.pose(Q, dL)
    err = 0.0
    for i, q in enumerate(Q):
        m = robot.model
        for p, d in zip(chain.params, dL[i]):
            m = ep._perturbed_model(m, p, d)
        d_ = m.createData()
        pin.framesForwardKinematics(m, d_, q)
        M = d_.oMf[robot.tool_id]
        err = max(err, np.abs(x[i] - M.translation).max() / scale, np.abs(R[i] - M.rotation).max())
    out.append(
        CheckRow(name, "perturbed FK T(q, L+dL) vs pin on the perturbed model", float(err), TOL, n)
    )
    for f in printed_forms(robot):
        p = book_spec(robot).params
        if f.length_jacobian is not None:
            e = max(
                np.abs(f.length_jacobian(q, p) - ep.length_jacobian_fd(robot, q)[:3]).max()
                for q in Q
            )
            out.append(CheckRow(name, "(6-119) vs FD of perturbed placements", float(e), 1e-10, n))
    return out
