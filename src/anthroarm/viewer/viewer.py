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
"""

from __future__ import annotations

import html as _html
import math
import re
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from meshcat.commands import SetObject, SetProperty
from meshcat.path import Path as MeshcatPath
from meshcat.visualizer import Visualizer

from .._io import atomic_write_text
from ..errors import ParameterError, ViewerError
from ..spatial.rotations import homogeneous, rotation_between
from ._store import SceneStore
from .visuals import (
    LINK_RGB,
    MESH_TRIANGLES,
    Body,
    Piece,
    _y_to,
    cylinder_between,
    rgb_hex,
    robot_bodies,
)

ROOT = "/meshcat/anthroarm"
#: Colour of a joint at its limit (joint-limit proximity).
LIMIT_RGB = (0.92, 0.12, 0.10)
#: Proximity above which a link starts to turn red: the last 15 % of the range on each side.
LIMIT_WARN = 0.7


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.\-]", "_", str(name)) or "_"


def _set_transform(path: str, T: np.ndarray) -> dict:
    return {
        "type": "set_transform",
        "path": path,
        "matrix": np.asarray(T, float).T.ravel().tolist(),
    }


def _set_object(
    path: str, geometry, rgb=(0.7, 0.7, 0.7), opacity: float = 1.0, material=None
) -> dict:
    if material is None:
        kw = {"color": rgb_hex(rgb)}
        if opacity < 1.0:
            kw.update(opacity=float(opacity), transparent=True)
        material = mg.MeshPhongMaterial(**kw)
    if isinstance(geometry, mg.Object):
        cmd = SetObject(geometry)
    else:
        cmd = SetObject(geometry, material)
    d = cmd.lower()
    d["path"] = path
    return d


def _set_property(path: str, key: str, value) -> dict:
    return {"type": "set_property", "path": path, "property": key, "value": value}


def _delete(path: str) -> dict:
    return {"type": "delete", "path": path}


def _rgb255(value, what: str) -> list[int]:
    try:
        c = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        c = np.array([np.nan])
    if c.shape != (3,) or not np.all(np.isfinite(c)) or np.any((c < 0) | (c > 255)):
        raise ParameterError(f"{what} must be three numbers (r, g, b) in 0..255, got {value!r}")
    return [int(round(x)) for x in c]


def _check_background(background):
    """``None`` or ((r, g, b), (r, g, b)) with 0..255 components -> two lists of ints."""
    if background is None:
        return None
    if (
        isinstance(background, (str, bytes))
        or not hasattr(background, "__len__")
        or len(background) != 2
    ):
        raise ParameterError(
            f"background must be ((r, g, b), (r, g, b)) in 0..255 (top, bottom), got {background!r}"
        )
    return _rgb255(background[0], "background top colour"), _rgb255(
        background[1], "background bottom colour"
    )


def limit_proximity(q, lower, upper) -> np.ndarray:
    """0 at the middle of each joint's range, 1 at (or beyond) a limit; 0 for unbounded joints.
    ``q``: joint positions θ (rad or m, :meth:`anthroarm.chain.Chain.angles`), one per limit."""
    q, lo, hi = (np.asarray(x, float) for x in (q, lower, upper))
    out = np.zeros_like(q)
    fin = np.isfinite(lo) & np.isfinite(hi) & (hi > lo)
    half = 0.5 * (hi[fin] - lo[fin])
    mid = 0.5 * (hi[fin] + lo[fin])
    out[fin] = np.clip(np.abs(q[fin] - mid) / half, 0.0, 1.0)
    return out


def limit_color(p: float, base=LINK_RGB) -> tuple[float, float, float]:
    """Link colour for proximity ``p``: the base colour up to :data:`LIMIT_WARN`, then a blend
    to :data:`LIMIT_RGB` at the limit."""
    w = float(np.clip((p - LIMIT_WARN) / (1.0 - LIMIT_WARN), 0.0, 1.0))
    return tuple((1 - w) * b + w * r for b, r in zip(base, LIMIT_RGB))


def manipulability(robot, Q, frame=None) -> np.ndarray:
    """Translational manipulability (Yoshikawa) of ``frame`` at each row of ``Q``: the product
    of the singular values of the 3 × nv linear block of the LOCAL_WORLD_ALIGNED Jacobian
    (= sqrt(det(Jv Jvᵀ)) when nv ≥ 3).  Units m^min(3, nv)."""
    Q = robot.check_q(Q)
    J = robot.jacobian(np.atleast_2d(Q), frame)[:, :3, :]
    s = np.linalg.svd(J, compute_uv=False)
    k = min(3, robot.nv)
    w = np.prod(s[:, :k], axis=1)
    return w if Q.ndim == 2 else w[0]


def viridis(x: np.ndarray) -> np.ndarray:
    """RGB (N, 3) in [0, 1] of the viridis colour map at ``x`` in [0, 1]."""
    from matplotlib import colormaps

    return np.asarray(colormaps["viridis"](np.clip(x, 0, 1)))[:, :3]


def colormap_rgb(values, colormap: str = "viridis", vmin=None, vmax=None):
    """RGB (N, 3) in [0, 1] of ``values`` (N,) through the matplotlib colour map ``colormap``,
    scaled from ``vmin`` (default: the smallest finite value) to ``vmax`` (the largest).
    Returns ``(rgb, vmin, vmax)``.  NaN or inf values, an unknown map or ``vmax < vmin`` raise
    :class:`~anthroarm.errors.ParameterError`."""
    from matplotlib import colormaps

    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or not np.all(np.isfinite(v)):
        raise ParameterError(
            f"values must be a 1-D array of finite numbers, got shape {v.shape}"
            + ("" if v.ndim != 1 else " with NaN or inf")
        )
    if not isinstance(colormap, str) or colormap not in colormaps:
        raise ParameterError(
            f"colormap must be a matplotlib colour map name (viridis, viridis_r, plasma, "
            f"coolwarm, ...), got {colormap!r}"
        )
    lo = float(v.min()) if vmin is None and v.size else (0.0 if vmin is None else float(vmin))
    hi = float(v.max()) if vmax is None and v.size else (1.0 if vmax is None else float(vmax))
    if not (math.isfinite(lo) and math.isfinite(hi) and hi >= lo):
        raise ParameterError(f"vmin, vmax must be finite with vmin <= vmax, got {lo}, {hi}")
    x = (v - lo) / (hi - lo) if hi > lo else np.full_like(v, 0.5)
    return np.asarray(colormaps[colormap](np.clip(x, 0.0, 1.0)))[:, :3], lo, hi


def _rgb01(value, n: int, what: str) -> np.ndarray:
    """One colour (3,) or one per item (n, 3), components in [0, 1] -> (n, 3) float."""
    try:
        c = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        c = np.array([np.nan])
    if c.shape == (3,):
        c = np.tile(c, (n, 1))
    if c.shape != (n, 3) or not np.all(np.isfinite(c)) or np.any((c < 0) | (c > 1)):
        raise ParameterError(
            f"{what} must be one colour (r, g, b) or ({n}, 3) colours, components in 0..1, "
            f"got shape {np.shape(value)}"
        )
    return c


def _points3(points, what: str, min_rows: int = 1) -> np.ndarray:
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{what} must be an (N, 3) array of numbers (m, base frame), got {type(points).__name__}"
        ) from None
    if P.shape == (3,):
        P = P[None]
    if P.ndim != 2 or P.shape[1] != 3 or len(P) < min_rows:
        raise ParameterError(
            f"{what} must be an (N>={min_rows}, 3) array (m, base frame), got shape {P.shape}"
        )
    if not np.all(np.isfinite(P)):
        bad = int(np.argmax(~np.isfinite(P).all(axis=1)))
        raise ParameterError(f"{what} contain NaN or inf (row {bad})")
    return P


class _ShadedMesh(mg.TriangularMeshGeometry):
    """A triangle mesh with per-vertex normals (meshcat's own sends none, so Phong shading
    would leave it flat black) and per-vertex colours."""

    def __init__(self, vertices, faces, normals, color):
        super().__init__(vertices, faces, color)
        self.normals = np.asarray(normals, dtype=np.float32)

    def lower(self, object_data):
        d = super().lower(object_data)
        d["data"]["attributes"]["normal"] = mg.pack_numpy_array(self.normals.T)
        return d


def arrow_mesh(origins, vectors, radius, colors, head_length=None, segments: int = 10):
    """One shaded triangle mesh of arrows: a shaft (cylinder) of ``radius`` and a cone head from
    each origin along its vector (both (N, 3), m).  ``colors`` (N, 3) in [0, 1].  The head is
    ``head_length`` long (default 3.5 radii, at most half the arrow) and 2.2 radii wide.
    Zero-length vectors draw nothing."""
    O, V = np.asarray(origins, float), np.asarray(vectors, float)
    verts, norms, cols, faces = [], [], [], []
    ang = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], 1)
    count = 0
    for o, v, c in zip(O, V, np.asarray(colors, float)):
        L = float(np.linalg.norm(v))
        if L < 1e-12:
            continue
        d = v / L
        R = rotation_between((0.0, 0.0, 1.0), d)
        ex, ey = R[:, 0], R[:, 1]
        hl = min(head_length if head_length is not None else 3.5 * radius, 0.5 * L)
        rim = ring[:, :1] * ex + ring[:, 1:] * ey  # (s, 3) unit radial directions
        a, b = o, o + (L - hl) * d  # shaft
        tip = o + v
        # shaft: 2s vertices with radial normals
        vs = np.concatenate([a + radius * rim, b + radius * rim])
        ns = np.concatenate([rim, rim])
        # cone: rim at b (2.2 r) and the tip, normals tilted by the cone's half-angle
        rc = 2.2 * radius
        slope = rc / hl
        nc = (rim + slope * d) / math.sqrt(1 + slope * slope)
        vc = np.concatenate([b + rc * rim, np.repeat(tip[None], segments, 0)])
        ncs = np.concatenate([nc, nc])
        # the cone's base disc (facing back)
        vb = np.concatenate([b + rc * rim, b[None]])
        nb = np.tile(-d, (segments + 1, 1))
        base = count
        k = np.arange(segments)
        k1 = (k + 1) % segments
        f_shaft = np.concatenate(
            [np.stack([k, k1, segments + k1], 1), np.stack([k, segments + k1, segments + k], 1)]
        )
        f_cone = np.stack([k, k1, segments + k], 1) + 2 * segments
        f_base = np.stack([np.full(segments, segments), k1, k], 1) + 4 * segments
        faces.append(np.concatenate([f_shaft, f_cone, f_base]) + base)
        vv = np.concatenate([vs, vc, vb])
        verts.append(vv)
        norms.append(np.concatenate([ns, ncs, nb]))
        cols.append(np.tile(c, (len(vv), 1)))
        count += len(vv)
    if not verts:
        return None
    return _ShadedMesh(
        np.concatenate(verts), np.concatenate(faces), np.concatenate(norms), np.concatenate(cols)
    )


class _SceneWindow:
    """What a meshcat :class:`~meshcat.visualizer.Visualizer` sends its commands through: here
    the Viewer's own channel (its in-memory scene and, when live, its server)."""

    def __init__(self, viewer: "Viewer"):
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
    """meshcat's :class:`~meshcat.visualizer.Visualizer` API on the scene of a
    :class:`Viewer` (:attr:`Viewer.scene`): ``scene["name"].set_object(geometry, material)``,
    ``set_transform``, ``set_property``, ``delete``, plus :meth:`set_cam_pos`.  Paths start at ``/meshcat`` (absolute paths such as
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
        x, y, z = (float(c) for c in _points3(position, "camera position")[0])
        self.window.send(
            SetProperty(
                "position", [x, z, -y], MeshcatPath(("Cameras", "default", "rotated", "<object>"))
            )
        )

    def __repr__(self) -> str:
        return f"<anthroarm Scene at {self.path.lower()} of {self.window._viewer!r}>"


def _box_corners(lo, hi) -> np.ndarray:
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])], float
    )


def local_corners(g) -> np.ndarray | None:
    """The 8 corners of a meshcat geometry's bounding box in its own frame (cylinders along y),
    or None for geometry without known bounds (a mesh file sent as it is)."""
    from .visuals import PackedMesh

    kind = type(g).__name__
    if isinstance(g, PackedMesh):
        return _box_corners(g.grid.min(0), g.grid.max(0)) if len(g.faces) else None
    if kind == "Sphere":
        e = np.full(3, float(g.radius))
    elif kind == "Ellipsoid":
        e = np.asarray(g.radii, float)
    elif kind == "Cylinder":
        rr = max(float(g.radiusTop), float(g.radiusBottom))
        e = np.array([rr, g.height / 2, rr])
    elif kind == "Box":
        e = np.asarray(g.lengths, float) / 2
    else:
        return None
    return _box_corners(-e, e)


def colormap_legend(title: str, colormap: str, vmin: float, vmax: float, n: int = 9) -> dict:
    """The ``anthroarm_ui`` spec of a colour-bar legend: ``n`` colours of ``colormap`` from
    ``vmin`` to ``vmax`` and three tick labels (min, middle, max)."""
    from matplotlib import colormaps

    stops = np.asarray(colormaps[colormap](np.linspace(0.0, 1.0, n)))[:, :3]
    ticks = [f"{v:.3g}" for v in (vmin, 0.5 * (vmin + vmax), vmax)]
    return {
        "kind": "legend",
        "title": str(title),
        "stops": [[round(float(c), 4) for c in rgb] for rgb in stops],
        "ticks": ticks,
    }


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


def framing_distance(
    corners, direction, fill: float = 0.85, fov_deg: float = 75.0, aspect: float = 4 / 3
) -> float:
    """Camera distance from the orbit target (the origin) along the unit ``direction`` at which
    every point of ``corners`` (K, 3; relative to the target) projects inside ``fill`` of the
    vertical field of view ``fov_deg`` and of the horizontal one (width / height = ``aspect``);
    z is up.  A point at depth D - c·d and offset (c·r, c·u) in the camera frame is inside when
    D >= c·d + |c·u| / (fill tan(fov/2)) (and the same with r and the horizontal half-angle)."""
    C = np.asarray(corners, float)
    d = np.asarray(direction, float)
    f = -d
    r = np.cross(f, [0.0, 0.0, 1.0])
    r = r / np.linalg.norm(r) if np.linalg.norm(r) > 1e-9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(r, f)
    tv = fill * math.tan(math.radians(fov_deg) / 2)
    th = fill * math.tan(math.radians(fov_deg) / 2) * aspect
    depth = C @ d
    need = np.maximum(depth + np.abs(C @ u) / tv, depth + np.abs(C @ r) / th)
    return float(max(need.max(), 1e-3))


class Viewer:
    """A meshcat scene showing one Robot.

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
        (:data:`~anthroarm.viewer.visuals.MESH_TRIANGLES` by default): meshes are parsed,
        merged and, above the budget, decimated into compact 16-bit
        :class:`~anthroarm.viewer.visuals.PackedMesh` geometry, so a Jupyter cell or an HTML
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
        from ..robot import Robot, load

        if isinstance(robot, (str, Path)):
            robot = load(robot)
        if not isinstance(robot, Robot):
            raise ParameterError(
                f"Viewer takes a Robot (aa.load(...)) or a model name / URDF path, got {type(robot).__name__}"
            )
        background = _check_background(background)
        self.robot = robot
        self.store = SceneStore()
        self.server = None
        if live:
            from .server import _check_port

            port = _check_port(port)  # a bad port is a ParameterError before any work
        self.root = f"{ROOT}/{_safe(name or robot.name)}"
        self.bodies: list[Body] = robot_bodies(
            robot, style, mesh_triangles
        )  # MeshError etc. before a server starts
        if live:
            from .server import ServerProcess

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
        self.q = robot.neutral() if q is None else robot.check_q(q, "q").copy()
        self._frame_scene(background, grid, axes, scale_bar)
        self._send(self._body_objects(self.bodies))
        self.display(self.q)

    # ------------------------------------------------------------------ plumbing
    def _send(self, cmds: list[dict]) -> None:
        if not cmds:
            return
        for c in cmds:
            self.store.apply(c)
        if self.server is not None:
            self.server.send_many(cmds)

    def _bpath(self, body: Body, prefix: str = "bodies") -> str:
        return f"{self.root}/{prefix}/{_safe(body.name)}"

    def _body_objects(self, bodies, prefix="bodies") -> list[dict]:
        cmds = []
        for b in bodies:
            bp = self._bpath(b, prefix)
            for k, p in enumerate(b.pieces):
                path = f"{bp}/{p.group}/{k}"
                cmds.append(_set_object(path, p.geometry, p.rgb, p.opacity))
                if not np.allclose(p.offset, np.eye(4)):
                    cmds.append(_set_transform(path, p.offset))
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
                pin.framesForwardKinematics(model, data, qi)
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
        self._reach_box = _box_corners(lo, hi) - self.center
        self._frame_box = _box_corners(blo, bhi) - self.center
        cmds = [_set_transform(self.root, homogeneous(r=-self.center))]
        self.floor = floor = min(0.0, float(lo[2])) - 0.01  # base frame
        cmds.append(
            _set_property("/Grid", "visible", False)
        )  # meshcat's 20 m grid: ours fits the robot
        cmds.append(_set_property("/Axes", "visible", False))
        # a translucent floor disc under the reach (always drawn; robust in software WebGL)
        rf = 0.9 * self.radius
        disc = mg.Cylinder(0.004 * rf, rf)
        cmds.append(_set_object(f"{self.root}/floor", disc, (0.80, 0.83, 0.88), 0.4))
        cmds.append(
            _set_transform(
                f"{self.root}/floor", homogeneous(_y_to([0, 0, 1]), [mid[0], mid[1], floor])
            )
        )
        if background is None:
            cmds.append(_set_property("/Background", "visible", False))
        else:
            top, bottom = background
            cmds.append(_set_property("/Background", "top_color", [int(c) for c in top]))
            cmds.append(_set_property("/Background", "bottom_color", [int(c) for c in bottom]))
        self._send(cmds)
        self._guides(mid, rf)
        self.set_grid(grid)
        self.set_axes(axes)
        self.set_scale_bar(scale_bar)
        self.set_camera()

    def _piece_corners(self, q) -> np.ndarray:
        """Corners (K, 3), base frame, of the local bounding boxes of every drawn piece at ``q``
        (mesh files sent as they are have no bounds here and are skipped)."""
        model, data = self.robot.model, self.robot.data
        pin.framesForwardKinematics(model, data, q)
        out = [np.zeros((0, 3))]
        for b in self.bodies:
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
        cmds = [_set_object(f"{self.root}/grid", grid)]
        size = 0.15 * self.radius
        for k, piece in enumerate(self._triad(size, 0.04 * size)):
            path = f"{self.root}/axes/{k}"
            cmds += [
                _set_object(path, piece.geometry, piece.rgb),
                _set_transform(path, piece.offset),
            ]
        # the scale bar: `spacing` long, alternating dark and light fifths, at the grid's front-left
        corner = (
            self._frame_box.max(0)[:2] + self.center[:2]
        )  # on the camera's side of the robot, on grid lines
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
                    _set_object(path, piece.geometry, piece.rgb),
                    _set_transform(path, piece.offset),
                ]
        self._send(cmds)

    def _ui(self, path: str, spec: dict) -> dict:
        return {"type": "anthroarm_ui", "path": path, "spec": spec}

    def set_grid(self, visible: bool = True) -> None:
        """Show or hide the floor grid (lines ``viewer.spacing`` m apart through the base origin)."""
        self._send([_set_property(f"{self.root}/grid", "visible", bool(visible))])

    def set_axes(self, visible: bool = True) -> None:
        """Show or hide the world axes at the robot's base origin (x red, y green, z blue)."""
        self._send([_set_property(f"{self.root}/axes", "visible", bool(visible))])

    def set_scale_bar(self, visible: bool = True) -> None:
        """Show or hide the scale bar on the floor and its note (its length = the grid spacing)."""
        cmds = [_set_property(f"{self.root}/scale", "visible", bool(visible))]
        note = f"{self.root}/ui/scale"
        if visible:
            cmds.append(
                self._ui(
                    note,
                    {
                        "kind": "note",
                        "text": f"scale bar and grid squares: {format_length(self.spacing)}",
                    },
                )
            )
        else:
            cmds.append(_delete(note))
        self._send(cmds)

    # ------------------------------------------------------------------ scene settings
    def set_camera(
        self,
        direction=(0.9, 1.0, 0.45),
        distance: float | None = None,
        fill: float = 0.85,
        fit: str = "pose",
    ) -> None:
        """Look at the robot from ``direction`` (base-frame axes) at ``distance`` m.

        The default distance frames ``fit``: ``"pose"``, the box around the robot as displayed
        now (every drawn piece), or ``"reach"``, the box around its workspace; the box
        fills ``fill`` of meshcat's 75° vertical field of view (and of the horizontal one of a
        4:3 view), seen from ``direction``."""
        if fit not in ("pose", "reach"):
            raise ValueError(f"fit must be 'pose' or 'reach', got {fit!r}")
        d = np.asarray(direction, float)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) < 1e-9:
            raise ValueError(f"direction must be a non-zero finite 3-vector, got {direction!r}")
        d = d / np.linalg.norm(d)
        if not (0.1 <= float(fill) <= 1.0):
            raise ValueError(f"fill must be in [0.1, 1], got {fill!r}")
        if fit == "pose":  # the robot as displayed now, about the fixed orbit target
            c = self._piece_corners(self.q)
            box = _box_corners(c.min(0), c.max(0)) - self.center if len(c) else self._frame_box
        else:
            box = self._reach_box
        dist = float(distance) if distance is not None else framing_distance(box, d, float(fill))
        if not (dist > 0 and math.isfinite(dist)):
            raise ValueError(f"distance must be positive and finite, got {distance!r}")
        x, y, z = dist * d
        # the camera lives in meshcat's y-up "rotated" frame: world (x, y, z) -> (x, z, -y)
        self._send([_set_property("/Cameras/default/rotated/<object>", "position", [x, z, -y])])

    def set_background(self, top=None, bottom=None, visible: bool = True) -> None:
        """Background gradient colours (0..255 RGB); ``visible=False`` for a transparent page."""
        cmds = []
        if top is not None:
            cmds.append(_set_property("/Background", "top_color", _rgb255(top, "top")))
        if bottom is not None:
            cmds.append(_set_property("/Background", "bottom_color", _rgb255(bottom, "bottom")))
        cmds.append(_set_property("/Background", "visible", bool(visible)))
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
        pin.framesForwardKinematics(model, data, q)
        oMi, oMf = data.oMi, data.oMf
        return [
            {
                "type": "set_transform",
                "path": path,
                "matrix": (oMi[j] if j is not None else oMf[f]).homogeneous.T.ravel().tolist(),
            }
            for path, j, f in self._moving()
        ]

    def _color_commands(self, q) -> list[dict]:
        """Recolour links and joint centres: with :meth:`show_limits`, links by the largest
        proximity over ``body.link_joints`` and joint centres by their own (from the joint
        positions θ of ``robot.chain``: a continuous joint's angle, a mimic joint's copy;
        unbounded joints are never coloured); with :meth:`show_joint_values`, each body's links
        by the value of the joint that moves it.  Only colours that changed since the last call
        are sent (None: the original colours)."""
        if (
            not self._limits_on
            and self._joint_rgb is None
            and not any(c is not None for c in self._colors.values())
        ):
            return []  # nothing coloured, nothing to restore: the common case of display()
        prox = None
        if self._limits_on:
            prox = limit_proximity(self.robot.chain.angles(q), self._joint_lower, self._joint_upper)
        frames = self.robot.chain.frames
        want: dict[str, tuple | None] = {}
        where: dict[str, tuple] = {}
        for b in self.bodies:
            has = {p.group for p in b.pieces}
            link_group = "links" if "links" in has else "mesh"
            bp = self._bpath(b)
            if link_group in has:
                where[f"{bp}/{link_group}"] = (b, link_group)
            if "joint" in has:
                where[f"{bp}/joint"] = (b, "joint")
            if prox is not None:
                groups = []
                if b.link_joints and link_group in has:
                    groups.append((link_group, b.link_joints))
                if b.limit_joint is not None and "joint" in has:
                    groups.append(("joint", [b.limit_joint]))
                for group, idx in groups:
                    base = next(p.rgb for p in b.pieces if p.group == group)
                    want[f"{bp}/{group}"] = tuple(
                        round(c, 3) for c in limit_color(float(prox[idx].max()), base)
                    )
            elif self._joint_rgb is not None and link_group in has:
                j = (
                    b.joint
                    if b.joint is not None
                    else (frames[b.frame].joint if b.frame is not None else -1)
                )
                if j >= 0:
                    want[f"{bp}/{link_group}"] = self._joint_rgb[j]
        cmds = []
        for path, (b, group) in where.items():
            rgb = want.get(path)
            if self._colors.get(path) == rgb:
                continue
            self._colors[path] = rgb
            if rgb is None:  # restore the original colours
                for k, p in enumerate(b.pieces):
                    if p.group == group:
                        cmds.append(_set_object(f"{path}/{k}", p.geometry, p.rgb, p.opacity))
                        if not np.allclose(p.offset, np.eye(4)):
                            cmds.append(_set_transform(f"{path}/{k}", p.offset))
            else:
                cmds.append({"type": "anthroarm_color", "path": path, "color": list(rgb)})
        return cmds

    def display(self, q) -> None:
        """Show configuration ``q``: every link transform (and, with :meth:`show_limits`,
        every changed link colour) in one message."""
        q = self.robot.check_q(q, "q")
        if q.ndim != 1:
            raise ValueError(
                f"{self.robot.name}: display takes one configuration ({self.robot.nq},), got {q.shape}; use play() for a trajectory"
            )
        self.q = q.copy()
        stop = [self._stop_command()] if self._animating else []
        self._animating = False
        self._send(stop + self._pose_commands(q) + self._color_commands(q))

    def _stop_command(self) -> dict:
        return {
            "type": "set_animation",
            "path": "",
            "animations": [],
            "options": {"play": False, "repetitions": 1},
        }

    def stop(self) -> None:
        """Stop and forget the animation set by :meth:`play` (``display`` does this too)."""
        self._animating = False
        self._send([self._stop_command()])

    def show_limits(self, on: bool = True) -> None:
        """Colour each link by how close its joint is to a limit (red within the last 15 %),
        with a colour legend; joints without limits (continuous joints) are skipped.
        ``on=False`` restores the colours and removes the legend."""
        self._limits_on = bool(on)
        if self._limits_on and self._joint_rgb is not None:  # one colouring at a time
            self._joint_rgb = None
            self._send([_delete(f"{self.root}/ui/joint_values")])
        legend = f"{self.root}/ui/limits"
        if self._limits_on:
            x = np.linspace(0.0, 1.0, 11)
            spec = {
                "kind": "legend",
                "title": "joint-limit proximity (0: mid-range, 1: at a limit)",
                "stops": [list(limit_color(v)) for v in x],
                "ticks": ["0", "0.5", "1"],
            }
            cmds = [self._ui(legend, spec)]
        else:
            cmds = [_delete(legend)]
        if self._teaching:  # the sliders recolour as they move (or stop doing so)
            cmds.append(self._ui(f"{self.root}/ui/teach", self._teach_spec()))
        self._send(self._color_commands(self.q) + cmds)

    def show_joint_values(
        self,
        values,
        label: str = "joint torque |τ| (N·m)",
        *,
        colormap: str = "plasma",
        vmin=None,
        vmax=None,
        absolute: bool = True,
    ) -> dict:
        """Colour each body's links by a value of the joint that moves it (joint torques from
        :mod:`anthroarm.dynamics`, loads, effort ratios ...), with a colour legend.

        Parameters
        ----------
        values : array_like
            One number per joint of ``robot.chain`` (mimic joints included), or one per
            velocity (``robot.nv``: a mimic joint then takes its source's value), e.g. τ.
        label : str
            Legend title, with the unit.
        colormap : str
            A matplotlib colour map name.
        vmin, vmax : float, optional
            Colour range (default: the values' range).
        absolute : bool
            Colour by ``|values|`` (a torque's size, either sign).

        Returns
        -------
        dict
            ``{"values": (njoints,), "colors": (njoints, 3), "vmin", "vmax"}``.

        Raises
        ------
        ParameterError
            Values of another length, NaN or inf, or a bad colour map or range.

        Notes
        -----
        ``values=None`` removes the colouring and its legend.  :meth:`show_limits` and this
        colouring replace each other.
        """
        legend = f"{self.root}/ui/joint_values"
        if values is None:
            self._joint_rgb = None
            self._send(self._color_commands(self.q) + [_delete(legend)])
            return {}
        chain = self.robot.chain
        v = np.asarray(values, dtype=float) if np.ndim(values) else np.array([np.nan])
        if v.ndim == 1 and len(v) == self.robot.nv and len(v) != len(chain.joints):
            v = np.array(
                [v[(chain.joints[j.mimic.source] if j.mimic else j).idx_v] for j in chain.joints]
            )
        if v.shape != (len(chain.joints),):
            raise ParameterError(
                f"values must have one number per joint ({len(chain.joints)}) or per velocity "
                f"({self.robot.nv}), got shape {np.shape(values)}"
            )
        v = np.abs(v) if absolute else v
        rgb, lo, hi = colormap_rgb(v, colormap, vmin, vmax)
        self._limits_on = False
        self._joint_rgb = [tuple(round(float(c), 3) for c in row) for row in rgb]
        self._send(
            self._color_commands(self.q)
            + [
                _delete(f"{self.root}/ui/limits"),
                self._ui(legend, colormap_legend(label, colormap, lo, hi)),
            ]
        )
        return {"values": v, "colors": rgb, "vmin": lo, "vmax": hi}

    # ------------------------------------------------------------------ overlays
    def _overlay_path(self, name: str) -> str:
        return f"{self.root}/overlays/{_safe(name)}"

    def clear(self, name: str | None = None) -> None:
        """Remove one overlay by name, or every overlay."""
        if name is None:
            self._overlay_bodies.clear()
            self._send([_delete(f"{self.root}/overlays")])
        else:
            self._overlay_bodies.pop(_safe(name), None)
            self._send([_delete(self._overlay_path(name))])
        self._movers = None

    @staticmethod
    def _triad(size: float, radius: float | None = None, opacity: float = 1.0) -> list[Piece]:
        r = radius if radius is not None else 0.06 * size
        cols = [(0.9, 0.1, 0.1), (0.1, 0.75, 0.1), (0.1, 0.25, 0.95)]
        out = []
        for i, c in enumerate(cols):
            e = np.zeros(3)
            e[i] = size
            out += cylinder_between(np.zeros(3), e, r, c, "triad", opacity)
        return out

    def show_frames(self, frames=None, size: float | None = None, name: str = "frames") -> None:
        """Coordinate triads (x red, y green, z blue) that follow the robot: ``frames`` is a
        list of frame names, ``None`` for the tool, or ``"joints"`` for every joint frame."""
        size = size if size is not None else 0.12 * self.radius
        robot = self.robot
        bodies = []
        if frames == "joints":
            for j in robot.chain.joints:
                bodies.append(Body(j.name, self._triad(size), joint=j.index))
        else:
            names = (
                [robot.tool]
                if frames is None
                else ([frames] if isinstance(frames, str) else list(frames))
            )
            for f in names:
                bodies.append(Body(str(f), self._triad(size), frame=robot.frame_id(f)))
        key = _safe(name)
        self.clear(key)
        self._overlay_bodies[key] = bodies
        self._movers = None
        self._send(self._body_objects(bodies, f"overlays/{key}"))
        self.display(self.q)

    def show_target(
        self, T, name: str = "target", size: float | None = None, rgb=(0.95, 0.55, 0.05)
    ) -> None:
        """An IK target: a translucent ball and a triad at ``T`` (4×4 pose, or a 3-vector
        position), in the robot's base frame, metres."""
        T = np.asarray(T, float)
        if T.shape == (3,) and np.all(np.isfinite(T)):
            T = homogeneous(r=T)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError(f"target must be a finite 4x4 pose or a 3-vector, got shape {T.shape}")
        size = size if size is not None else 0.1 * self.radius
        path = self._overlay_path(name)
        cmds = [
            _delete(path),
            _set_transform(path, T),
            _set_object(f"{path}/ball", mg.Sphere(0.35 * size), rgb, 0.45),
        ]
        for k, p in enumerate(self._triad(size, 0.05 * size)):
            cmds += [
                _set_object(f"{path}/triad/{k}", p.geometry, p.rgb),
                _set_transform(f"{path}/triad/{k}", p.offset),
            ]
        self._send(cmds)

    def show_trace(
        self,
        points,
        name: str = "trace",
        rgb=(0.80, 0.25, 0.60),
        radius: float | None = None,
        configurations: bool | None = None,
    ) -> np.ndarray:
        """A polyline through ``points`` (N, 3) in the base frame, or through the tool positions
        of a joint trajectory (N, nq) (``configurations=True``; guessed from the shape when
        None).  Drawn as thin cylinders so it is visible at any zoom.  Returns the (N, 3) points."""
        P = np.asarray(points, float)
        if configurations is None:
            configurations = P.ndim == 2 and P.shape[1] == self.robot.nq and P.shape[1] != 3
        if configurations:
            P = self.robot.fk(self.robot.check_q(P, "trajectory"))[:, :3, 3]
        if P.ndim != 2 or P.shape[1] != 3 or len(P) < 2:
            raise ValueError(
                f"trace needs (N>=2, 3) points or (N, {self.robot.nq}) configurations, got shape {P.shape}"
            )
        if not np.all(np.isfinite(P)):
            raise ValueError("trace points contain NaN or inf")
        r = radius if radius is not None else 0.005 * self.radius
        path = self._overlay_path(name)
        cmds = [_delete(path)]
        # thin out to at most 200 segments
        idx = np.unique(np.linspace(0, len(P) - 1, min(len(P), 201)).round().astype(int))
        Pk = P[idx]
        for k in range(len(Pk) - 1):
            for p in cylinder_between(Pk[k], Pk[k + 1], r, rgb, "trace"):
                cmds += [
                    _set_object(f"{path}/{k}", p.geometry, p.rgb),
                    _set_transform(f"{path}/{k}", p.offset),
                ]
        self._send(cmds)
        return P

    def show_workspace(
        self,
        n: int = 4000,
        rng=0,
        frame=None,
        name: str = "workspace",
        point_size: float | None = None,
    ) -> dict:
        """The reachable workspace of ``frame`` (default tool) as a point cloud of ``n`` random
        configurations inside the limits, coloured by translational manipulability
        (:func:`manipulability`; viridis, yellow = most dexterous), with its colour legend.
        Returns ``{"points": (n, 3), "manipulability": (n,)}``."""
        if int(n) < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        Q = self.robot.random_q(int(n), rng=rng)
        P = self.robot.fk(Q, frame)[:, :3, 3]
        w = manipulability(self.robot, Q, frame)
        top = float(w.max()) if w.size and w.max() > 0 else 1.0
        unit = f"m{'²³'[min(3, self.robot.nv) - 2]}" if self.robot.nv >= 2 else "m"
        self.show_points(
            P,
            values=w,
            colormap="viridis",
            vmin=0.0,
            vmax=top,
            size=point_size,
            name=name,
            label=f"manipulability ({unit}; yellow = most dexterous)",
        )
        return {"points": P, "manipulability": w}

    def show_points(
        self,
        points,
        colors=None,
        *,
        values=None,
        colormap: str = "viridis",
        vmin=None,
        vmax=None,
        size: float | None = None,
        name: str = "points",
        label: str | None = None,
    ) -> dict:
        """A 3-D point cloud (reachability and comfort maps, markers, sampled positions).

        Parameters
        ----------
        points : array_like, shape (N, 3)
            Positions in the robot's base frame, metres.
        colors : array_like, optional
            One colour ``(r, g, b)`` or one per point ``(N, 3)``, components in 0..1.  Default:
            a single orange, or the colour map of ``values``.
        values : array_like, shape (N,), optional
            A scalar per point, coloured through ``colormap`` from ``vmin`` to ``vmax`` (default:
            their range).  Not together with ``colors``.
        colormap : str
            A matplotlib colour map name (``"viridis"``, ``"viridis_r"``, ``"plasma"``, ...).
        size : float, optional
            Point size in metres (default 2 % of the reach).
        name : str
            Overlay name (:meth:`clear` removes it; a second call with the same name replaces it).
        label : str, optional
            Title of the colour legend drawn for ``values`` (default ``name``).

        Returns
        -------
        dict
            ``{"points": (N, 3), "colors": (N, 3), "vmin", "vmax"}`` (``vmin``/``vmax`` None
            without ``values``).

        Raises
        ------
        ParameterError
            Points not (N, 3) or not finite, colours outside 0..1, values of the wrong length
            or not finite, an unknown colour map, both ``colors`` and ``values``, or a size that
            is not positive.
        """
        P = _points3(points, "points")
        lo = hi = None
        if values is not None:
            if colors is not None:
                raise ParameterError("give colors or values (with a colormap), not both")
            v = np.asarray(values, dtype=float) if np.ndim(values) else np.array([np.nan])
            if v.shape != (len(P),):
                raise ParameterError(
                    f"values must have one number per point ({len(P)}), got shape {np.shape(values)}"
                )
            C, lo, hi = colormap_rgb(v, colormap, vmin, vmax)
        else:
            C = _rgb01((0.95, 0.55, 0.05) if colors is None else colors, len(P), "colors")
        size = self._length(size, 0.02 * self.radius, "size")
        cloud = mg.PointCloud(P.T.astype(np.float32), C.T.astype(np.float32), size=size)
        path = self._overlay_path(name)
        self._send([_delete(path), _set_object(path, cloud)])
        if values is not None:
            self._send(
                [self._ui(f"{path}/legend", colormap_legend(label or name, colormap, lo, hi))]
            )
        return {"points": P, "colors": C, "vmin": lo, "vmax": hi}

    def show_map(
        self,
        result,
        var: str | None = None,
        *,
        colormap: str | None = None,
        size: float | None = None,
        name: str | None = None,
    ) -> dict:
        """A voxel map of :mod:`anthroarm.batch` as a 3-D point cloud with its colour legend: one
        point at the centre of every reached voxel, coloured by its value.

        Parameters
        ----------
        result : anthroarm.batch.result.BatchResult
            A ``reachability_map`` (``counts``: configurations per voxel) or ``comfort_map``
            (``discomfort``: 0 = comfortable) result, computed for this robot (the voxel
            centres are in its base frame, m).
        var : str, optional
            The variable to draw (default: ``counts`` or ``discomfort`` by the job).
        colormap : str, optional
            Default ``viridis`` (``viridis_r`` for discomfort: yellow = comfortable).
        size : float, optional
            Point size, m (default: the voxel side).
        name : str, optional
            Overlay name (default: the job's name).

        Returns
        -------
        dict
            As :meth:`show_points`, plus ``"values"`` (K,).

        Raises
        ------
        ParameterError
            A result without a voxel map, or an unknown ``var``.
        """
        from ..batch.plot import _MAPS, occupied_points

        job = getattr(result, "job", None)
        variables = getattr(result, "variables", None)
        if not isinstance(variables, dict):
            raise ParameterError(
                f"show_map takes an anthroarm.batch result (reachability_map, comfort_map), "
                f"got {type(result).__name__}"
            )
        var = var or _MAPS.get(job)
        if var is None or var not in variables or tuple(result.dims(var)) != ("x", "y", "z"):
            raise ParameterError(
                f"{job}: no voxel map {var!r} to draw; voxel maps: "
                f"{[k for k in variables if tuple(result.dims(k)) == ('x', 'y', 'z')]}"
            )
        P, vals = occupied_points(result, var)
        if len(P) == 0:
            raise ParameterError(f"{job}: the map {var!r} has no reached voxel to draw")
        voxel = float(result.attrs.get("voxel", 0.0)) or None
        cmap = colormap or ("viridis_r" if var == "discomfort" else "viridis")
        note = (
            " (configurations per voxel)"
            if var == "counts"
            else " (0 = comfortable)"
            if var == "discomfort"
            else ""
        )
        out = self.show_points(
            P,
            values=np.asarray(vals, float),
            colormap=cmap,
            size=size or voxel,
            name=name or job or var,
            label=f"{job}: {var}{note}",
        )
        out["values"] = np.asarray(vals, float)
        return out

    def show_arrows(
        self,
        origins,
        directions,
        colors=None,
        *,
        scale: float = 1.0,
        radius: float | None = None,
        name: str = "arrows",
    ) -> np.ndarray:
        """Arrows (contact normals, forces, velocities) from ``origins`` along ``directions``.

        Parameters
        ----------
        origins : array_like, shape (N, 3)
            Tails in the robot's base frame, metres.
        directions : array_like, shape (N, 3)
            Arrow vectors; each is drawn ``scale`` times its length (a force in N with
            ``scale=0.01`` is 1 cm per newton).  A zero vector draws nothing.
        colors : array_like, optional
            One colour ``(r, g, b)`` or one per arrow ``(N, 3)``, 0..1 (default red).
        scale : float
            Metres of arrow per unit of ``directions`` (positive).
        radius : float, optional
            Shaft radius in metres (default 0.6 % of the reach); the head is 2.2 radii wide.
        name : str
            Overlay name (:meth:`clear` removes it).

        Returns
        -------
        numpy.ndarray
            The (N, 3) tips, base frame, metres.

        Raises
        ------
        ParameterError
            Shapes that differ or are not (N, 3), NaN or inf, bad colours, a scale or radius
            that is not positive and finite.
        """
        O = _points3(origins, "origins")
        D = _points3(directions, "directions")
        if D.shape != O.shape:
            raise ParameterError(
                f"origins and directions must have the same shape, got {O.shape} and {D.shape}"
            )
        scale = self._length(scale, 1.0, "scale")
        r = self._length(radius, 0.006 * self.radius, "radius")
        C = _rgb01((0.85, 0.10, 0.10) if colors is None else colors, len(O), "colors")
        V = scale * D
        mesh = arrow_mesh(O, V, r, C)
        path = self._overlay_path(name)
        cmds = [_delete(path)]
        if mesh is not None:
            cmds.append(_set_object(path, mesh, material=mg.MeshPhongMaterial(vertexColors=True)))
        self._send(cmds)
        return O + V

    @staticmethod
    def _length(value, default: float, what: str) -> float:
        if value is None:
            return float(default)
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ParameterError(f"{what} must be a positive number, got {value!r}")
        v = float(value)
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(f"{what} must be positive and finite, got {value!r}")
        return v

    # ------------------------------------------------------------------ teach
    def teach(self, on: bool = True, q=None) -> "Viewer":
        """Joint sliders on the page (like Robotics Toolbox's ``teach``): one per independent
        joint, in degrees (mm for a prismatic joint) within its limits (continuous or unbounded
        revolute joints ±180°); mimic joints follow their source.  Dragging a slider moves the
        robot at once, in a live tab, a Jupyter cell or an exported HTML file alike: the page
        computes the forward kinematics of ``robot.chain`` itself (the joint placements, axes
        and mimic relations sent with the sliders; tested against Pinocchio in a real browser),
        and shows the tool's position (mm) and roll, pitch, yaw (°, Pinocchio's ``rpy``
        convention) in the robot's base frame under the sliders.  With :meth:`show_limits` on,
        the links turn red as the sliders approach a limit.

        The sliders start at ``q`` (default: the configuration displayed now).  ``on=False``
        removes them.  The Python side is not told of the page's slider positions: call
        :meth:`display` to show a configuration from Python.  Returns the viewer."""
        path = f"{self.root}/ui/teach"
        self._teaching = bool(on)
        if not on:
            self._send([_delete(path)])
            return self
        if q is not None or self._animating:
            self.display(self.q if q is None else q)
        self._send([self._ui(path, self._teach_spec())])
        return self

    def _teach_spec(self) -> dict:
        chain = self.robot.chain
        theta = chain.angles(self.q)
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

    # ------------------------------------------------------------------ animation
    def play(self, Q, dt: float = 1 / 30, loop: bool = True, trace: bool = True) -> None:
        """Play the joint trajectory ``Q`` (N, nq), one row every ``dt`` seconds, as a meshcat
        animation (also stored in :meth:`static_html`).  ``trace`` draws the tool path."""
        Q = self.robot.check_q(Q, "Q")
        if Q.ndim != 2 or len(Q) < 2:
            raise ValueError(
                f"play needs a trajectory of shape (N>=2, {self.robot.nq}), got {Q.shape}"
            )
        if not (dt > 0 and math.isfinite(dt)):
            raise ValueError(f"dt must be positive and finite, got {dt}")
        if trace:
            self.show_trace(Q, configurations=True)
        fps = 1.0 / dt
        tracks: dict[str, tuple[list, list]] = {}
        for k, q in enumerate(Q):
            for cmd in self._pose_commands(q):
                M = np.asarray(cmd["matrix"]).reshape(4, 4).T
                quat = pin.Quaternion(M[:3, :3]).coeffs()  # x, y, z, w as three.js
                pos, rot = tracks.setdefault(cmd["path"], ([], []))
                pos.append({"time": k, "value": M[:3, 3].tolist()})
                rot.append({"time": k, "value": [float(c) for c in quat]})
        anims = [
            {
                "path": path,
                "clip": {
                    "fps": fps,
                    "name": "default",
                    "tracks": [
                        {"name": ".position", "type": "vector3", "keys": pos},
                        {"name": ".quaternion", "type": "quaternion", "keys": rot},
                    ],
                },
            }
            for path, (pos, rot) in tracks.items()
        ]
        cmd = {
            "type": "set_animation",
            "path": "",
            "animations": anims,
            "options": {"play": True, "repetitions": float("inf") if loop else 1},
        }
        self.display(Q[0])
        self._send([cmd])
        self._animating = True
        self.trajectory = Q

    # ------------------------------------------------------------------ output
    def static_html(self, title: str | None = None) -> str:
        """A self-contained HTML page (meshcat's JavaScript inlined) with the current scene and
        animation; opens offline in any browser."""
        return self.store.static_html(title or f"anthroarm — {self.robot.name}")

    def export_html(self, path) -> Path:
        """Write :meth:`static_html` to ``path`` atomically, as UTF-8 (its folder must exist,
        ``FileNotFoundError`` otherwise); returns the path."""
        path = Path(path)
        atomic_write_text(path, self.static_html())
        return path

    @property
    def scene(self) -> Scene:
        """The underlying meshcat scene, as a meshcat :class:`~meshcat.visualizer.Visualizer`
        (:class:`Scene`): the escape hatch for anything the Viewer has no method for.

        >>> import meshcat.geometry as mg
        >>> v.scene["mine/box"].set_object(mg.Box([0.1, 0.1, 0.1]))   # /meshcat/mine/box
        >>> v.scene["/Grid"].set_property("visible", True)
        >>> v.scene.set_cam_pos([1.5, 1.0, 0.8])

        Its commands go through the Viewer: they are kept in :meth:`static_html` and sent to
        the live server.  Coordinates are meshcat's world frame; the robot's base frame is
        shifted by ``-viewer.center`` in it (draw under ``viewer.root`` to use base-frame
        coordinates: ``v.scene[v.root + "/mine"]``)."""
        return Scene(window=_SceneWindow(self))

    @property
    def url(self) -> str | None:
        """Browser URL of the live server (None when not live)."""
        return self.server.web_url if self.server is not None else None

    def open(self) -> "Viewer":
        """Open the live scene in the default web browser."""
        if self.server is None:
            raise RuntimeError(
                "this viewer is not live; create it with live=True, or use export_html()"
            )
        import webbrowser

        webbrowser.open(self.url, new=2)
        return self

    def wait(self, n: int = 1, timeout: float = 30.0) -> None:
        """Block until ``n`` browser tabs are connected to the live server; ViewerError after
        ``timeout`` seconds.  ``n`` in 1..1024 and a finite ``timeout`` in (0, 3600] s
        (:class:`~anthroarm.errors.ParameterError`, a TypeError/ValueError, otherwise)."""
        if self.server is None:
            raise RuntimeError("this viewer is not live")
        self.server.wait(n, timeout)

    def _iframe(self, height: int) -> str:
        if self.server is not None:
            src = f'src="{self.url}"'
        else:
            src = f'srcdoc="{_html.escape(self.static_html(), quote=True)}"'
        return (
            f'<div style="height: {int(height)}px; width: 100%; overflow: hidden; resize: both">'
            f'<iframe {src} style="width: 100%; height: 100%; border: none"></iframe></div>'
        )

    def jupyter_cell(self, height: int = 420):
        """Inline view for Jupyter: the live page when live, else a static snapshot that works
        without any server (and in exported notebooks)."""
        from IPython.display import HTML

        return HTML(self._iframe(height))

    def _repr_html_(self) -> str:
        return self._iframe(420)

    def close(self) -> None:
        """Stop the server (if live).  The in-memory scene stays usable for export."""
        if self.server is not None:
            self.server.close()
            self.server = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self) -> str:
        where = self.url if self.server is not None else "in memory"
        return f"Viewer({self.robot.name!r}, {where})"
