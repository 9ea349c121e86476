"""What a :class:`~anthroarm.viewer.Viewer` draws over the robot: coordinate frames, IK targets,
traces, point clouds (workspace, voxel maps), arrows, and the colouring of the links by
joint-limit proximity or by a value per joint, each with its colour legend.

:class:`OverlaysMixin` is one part of :class:`~anthroarm.viewer.Viewer`.  Coordinates are the
robot's base frame, metres (like ``robot.fk``).

Function-local import (heavy: it pulls in the batch package and Numba): ``anthroarm.batch.plot``
in :meth:`OverlaysMixin.show_map`, only when a voxel map is drawn.
"""

from __future__ import annotations

import meshcat.geometry as mg
import numpy as np

from ..batch.plot import MAP_VARIABLES, occupied_points
from ..errors import ParameterError
from ..spatial.rotations import homogeneous
from .checks import points3, positive_length, rgb01
from .colors import (
    colormap_legend,
    colormap_rgb,
    limit_color,
    limit_proximity,
    limits_legend,
)
from .messages import delete, safe_name, set_color, set_object, set_transform, ui
from .shapes import Body, arrow_mesh, cylinder_between, triad

#: Opacity of a voxel map's points (:meth:`OverlaysMixin.show_map`).
MAP_OPACITY = 0.35
#: A voxel map's point size as a fraction of the voxel side.
MAP_POINT_FRACTION = 0.5


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


