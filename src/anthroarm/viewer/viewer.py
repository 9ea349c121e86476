"""The meshcat viewer of a Robot: poses, overlays, animations, static HTML, Jupyter.

>>> import anthroarm as aa
>>> v = aa.viewer.Viewer("human_arm7")              # in memory: export or show inline
>>> v.display(q)                                     # all link transforms in ONE message
>>> v.show_target(T); v.show_workspace(); v.show_limits()
>>> v.play(Q, dt=0.02); v.export_html("reach.html") # self-contained file, arm moving
>>> live = aa.viewer.Viewer("panda", live=True)      # + a server on 127.0.0.1 (browser tab)
>>> live.url
'http://127.0.0.1:7000/static/'

Every command updates an in-process copy of the scene (so ``static_html()`` never needs the
server) and, when ``live``, is forwarded to the server — a pose update as one
``anthroarm_batch`` message, so the browser never draws a half-updated arm.

Coordinates: overlays (targets, traces, workspace) are given in the robot's base frame (m),
like ``robot.fk``.  The robot is shifted in the browser so that its reach is centred on
meshcat's orbit target; that shift is invisible to the API.

The Viewer is composed of one part per concern, each in its own module:
:mod:`~anthroarm.viewer.scene` (bodies, poses, camera, guides), :mod:`~anthroarm.viewer.overlays`
(frames, targets, traces, point clouds, arrows, link colours and legends),
:mod:`~anthroarm.viewer.teach` (joint sliders), :mod:`~anthroarm.viewer.export` (animations,
HTML, Jupyter) and :mod:`~anthroarm.viewer.live` (the in-memory scene and the live server).
The names that used to live here (``Scene``, ``framing_distance``, ``limit_color`` ...) are
importable from here too.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..loading import load
from ..robot import Robot
from ._store import SceneStore
from .checks import check_background
from .colors import (
    LIMIT_RGB,
    LIMIT_WARN,
    colormap_legend,
    colormap_rgb,
    limit_color,
    limit_proximity,
    viridis,
)
from .export import ExportMixin
from .live import LiveMixin
from .meshes import MESH_TRIANGLES
from .messages import ROOT, safe_name
from .overlays import OverlaysMixin, manipulability
from .scene import Scene, SceneMixin, format_length, framing_distance, nice_length
from .server import ServerProcess, check_port
from .shapes import arrow_mesh, local_corners
from .teach import TeachMixin
from .visuals import Body, robot_bodies

__all__ = [
    "LIMIT_RGB",
    "LIMIT_WARN",
    "ROOT",
    "Scene",
    "Viewer",
    "arrow_mesh",
    "colormap_legend",
    "colormap_rgb",
    "format_length",
    "framing_distance",
    "limit_color",
    "limit_proximity",
    "local_corners",
    "manipulability",
    "nice_length",
    "viridis",
]


class Viewer(SceneMixin, OverlaysMixin, TeachMixin, ExportMixin, LiveMixin):
    """A meshcat scene showing one Robot.

    Its methods, by concern (one module each):

    * scene (:class:`~anthroarm.viewer.scene.SceneMixin`): :meth:`display`, :meth:`set_camera`,
      :meth:`set_background`, :meth:`set_grid`, :meth:`set_axes`, :meth:`set_scale_bar`, and
      :attr:`~anthroarm.viewer.scene.SceneMixin.scene` (meshcat's own API);
    * overlays (:class:`~anthroarm.viewer.overlays.OverlaysMixin`): :meth:`show_frames`,
      :meth:`show_target`, :meth:`show_trace`, :meth:`show_points`, :meth:`show_workspace`,
      :meth:`show_map`, :meth:`show_arrows`, :meth:`show_limits`, :meth:`show_joint_values`,
      :meth:`clear`;
    * teach (:class:`~anthroarm.viewer.teach.TeachMixin`): :meth:`teach`;
    * export (:class:`~anthroarm.viewer.export.ExportMixin`): :meth:`play`, :meth:`stop`,
      :meth:`static_html`, :meth:`export_html`, :meth:`jupyter_cell`;
    * live server (:class:`~anthroarm.viewer.live.LiveMixin`):
      :attr:`~anthroarm.viewer.live.LiveMixin.url`, :meth:`open`, :meth:`wait`, :meth:`close`
      (also on leaving a ``with`` block).

    Parameters
    ----------
    robot : Robot or str
        A loaded robot or a catalog name.
    live : bool
        Start a server on 127.0.0.1 (see :class:`~anthroarm.viewer.server.ServerProcess`) so a
        browser tab or a Jupyter iframe shows the scene as it changes.  ``False``: the scene
        lives in memory only (``export_html``, ``jupyter_cell``).
    port : int, optional
        Server port (``live=True``): an integer in 1..65535 (a bool or float is a TypeError); a
        port in use raises ViewerPortInUseError.
    style : {"auto", "generated", "urdf", "visual_model"}
        Visuals (:func:`~anthroarm.viewer.visuals.robot_bodies`): capsules, cylinders and spheres
        generated from ``robot.chain`` (book models, robots without visual geometry), the URDF's
        ``<visual>`` meshes, or ``robot.visual_model`` (a robot loaded from a ``pin.Model``).
    background : ((r, g, b), (r, g, b)), optional
        meshcat's gradient (top, bottom; 0..255).  Default: meshcat's background hidden, the
        page's own light CSS gradient shows through (identical in every browser, including
        headless software WebGL, where meshcat's gradient texture comes out inverted).
    q : array, optional
        Initial configuration (default ``robot.neutral()``).
    grid, axes, scale_bar : bool
        Guides (each also switchable later: :meth:`set_grid`, :meth:`set_axes`,
        :meth:`set_scale_bar`): a floor grid of ``viewer.spacing`` m squares through the base
        origin, the world axes at the base origin, and a scale bar one grid square long with
        a note giving its length.  A translucent floor disc is always drawn.
    mesh_triangles : int or None
        Most triangles each mesh file is drawn with
        (:data:`~anthroarm.viewer.meshes.MESH_TRIANGLES` by default): meshes are parsed,
        merged and, above the budget, decimated into compact 16-bit
        :class:`~anthroarm.viewer.meshes.PackedMesh` geometry, so a Jupyter cell or an HTML
        file stays small (Franka Panda: 15.0 MB → 1.49 MB).  ``None`` sends the files as they are.
    """

    def __init__(
        self,
        robot,
        *,
        live: bool = False,
        port: int | None = None,
        style: str = "auto",
        q=None,
        name: str | None = None,
        background=None,
        grid: bool = True,
        axes: bool = True,
        scale_bar: bool = True,
        mesh_triangles: int | None = MESH_TRIANGLES,
    ):
        if isinstance(robot, (str, Path)):
            robot = load(robot)
        if not isinstance(robot, Robot):
            raise ParameterError(
                f"Viewer takes a Robot (aa.load(...)) or a model name / URDF path, got {type(robot).__name__}"
            )
        background = check_background(background)
        self.robot = robot
        self.store = SceneStore()
        self.server = None
        if live:
            port = check_port(port)  # a bad port is a ParameterError before any work
        self.root = f"{ROOT}/{safe_name(name or robot.name)}"
        self.bodies: list[Body] = robot_bodies(
            robot, style, mesh_triangles
        )  # MeshError etc. before a server starts
        if live:
            self.server = ServerProcess(port=port)
        self._overlay_bodies: dict[str, list[Body]] = {}
        self._movers: list[tuple[str, int | None, int | None]] | None = None
        joints = robot.chain.joints
        self._joint_lower = np.array([j.lower for j in joints])
        self._joint_upper = np.array([j.upper for j in joints])
        self._limits_on = False
        self._joint_rgb: list | None = None  # show_joint_values: one colour per chain joint
        self._teaching = False
        self._animating = False
        self._colors: dict[str, tuple] = {}
        self._extents: dict[str, np.ndarray] = {}  # overlay name -> its box, for fit="all"
        self._camera: dict | None = None  # the last set_camera arguments
        self.q = robot.neutral() if q is None else robot.check_q(q, "q").copy()
        self._frame_scene(background, grid, axes, scale_bar)
        self._send(self._body_objects(self.bodies))
        self.display(self.q)

    def __repr__(self) -> str:
        where = self.url if self.server is not None else "in memory"
        return f"Viewer({self.robot.name!r}, {where})"
