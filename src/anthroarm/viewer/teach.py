"""Joint sliders on the page (:meth:`TeachMixin.teach`, like Robotics Toolbox's ``teach``): the
``anthroarm_ui`` "teach" spec carries ``robot.chain`` (joint placements, axes, mimic relations),
the sliders and the bodies to move, so the page computes the forward kinematics itself — in a
live tab, a Jupyter cell or an exported HTML file alike.

:class:`TeachMixin` is one part of :class:`~anthroarm.viewer.Viewer`.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ViewerError
from .colors import LIMIT_RGB, LIMIT_WARN
from .messages import delete, ui


class TeachMixin:
    """Joint sliders with the page's own forward kinematics (a part of
    :class:`~anthroarm.viewer.Viewer`)."""

    def teach(self, on: bool = True, q=None):
        """Joint sliders on the page (like Robotics Toolbox's ``teach``): one per independent
        joint, in degrees (mm for a prismatic joint) within its limits (continuous or unbounded
        revolute joints ±180°); mimic joints follow their source.  Dragging a slider moves the
        robot at once, in a live tab, a Jupyter cell or an exported HTML file alike: the page
        computes the forward kinematics of ``robot.chain`` itself (the joint placements, axes
        and mimic relations sent with the sliders; tested against Pinocchio in a real browser),
        and shows the tool's position (mm) and roll, pitch, yaw (°, Pinocchio's ``rpy``
        convention) in the robot's base frame under the sliders.  With
        :meth:`~Viewer.show_limits` on, the links turn red as the sliders approach a limit.

        The sliders start at ``q`` (default: the configuration displayed now).  ``on=False``
        removes them.  The Python side is not told of the page's slider positions: call
        :meth:`~Viewer.display` to show a configuration from Python.  Each slider has a number
        box to type a value in, and shows the joint's full name on hover; while the panel is
        open, the 3-D view takes the rest of the page and the camera frames the robot for that
        narrower view.  Returns the viewer."""
        path = f"{self.root}/ui/teach"
        self._teaching = bool(on)
        if not on:
            self._send([delete(path)])
            self._refit()
            return self
        if q is not None or self._animating:
            self.display(self.q if q is None else q)
        self._send([ui(path, self._teach_spec())])
        self._refit()
        return self

    def _refit(self) -> None:
        """Frame again for the pane beside (or without) the panel, unless placed by hand."""
        cam = self._camera
        if cam is not None and cam["distance"] is None:
            self.set_camera(**cam)

    def _teach_spec(self) -> dict:
        chain = self.robot.chain
        theta = self.robot.angles(self.q)  # every Pinocchio joint (φ(q) for an OpenSim model)
        joints, sliders = [], []
        for j in chain.joints:
            m = j.mimic
            joints.append(
                {
                    "parent": int(j.parent),
                    "kind": j.kind,
                    "axis": [float(a) for a in j.axis],
                    "placement": [float(x) for x in j.placement.ravel()],
                    "src": -1 if m is None else int(m.source),
                    "mult": 1.0 if m is None else float(m.multiplier),
                    "off": 0.0 if m is None else float(m.offset),
                }
            )
            if m is not None:
                continue
            if j.kind == "prismatic":
                lo, hi = (
                    (j.lower, j.upper)
                    if np.isfinite(j.lower) and np.isfinite(j.upper)
                    else (-0.5 * self.robot.length_scale, 0.5 * self.robot.length_scale)
                )
                scale, unit, lo, hi, value = 1e-3, "mm", 1e3 * lo, 1e3 * hi, 1e3 * theta[j.index]
            else:
                lo, hi = (
                    (j.lower, j.upper)
                    if (
                        j.kind != "continuous"
                        and np.isfinite(j.lower)
                        and np.isfinite(j.upper)
                        and j.upper - j.lower <= 2 * math.pi + 1e-9
                    )
                    else (-math.pi, math.pi)
                )
                scale, unit, lo, hi, value = (
                    math.pi / 180,
                    "°",
                    math.degrees(lo),
                    math.degrees(hi),
                    math.degrees(theta[j.index]),
                )
            # on the slider's own grid (min + k·step, step 0.1): the browser snaps a value to it
            lo, hi = math.ceil(lo * 10 - 1e-6) / 10, math.floor(hi * 10 + 1e-6) / 10
            value = min(max(round(value * 10) / 10, lo), hi)
            sliders.append(
                {
                    "joint": int(j.index),
                    "name": j.name,
                    "min": lo,
                    "max": hi,
                    "step": 0.1,
                    "value": value,
                    "unit": unit,
                    "scale": scale,
                    "digits": 1,
                }
            )
            theta[j.index] = value * scale  # the page starts where its sliders are
        if getattr(self.robot, "coupling", None) is not None:
            joints, sliders, theta = coupled_sliders(self.robot, self.q, joints)
        movers = []
        for path, jid, fid in self._moving():
            if jid is not None:
                movers.append({"path": path, "joint": jid - 1})
            else:
                f = chain.frames[fid]
                movers.append(
                    {
                        "path": path,
                        "joint": int(f.joint),
                        "offset": [float(x) for x in f.placement.ravel()],
                    }
                )
        tool = chain.frames[self.robot.tool_id]
        limits = None
        if self._limits_on:  # the page recolours like _color_commands: same groups, same blend
            groups = []
            for b in self.bodies:
                has = {pc.group for pc in b.pieces}
                link_group = "links" if "links" in has else "mesh"
                for group, idx in (
                    (link_group, b.link_joints),
                    ("joint", [b.limit_joint] if b.limit_joint is not None else []),
                ):
                    if idx and group in has:
                        base = next(pc.rgb for pc in b.pieces if pc.group == group)
                        groups.append(
                            {
                                "path": f"{self._bpath(b)}/{group}",
                                "joints": [int(i) for i in idx],
                                "base": [float(c) for c in base],
                            }
                        )
            fin = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731 - msgpack has no inf
            limits = {
                "lower": [fin(x) for x in self._joint_lower],
                "upper": [fin(x) for x in self._joint_upper],
                "warn": LIMIT_WARN,
                "red": list(LIMIT_RGB),
                "groups": groups,
            }
        return {
            "kind": "teach",
            "title": f"{self.robot.name}: joints",
            "theta": [float(t) for t in theta],
            "joints": joints,
            "sliders": sliders,
            "movers": movers,
            "tool": {
                "name": tool.name,
                "joint": int(tool.joint),
                "offset": [float(x) for x in tool.placement.ravel()],
            },
            "limits": limits,
        }


TABLE_POINTS = 257  # samples of a nonlinear φ_k over its coordinate's range (the page interpolates)


def coupled_sliders(robot, q, joints):
    """Teach sliders of an OpenSim model with nonlinear couplings (``robot.coupling``): one per
    independent coordinate (named after it, within its range; mm for a translation), held in
    ``theta`` after the Pinocchio joints; each Pinocchio joint follows its coordinate as a
    linear relation (``mult``, ``off``: exact) or, for a spline or coupler, as a table of
    :data:`TABLE_POINTS` samples of φ_k over the coordinate's range that the page interpolates
    linearly (gait2392's knee translations: within 3.3e-7 m of the spline).  Returns
    ``(joints, sliders, theta)``."""
    c = robot.coupling
    n = len(joints)
    q = np.asarray(q, dtype=float)
    # which coordinate moves each Pinocchio joint: G's non-zero column on a few states
    Qs = np.vstack([q, robot.random_q(8, rng=0)])
    _, G = c.jacobian(Qs)
    moved = np.abs(G).max(axis=0) > 0  # (nq_full, nq)
    chain = robot.chain
    by_name = {j.name: j for j in chain.joints}
    out = []
    for k, spec in enumerate(joints):
        spec = dict(spec)
        cols = np.flatnonzero(moved[k])
        if len(cols) == 0:  # held (a locked coordinate's function): keeps its value
            spec.update(src=-1, mult=1.0, off=0.0)
            out.append(spec)
            continue
        if len(cols) > 1:
            raise ViewerError(
                f"{robot.name}: joint {chain.joints[k].name!r} depends on several coordinates; "
                "the teach sliders cannot drive it"
            )
        i = int(cols[0])
        xs = np.linspace(c.lower[i], c.upper[i], TABLE_POINTS)
        Q = np.repeat(q[None], TABLE_POINTS, axis=0)
        Q[:, i] = xs
        ys = c.full(Q)[:, k]
        mult = (ys[-1] - ys[0]) / (xs[-1] - xs[0]) if xs[-1] > xs[0] else 0.0
        off = ys[0] - mult * xs[0]
        spec.update(src=n + i, mult=float(mult), off=float(off))
        if np.abs(mult * xs + off - ys).max() > 1e-12:  # nonlinear: the sampled table
            spec["xs"] = [float(x) for x in xs]
            spec["ys"] = [float(y) for y in ys]
        out.append(spec)
    sliders = []
    for i, name in enumerate(c.names):
        j = by_name.get(name)  # the coordinate's own joint, else the first joint it moves
        if j is None and moved[:, i].any():
            j = chain.joints[int(np.flatnonzero(moved[:, i])[0])]
        prismatic = j is not None and j.kind == "prismatic"
        scale, unit = (1e-3, "mm") if prismatic else (math.pi / 180, "°")
        lo, hi = c.lower[i] / scale, c.upper[i] / scale
        lo, hi = math.ceil(lo * 10 - 1e-6) / 10, math.floor(hi * 10 + 1e-6) / 10
        value = min(max(round(q[i] / scale * 10) / 10, lo), hi)
        sliders.append(
            {
                "joint": n + i,
                "name": name,
                "min": lo,
                "max": hi,
                "step": 0.1,
                "value": value,
                "unit": unit,
                "scale": scale,
                "digits": 1,
            }
        )
    qs = np.array([s["value"] * s["scale"] for s in sliders])  # the page starts at its sliders
    theta = np.concatenate([c.full(qs), qs])
    return out, sliders, theta
