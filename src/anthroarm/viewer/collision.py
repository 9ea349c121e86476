"""What the robot's bodies occupy, in the viewer: its collision bodies (issue 33), the colliding
ones in red, the obstacles, and the closest pair joined by a line with its distance as a note.

>>> import anthroarm as aa
>>> from anthroarm.viewer import Viewer
>>> from anthroarm.viewer.collision import show_collisions
>>> robot = aa.load("human_upper_limb")
>>> v = Viewer(robot)
>>> info = show_collisions(v, robot.neutral(), [aa.collision.sphere(0.05, xyz=(0.1, 0.2, -0.4))])

The bodies are drawn at ``q`` (they do not follow later :meth:`~anthroarm.viewer.Viewer.display`
calls: call :func:`show_collisions` again, as ``teach`` does on each slider move when given
``collisions=True``).  Capsules, spheres, boxes and cylinders are drawn as such; a convex hull
as its triangles.  Units: m, the robot's base frame.
"""

from __future__ import annotations

import coal
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from .. import collision
from .messages import delete, safe_name, set_object, set_transform, ui
from .shapes import capsule, cylinder_between

#: colours: a colliding body, a free one, an obstacle, the closest pair's line
HIT_RGB = (0.9, 0.1, 0.1)
FREE_RGB = (0.55, 0.75, 0.95)
OBSTACLE_RGB = (0.6, 0.6, 0.6)
CLOSEST_RGB = (1.0, 0.8, 0.0)


def _pieces(shape, M: np.ndarray, rgb) -> list:
    """(geometry, 4×4 pose) of one coal shape at world pose M."""
    if isinstance(shape, coal.Capsule):
        h = float(shape.halfLength)
        a, b = M[:3, :3] @ [0, 0, -h] + M[:3, 3], M[:3, :3] @ [0, 0, h] + M[:3, 3]
        return [(p.geometry, p.offset) for p in capsule(a, b, float(shape.radius), rgb)]
    if isinstance(shape, coal.Cylinder):
        h = float(shape.halfLength)
        a, b = M[:3, :3] @ [0, 0, -h] + M[:3, 3], M[:3, :3] @ [0, 0, h] + M[:3, 3]
        return [(p.geometry, p.offset) for p in cylinder_between(a, b, float(shape.radius), rgb)]
    if isinstance(shape, coal.Sphere):
        return [(mg.Sphere(float(shape.radius)), M)]
    if isinstance(shape, coal.Box):
        return [(mg.Box((2 * np.asarray(shape.halfSide)).tolist()), M)]
    if isinstance(shape, coal.ConvexBase):
        pts = np.array([shape.points(i) for i in range(shape.num_points)])
        tris = []
        for k in range(shape.num_polygons):
            poly = shape.polygons(k)
            idx = [int(poly[i]) for i in range(poly.size())]
            tris += [(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)]
        return [(mg.TriangularMeshGeometry(pts, np.array(tris, dtype=np.uint32)), M)]
    return []


def show_collisions(viewer, q=None, obstacles=None, name: str = "collisions", opacity: float = 0.5):
    """Draw the collision bodies of ``viewer.robot`` at ``q`` (default: the viewer's current
    configuration) and ``obstacles``; bodies of a pair in collision red, the others light blue;
    the closest pair's witness points joined by a yellow line and its names and distance in a
    note.  Returns ``{"colliding": [(a, b), ...], "closest": (a, b, d) or None}``."""
    robot = viewer.robot
    q = viewer.q if q is None else robot.check_q(q, "q")
    cm = collision.model(robot)
    env = collision.environment(obstacles)
    dist = collision.distances(robot, q, env)
    hit_pairs = dist.colliding()
    hit = {n for pair in hit_pairs for n in pair}
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    root = viewer._overlay_path(name)
    cmds = [delete(root)]
    bodies = [
        (g.name, g.geometry, (data.oMi[int(g.parentJoint)] * g.placement).homogeneous, None)
        for g in cm.geometry.geometryObjects
    ] + [(o.name, o.geometry, o.pose.homogeneous, OBSTACLE_RGB) for o in env.obstacles]
    for bname, shape, M, rgb in bodies:
        rgb = rgb or (HIT_RGB if bname in hit else FREE_RGB)
        for k, (geom, T) in enumerate(_pieces(shape, M, rgb)):
            path = f"{root}/{bname}/{k}"
            cmds += [set_object(path, geom, HIT_RGB if bname in hit else rgb, opacity)]
            cmds += [set_transform(path, T)]
    closest = dist.closest
    if closest is not None:
        k = int(np.argmin(dist.distance))
        a, b = dist.point_a[k], dist.point_b[k]
        if np.linalg.norm(b - a) > 1e-6:
            for j, p in enumerate(cylinder_between(a, b, 0.002, CLOSEST_RGB)):
                cmds += [set_object(f"{root}/closest/{j}", p.geometry, CLOSEST_RGB)]
                cmds += [set_transform(f"{root}/closest/{j}", p.offset)]
        text = f"closest: {closest[0]} – {closest[1]}: {1e3 * closest[2]:.1f} mm"
        if hit_pairs:
            text += f"; in collision: {', '.join(f'{x}–{y}' for x, y in hit_pairs[:4])}"
            text += " …" if len(hit_pairs) > 4 else ""
        cmds.append(ui(f"{root}/note", {"kind": "note", "text": text}))
    viewer._send(cmds)
    P = np.array([M[:3, 3] for _, _, M, _ in bodies]).reshape(-1, 3)
    viewer._add_extent(safe_name(name), P)  # framing "all" includes the bodies
    return {"colliding": hit_pairs, "closest": closest}


__all__ = ["show_collisions", "HIT_RGB", "FREE_RGB", "OBSTACLE_RGB", "CLOSEST_RGB"]