class OverlaysMixin:
    """Frames, targets, traces, point clouds, arrows and link colours (a part of
    :class:`~anthroarm.viewer.Viewer`)."""

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
            prox = limit_proximity(self.robot.angles(q), self._joint_lower, self._joint_upper)
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
                        cmds.append(set_object(f"{path}/{k}", p.geometry, p.rgb, p.opacity))
                        if not np.allclose(p.offset, np.eye(4)):
                            cmds.append(set_transform(f"{path}/{k}", p.offset))
            else:
                cmds.append(set_color(path, rgb))
        return cmds

    def show_limits(self, on: bool = True) -> None:
        """Colour each link by how close its joint is to a limit (red within the last 15 %),
        with a colour legend; joints without limits (continuous joints) are skipped.
        ``on=False`` restores the colours and removes the legend."""
        self._limits_on = bool(on)
        if self._limits_on and self._joint_rgb is not None:  # one colouring at a time
            self._joint_rgb = None
            self._send([delete(f"{self.root}/ui/joint_values")])
        legend = f"{self.root}/ui/limits"
        if self._limits_on:
            cmds = [ui(legend, limits_legend())]
        else:
            cmds = [delete(legend)]
        if self._teaching:  # the sliders recolour as they move (or stop doing so)
            cmds.append(ui(f"{self.root}/ui/teach", self._teach_spec()))
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
            self._send(self._color_commands(self.q) + [delete(legend)])
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
                delete(f"{self.root}/ui/limits"),
                ui(legend, colormap_legend(label, colormap, lo, hi)),
            ]
        )
        return {"values": v, "colors": rgb, "vmin": lo, "vmax": hi}

    def _overlay_path(self, name: str) -> str:
        return f"{self.root}/overlays/{safe_name(name)}"

    def clear(self, name: str | None = None) -> None:
        """Remove one overlay by name, or every overlay."""
        if name is None:
            self._overlay_bodies.clear()
            self._send([delete(f"{self.root}/overlays")])
        else:
            self._overlay_bodies.pop(safe_name(name), None)
            self._send([delete(self._overlay_path(name))])
        self._movers = None
        self._drop_extent(None if name is None else safe_name(name))

    def show_frames(self, frames=None, size: float | None = None, name: str = "frames") -> None:
        """Coordinate triads (x red, y green, z blue) that follow the robot: ``frames`` is a
        list of frame names, ``None`` for the tool, or ``"joints"`` for every joint frame."""
        size = size if size is not None else 0.12 * self.radius
        robot = self.robot
        bodies = []
        if frames == "joints":
            for j in robot.chain.joints:
                bodies.append(Body(j.name, triad(size), joint=j.index))
        else:
            names = (
                [robot.tool]
                if frames is None
                else ([frames] if isinstance(frames, str) else list(frames))
            )
            for f in names:
                bodies.append(Body(str(f), triad(size), frame=robot.frame_id(f)))
        key = safe_name(name)
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
            delete(path),
            set_transform(path, T),
            set_object(f"{path}/ball", mg.Sphere(0.35 * size), rgb, 0.45),
        ]
        for k, p in enumerate(triad(size, 0.05 * size)):
            cmds += [
                set_object(f"{path}/triad/{k}", p.geometry, p.rgb),
                set_transform(f"{path}/triad/{k}", p.offset),
            ]
        self._send(cmds)
        self._add_extent(safe_name(name), T[:3, 3] + np.array([[-size], [size]]))

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
        cmds = [delete(path)]
        # thin out to at most 200 segments
        idx = np.unique(np.linspace(0, len(P) - 1, min(len(P), 201)).round().astype(int))
        Pk = P[idx]
        for k in range(len(Pk) - 1):
            for p in cylinder_between(Pk[k], Pk[k + 1], r, rgb, "trace"):
                cmds += [
                    set_object(f"{path}/{k}", p.geometry, p.rgb),
                    set_transform(f"{path}/{k}", p.offset),
                ]
        self._send(cmds)
        self._add_extent(safe_name(name), P)
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
        opacity: float = 1.0,
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
        opacity : float
            In (0, 1]; below 1 the points are see-through (and do not hide each other's
            background): a dense map around the robot leaves the robot visible.

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
        P = points3(points, "points")
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
            C = rgb01((0.95, 0.55, 0.05) if colors is None else colors, len(P), "colors")
        size = positive_length(size, 0.02 * self.radius, "size")
        if not (isinstance(opacity, (int, float)) and 0.0 < float(opacity) <= 1.0):
            raise ParameterError(f"opacity must be in (0, 1], got {opacity!r}")
        cloud = mg.PointCloud(P.T.astype(np.float32), C.T.astype(np.float32), size=size)
        path = self._overlay_path(name)
        made = set_object(path, cloud)
        if opacity < 1.0:
            for m in made["object"]["materials"]:
                m.update(transparent=True, opacity=float(opacity), depthWrite=False)
        self._send([delete(path), made])
        if values is not None:
            self._send([ui(f"{path}/legend", colormap_legend(label or name, colormap, lo, hi))])
        self._add_extent(safe_name(name), P)
        return {"points": P, "colors": C, "vmin": lo, "vmax": hi}

    def show_map(
        self,
        result,
        var: str | None = None,
        *,
        colormap: str | None = None,
        size: float | None = None,
        name: str | None = None,
        opacity: float = MAP_OPACITY,
    ) -> dict:
        """A voxel map of :mod:`anthroarm.batch` as a 3-D point cloud with its colour legend: one
        point at the centre of every reached voxel, coloured by its value, see-through
        (``opacity``) so the robot inside stays visible; the camera then frames the map and the
        robot from outside the cloud (unless
        :meth:`~anthroarm.viewer.scene.SceneMixin.set_camera` was given a distance).

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
            Point size, m (default: half the voxel side, so the cloud has gaps to see through).
        name : str, optional
            Overlay name (default: the job's name).
        opacity : float
            In (0, 1] (default :data:`MAP_OPACITY`).

        Returns
        -------
        dict
            As :meth:`show_points`, plus ``"values"`` (K,).

        Raises
        ------
        ParameterError
            A result without a voxel map, or an unknown ``var``.
        """
        job = getattr(result, "job", None)
        variables = getattr(result, "variables", None)
        if not isinstance(variables, dict):
            raise ParameterError(
                f"show_map takes an anthroarm.batch result (reachability_map, comfort_map), "
                f"got {type(result).__name__}"
            )
        var = var or MAP_VARIABLES.get(job)
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
            size=size or (MAP_POINT_FRACTION * voxel if voxel else None),
            name=name or job or var,
            label=f"{job}: {var}{note}",
            opacity=opacity,
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
        O = points3(origins, "origins")
        D = points3(directions, "directions")
        if D.shape != O.shape:
            raise ParameterError(
                f"origins and directions must have the same shape, got {O.shape} and {D.shape}"
            )
        scale = positive_length(scale, 1.0, "scale")
        r = positive_length(radius, 0.006 * self.radius, "radius")
        C = rgb01((0.85, 0.10, 0.10) if colors is None else colors, len(O), "colors")
        V = scale * D
        mesh = arrow_mesh(O, V, r, C)
        path = self._overlay_path(name)
        cmds = [delete(path)]
        if mesh is not None:
            cmds.append(set_object(path, mesh, material=mg.MeshPhongMaterial(vertexColors=True)))
        self._send(cmds)
        return O + V
