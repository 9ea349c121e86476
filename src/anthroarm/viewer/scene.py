"""The scene of a :class:`~anthroarm.viewer.Viewer`: the robot's bodies and their poses, the
framing (centre, camera, floor) and the guides (grid, world axes, scale bar), and
:class:`Scene`, meshcat's own ``Visualizer`` API on the Viewer's channel.

:class:`SceneMixin` is one part of :class:`~anthroarm.viewer.Viewer` (with
:class:`~anthroarm.viewer.overlays.OverlaysMixin`, :class:`~anthroarm.viewer.teach.TeachMixin`,
:class:`~anthroarm.viewer.export.ExportMixin` and :class:`~anthroarm.viewer.live.LiveMixin`);
the parts share the Viewer's state, set in ``Viewer.__init__``.
"""

from __future__ import annotations

import math

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from meshcat.commands import SetProperty
from meshcat.path import Path as MeshcatPath
from meshcat.visualizer import Visualizer

from ..errors import ParameterError, ViewerError
from ..spatial.rotations import homogeneous
from .checks import points3, rgb255
from .framing import (
    ANIMATION_SAMPLES,
    EXTENT_POINTS,
    HAND_ZOOM_RATIO,
    TEACH_ASPECT,
    body_joint,
    box_diagonal,
    check_fit,
    framing_distance,
    hand_joints,
    view_direction,
)
from .messages import (
    delete,
    safe_name,
    set_object,
    set_property,
    set_transform,
    stop_animation,
    ui,
)
from .shapes import Body, box_corners, cylinder_between, local_corners, triad, y_to


def pinocchio_q(robot, q) -> np.ndarray:
    """Pinocchio's configuration of ``robot`` at ``q``: φ(q) for an OpenSim model whose joints
    are functions of its coordinates (``robot.coupling``, :mod:`anthroarm.osim.coupling`), q
    itself otherwise.  Works row-wise on a batch."""
    c = getattr(robot, "coupling", None)
    return q if c is None else c.full(q)


def nice_length(x: float) -> float:
    """The largest of 1, 2, 5 × 10^k metres not above ``x`` (> 0): grid spacings, scale bars."""
    k = math.floor(math.log10(x))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**k <= x * (1 + 1e-9):
            return m * 10.0**k
    return 10.0**k  # pragma: no cover - unreachable


def format_length(x: float) -> str:
    """``0.05`` -> ``'5 cm'``, ``0.002`` -> ``'2 mm'``, ``2.0`` -> ``'2 m'``."""
    for unit, f in (("m", 1.0), ("cm", 100.0), ("mm", 1000.0)):
        if x * f >= 1 - 1e-9:
            return f"{x * f:.3g} {unit}"
    return f"{x * 1000:.3g} mm"


class SceneWindow:
    """What a meshcat :class:`~meshcat.visualizer.Visualizer` sends its commands through: here
    the Viewer's own channel (its in-memory scene and, when live, its server)."""

    def __init__(self, viewer):
        self._viewer = viewer

    @property
    def web_url(self):
        return self._viewer.url

    def send(self, command) -> None:
        self._viewer._send([command.lower()])

    def open(self):
        self._viewer.open()
        return self

    def wait(self):
        self._viewer.wait()

    def get_scene(self) -> str:
        return self._viewer.static_html()

    def get_image(self):
        raise ViewerError(
            "image capture is not supported by the anthroarm viewer; use "
            "anthroarm.viewer.browser.screenshot on export_html()"
        )

    def close(self) -> None:
        self._viewer.close()


class Scene(Visualizer):
    """meshcat's :class:`~meshcat.visualizer.Visualizer` API on the scene of a :class:`Viewer`
    (:attr:`Viewer.scene <anthroarm.viewer.scene.SceneMixin.scene>`):
    ``scene["name"].set_object(geometry, material)``, ``set_transform``, ``set_property``,
    ``delete``, plus :meth:`set_cam_pos`.  Paths start at ``/meshcat`` (absolute paths such as
    ``"/Grid"`` or ``"/Cameras/default"`` address meshcat's own nodes).  Everything sent
    through it is kept in the static HTML export and reaches a live browser."""

    __slots__ = ()

    def __getitem__(self, path):
        vis = Scene(window=self.window)
        vis.path = self.path.append(path)
        return vis

    def set_cam_pos(self, position) -> None:
        """Place the camera at ``position`` (3-vector, m) in meshcat's world frame (z up); it
        keeps looking at the orbit target, the world origin (where the Viewer puts the centre
        of the robot's reach)."""
        x, y, z = (float(c) for c in points3(position, "camera position")[0])
        self.window.send(
            SetProperty(
                "position", [x, z, -y], MeshcatPath(("Cameras", "default", "rotated", "<object>"))
            )
        )

    def __repr__(self) -> str:
        return f"<anthroarm Scene at {self.path.lower()} of {self.window._viewer!r}>"


class SceneMixin:
    """The robot in the scene: its bodies and poses, the camera and the guides (a part of
    :class:`~anthroarm.viewer.Viewer`)."""

    def _bpath(self, body: Body, prefix: str = "bodies") -> str:
        return f"{self.root}/{prefix}/{safe_name(body.name)}"

    def _body_objects(self, bodies, prefix="bodies") -> list[dict]:
        cmds = []
        for b in bodies:
            bp = self._bpath(b, prefix)
            for k, p in enumerate(b.pieces):
                path = f"{bp}/{p.group}/{k}"
                cmds.append(set_object(path, p.geometry, p.rgb, p.opacity))
                if not np.allclose(p.offset, np.eye(4)):
                    cmds.append(set_transform(path, p.offset))
        return cmds

    def _frame_scene(self, background, grid: bool, axes: bool, scale_bar: bool) -> None:
        """Centre the robot on meshcat's orbit target, place the camera, the floor and the
        guides (grid, world axes, scale bar)."""
        robot = self.robot
        model, data = robot.model, robot.data
        tips = {robot.chain.frame(t).index for t in robot.chain.tips} | {robot.tool_id}

        def points(Q):
            pts = []
            for qi in Q:
                pin.framesForwardKinematics(model, data, pinocchio_q(robot, qi))
                pts.extend(np.array(data.oMi[j.index + 1].translation) for j in robot.chain.joints)
                pts.extend(np.array(data.oMf[f].translation) for f in tips)
            return np.asarray(pts + [np.zeros(3)])

        reach = points(robot.random_q(128, rng=0))  # the workspace: sizes and the floor
        lo, hi = reach.min(0), reach.max(0)
        mid = 0.5 * (lo + hi)
        self.radius = float(
            max(np.linalg.norm(reach - mid, axis=1).max(), 0.1 * robot.length_scale, 1e-3)
        )
        # the framing: the robot as first displayed (its drawn pieces, joints and tips)
        pose = np.vstack([points(self.q[None]), self._piece_corners(self.q)])
        blo, bhi = pose.min(0), pose.max(0)
        self.center = 0.5 * (blo + bhi)
        self._reach_corners = box_corners(lo, hi)
        self._frame_corners = box_corners(blo, bhi)
        cmds = [set_transform(self.root, homogeneous(r=-self.center))]
        self.floor = floor = min(0.0, float(lo[2]), float(blo[2])) - 0.01  # base frame, under all
        cmds.append(
            set_property("/Grid", "visible", False)
        )  # meshcat's 20 m grid: ours fits the robot
        cmds.append(set_property("/Axes", "visible", False))
        # a translucent floor disc under the reach (always drawn; robust in software WebGL)
        rf = 0.9 * self.radius
        disc = mg.Cylinder(0.004 * rf, rf)
        cmds.append(set_object(f"{self.root}/floor", disc, (0.80, 0.83, 0.88), 0.4))
        cmds.append(
            set_transform(
                f"{self.root}/floor", homogeneous(y_to([0, 0, 1]), [mid[0], mid[1], floor])
            )
        )
        if background is None:
            cmds.append(set_property("/Background", "visible", False))
        else:
            top, bottom = background
            cmds.append(set_property("/Background", "top_color", [int(c) for c in top]))
            cmds.append(set_property("/Background", "bottom_color", [int(c) for c in bottom]))
        self._send(cmds)
        self._guides(mid, rf)
        self.set_grid(grid)
        self.set_axes(axes)
        self.set_scale_bar(scale_bar)
        self.set_camera()

    def _piece_corners(self, q, joints=None) -> np.ndarray:
        """Corners (K, 3), base frame, of the local bounding boxes of every drawn piece at ``q``
        (mesh files sent as they are have no bounds here and are skipped); only the bodies
        moved by one of ``joints`` (chain indices) when given."""
        model, data = self.robot.model, self.robot.data
        pin.framesForwardKinematics(model, data, pinocchio_q(self.robot, q))
        out = [np.zeros((0, 3))]
        for b in self.bodies:
            if joints is not None and body_joint(self.robot.chain, b) not in joints:
                continue
            M = (
                np.eye(4)
                if b.joint is None and b.frame is None
                else (
                    data.oMi[b.joint + 1].homogeneous
                    if b.joint is not None
                    else data.oMf[b.frame].homogeneous
                )
            )
            for pc in b.pieces:
                c = local_corners(pc.geometry)
                if c is not None:
                    A = M @ pc.offset
                    out.append(c @ A[:3, :3].T + A[:3, 3])
        return np.vstack(out)

    def _guides(self, mid, rf: float) -> None:
        """Grid lines on the floor (``spacing`` m apart, through the base origin), a world-axes
        triad at the base origin, a scale bar ``spacing`` long on the floor in front of the robot
        (the default camera's side)."""
        self.spacing = sp = nice_length(2 * rf / 10)
        n0 = np.floor((mid[:2] - rf) / sp).astype(int)
        n1 = np.ceil((mid[:2] + rf) / sp).astype(int)
        xs, ys = sp * np.arange(n0[0], n1[0] + 1), sp * np.arange(n0[1], n1[1] + 1)
        z = self.floor + 0.002 * rf
        segs = [[(x, ys[0], z), (x, ys[-1], z)] for x in xs] + [
            [(xs[0], y, z), (xs[-1], y, z)] for y in ys
        ]
        P = np.asarray(segs, np.float32).reshape(-1, 3)
        grid = mg.LineSegments(
            mg.PointsGeometry(P.T),
            mg.LineBasicMaterial(color=0x7D8899, opacity=0.6, transparent=True),
        )
        cmds = [set_object(f"{self.root}/grid", grid)]
        size = 0.15 * self.radius
        for k, piece in enumerate(triad(size, 0.04 * size)):
            path = f"{self.root}/axes/{k}"
            cmds += [
                set_object(path, piece.geometry, piece.rgb),
                set_transform(path, piece.offset),
            ]
        # the scale bar: `spacing` long, alternating dark and light fifths, at the grid's front-left
        corner = self._frame_corners.max(0)[:2]  # on the camera's side of the robot, on grid lines
        a = np.array(
            [sp * (np.floor(corner[0] / sp) - 1), sp * np.floor(corner[1] / sp), z + 0.006 * rf]
        )
        for k in range(5):
            p0, p1 = a + [k * sp / 5, 0, 0], a + [(k + 1) * sp / 5, 0, 0]
            for piece in cylinder_between(
                p0, p1, 0.012 * rf, (0.1, 0.1, 0.12) if k % 2 == 0 else (0.97, 0.97, 0.97)
            ):
                path = f"{self.root}/scale/{k}"
                cmds += [
                    set_object(path, piece.geometry, piece.rgb),
                    set_transform(path, piece.offset),
                ]
        self._send(cmds)

    def set_grid(self, visible: bool = True) -> None:
        """Show or hide the floor grid (lines ``viewer.spacing`` m apart through the base origin)."""
        self._send([set_property(f"{self.root}/grid", "visible", bool(visible))])

    def set_axes(self, visible: bool = True) -> None:
        """Show or hide the world axes at the robot's base origin (x red, y green, z blue)."""
        self._send([set_property(f"{self.root}/axes", "visible", bool(visible))])

    def set_scale_bar(self, visible: bool = True) -> None:
        """Show or hide the scale bar on the floor and its note (its length = the grid spacing)."""
        cmds = [set_property(f"{self.root}/scale", "visible", bool(visible))]
        note = f"{self.root}/ui/scale"
        if visible:
            cmds.append(
                ui(
                    note,
                    {
                        "kind": "note",
                        "text": f"scale bar and grid squares: {format_length(self.spacing)}",
                    },
                )
            )
        else:
            cmds.append(delete(note))
        self._send(cmds)

    # ------------------------------------------------------------------ scene settings
    def set_camera(
        self,
        direction="iso",
        distance: float | None = None,
        fill: float = 0.85,
        fit: str = "auto",
    ) -> None:
        """Frame ``fit`` seen from ``direction``, at ``distance`` m (default: where it fills
        ``fill`` of the view).

        Parameters
        ----------
        direction : str or array_like
            A named view, ``"iso"`` (front-left-above, the default), ``"front"`` (from +x),
            ``"back"``, ``"side"`` (from +y) or ``"top"``, or a 3-vector from the subject to
            the camera (base-frame axes).
        distance : float, optional
            Camera distance from the subject's centre, m.  Default: the distance at which the
            subject's box fills ``fill`` of meshcat's 75° vertical field of view and of the
            horizontal one of a 4:3 view
            (:func:`~anthroarm.viewer.framing.framing_distance`): the camera is outside it.
        fill : float
            In [0.1, 1].
        fit : {"auto", "pose", "all", "reach", "hand"}
            The subject (:mod:`anthroarm.viewer.framing`): the robot as displayed now, with
            everything drawn around it (points, maps, targets, traces, an animation's poses),
            its workspace, or its hand; ``"auto"`` zooms on the hand of a limb when nothing else
            is drawn, else frames ``"all"``.  The subject's centre becomes the orbit target
            (``viewer.center``, base frame).

        While ``distance`` is None and ``fit`` is ``"auto"`` or ``"all"``, the framing follows
        what is drawn: each overlay and :meth:`~Viewer.play` re-frames the scene.

        Raises
        ------
        ParameterError
            An unknown view or fit, a zero or non-finite direction, ``fill`` outside [0.1, 1],
            a distance that is not positive and finite.
        """
        d = view_direction(direction)
        check_fit(fit)
        if not (0.1 <= float(fill) <= 1.0):
            raise ParameterError(f"fill must be in [0.1, 1], got {fill!r}")
        if distance is not None and not (float(distance) > 0 and math.isfinite(float(distance))):
            raise ParameterError(f"distance must be positive and finite (m), got {distance!r}")
        pts = self._subject(fit)
        self.center = 0.5 * (pts.min(0) + pts.max(0))
        dist = (
            float(distance)
            if distance is not None
            else framing_distance(pts - self.center, d, float(fill), aspect=self._aspect())
        )
        self._camera = dict(direction=direction, distance=distance, fill=fill, fit=fit)
        self.camera_position = dist * d  # base-frame axes, from the orbit target
        x, y, z = self.camera_position
        # the camera lives in meshcat's y-up "rotated" frame: world (x, y, z) -> (x, z, -y)
        self._send(
            [
                set_transform(self.root, homogeneous(r=-self.center)),
                set_property("/Cameras/default/rotated/<object>", "position", [x, z, -y]),
            ]
        )

    def _aspect(self) -> float:
        """Width / height of the 3-D pane the framing assumes: 4:3, or the narrower pane left
        beside an open teach panel."""
        return TEACH_ASPECT if self._teaching else 4 / 3

    def camera_subject(self, fit: str = "auto") -> np.ndarray:
        """Points (K, 3; base frame, m) of what ``fit`` frames now (see :meth:`set_camera`): the
        corners of the drawn pieces' boxes and the points of the overlays."""
        return self._subject(check_fit(fit))

    def _subject(self, fit: str) -> np.ndarray:
        c = self._piece_corners(self.q)
        pose = c if len(c) else self._frame_corners
        if fit == "auto":
            hand = self._hand_corners()
            small = hand is not None and box_diagonal(hand) <= HAND_ZOOM_RATIO * box_diagonal(pose)
            fit = "hand" if small and not self._extents else "all"
        if fit == "hand":
            hand = self._hand_corners()
            return pose if hand is None else hand
        if fit == "reach":
            return self._reach_corners
        if fit == "all":
            return np.vstack([pose, *self._extents.values()])
        return pose

    def _hand_corners(self) -> np.ndarray | None:
        joints = hand_joints(self.robot.chain)
        if joints is None:
            return None
        c = self._piece_corners(self.q, joints)
        return c if len(c) else None

    def _add_extent(self, name: str, points) -> None:
        """Count ``points`` (K, 3; base frame) in the framing of ``fit="all"`` under the overlay
        ``name`` and re-frame if the camera follows what is drawn."""
        P = np.asarray(points, float).reshape(-1, 3)
        P = P[np.all(np.isfinite(P), axis=1)]
        if len(P) > EXTENT_POINTS:  # the box's extremes and an even subsample
            keep = np.linspace(0, len(P) - 1, EXTENT_POINTS).astype(int)
            P = np.vstack([P[keep], P[P.argmin(0)], P[P.argmax(0)]])
        if len(P):
            self._extents[name] = P
        else:
            self._extents.pop(name, None)
        self._reframe()

    def _drop_extent(self, name: str | None) -> None:
        if name is None:
            self._extents.clear()
        else:
            self._extents.pop(name, None)

    def _reframe(self) -> None:
        cam = self._camera
        if cam is not None and cam["distance"] is None and cam["fit"] in ("auto", "all"):
            self.set_camera(**cam)

    def _animation_extent(self, Q) -> None:
        """The robot's drawn pieces over (at most :data:`ANIMATION_SAMPLES`) poses of ``Q``."""
        idx = np.unique(np.linspace(0, len(Q) - 1, min(len(Q), ANIMATION_SAMPLES)).astype(int))
        pts = np.vstack([self._piece_corners(Q[k]) for k in idx])
        self._add_extent("animation", pts)

    def set_background(self, top=None, bottom=None, visible: bool = True) -> None:
        """Background gradient colours (0..255 RGB); ``visible=False`` for a transparent page."""
        cmds = []
        if top is not None:
            cmds.append(set_property("/Background", "top_color", rgb255(top, "top")))
        if bottom is not None:
            cmds.append(set_property("/Background", "bottom_color", rgb255(bottom, "bottom")))
        cmds.append(set_property("/Background", "visible", bool(visible)))
        self._send(cmds)

    # ------------------------------------------------------------------ poses
    def _all_bodies(self):
        for b in self.bodies:
            yield b, "bodies"
        for name, bs in self._overlay_bodies.items():
            for b in bs:
                yield b, f"overlays/{name}"

    def _moving(self) -> list[tuple[str, int | None, int | None]]:
        """(path, Pinocchio joint id or None, frame id or None) of every moving body; rebuilt
        when the overlays change."""
        if self._movers is None:
            self._movers = [
                (self._bpath(b, prefix), None if b.joint is None else b.joint + 1, b.frame)
                for b, prefix in self._all_bodies()
                if b.joint is not None or b.frame is not None
            ]
        return self._movers

    def _pose_commands(self, q) -> list[dict]:
        model, data = self.robot.model, self.robot.data
        pin.framesForwardKinematics(model, data, pinocchio_q(self.robot, q))
        oMi, oMf = data.oMi, data.oMf
        return [
            {
                "type": "set_transform",
                "path": path,
                "matrix": (oMi[j] if j is not None else oMf[f]).homogeneous.T.ravel().tolist(),
            }
            for path, j, f in self._moving()
        ]

    def display(self, q) -> None:
        """Show configuration ``q``: every link transform (and, with :meth:`~Viewer.show_limits`,
        every changed link colour) in one message."""
        q = self.robot.check_q(q, "q")
        if q.ndim != 1:
            raise ValueError(
                f"{self.robot.name}: display takes one configuration ({self.robot.nq},), got {q.shape}; use play() for a trajectory"
            )
        self.q = q.copy()
        stop = [stop_animation()] if self._animating else []
        self._animating = False
        self._send(stop + self._pose_commands(q) + self._color_commands(q))

    @property
    def scene(self) -> Scene:
        """The underlying meshcat scene, as a meshcat :class:`~meshcat.visualizer.Visualizer`
        (:class:`Scene`): the escape hatch for anything the Viewer has no method for.

        >>> import meshcat.geometry as mg
        >>> v.scene["mine/box"].set_object(mg.Box([0.1, 0.1, 0.1]))   # /meshcat/mine/box
        >>> v.scene["/Grid"].set_property("visible", True)
        >>> v.scene.set_cam_pos([1.5, 1.0, 0.8])

        Its commands go through the Viewer: they are kept in :meth:`~Viewer.static_html` and sent to
        the live server.  Coordinates are meshcat's world frame; the robot's base frame is
        shifted by ``-viewer.center`` in it (draw under ``viewer.root`` to use base-frame
        coordinates: ``v.scene[v.root + "/mine"]``)."""
        return Scene(window=SceneWindow(self))
