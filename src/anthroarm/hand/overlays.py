"""Grasp overlays in the viewer: the object, the contact points and the inward normals.

:func:`show_grasp` draws on an :class:`anthroarm.viewer.viewer.Viewer` (base frame of its robot,
metres): the contact points with :meth:`~anthroarm.viewer.viewer.Viewer.show_points`, the
inward surface normals −m (where the pads press) with
:meth:`~anthroarm.viewer.viewer.Viewer.show_arrows`, and the sphere or cylinder as a meshcat
primitive under the robot's scene root (``Viewer.scene``), so it moves with the robot's
placement in the scene.  meshcat's cylinder runs along its own y axis; the transform maps it
onto the cylinder's axis.
"""

from __future__ import annotations

import numpy as np

from .objects import Cylinder, Sphere


def object_transform(obj) -> np.ndarray:
    """4×4 pose of meshcat's primitive for ``obj``: centre at the object's centre and, for a
    cylinder, meshcat's y axis along the cylinder's axis (a right-handed frame)."""
    T = np.eye(4)
    T[:3, 3] = obj.center
    if isinstance(obj, Cylinder):
        y = obj.axis
        e = np.eye(3)[int(np.argmin(np.abs(y)))]
        x = e - (e @ y) * y
        x /= np.linalg.norm(x)
        T[:3, :3] = np.column_stack([x, y, np.cross(x, y)])
    return T


def show_grasp(
    viewer,
    obj,
    contacts,
    *,
    length: float | None = None,
    name: str = "grasp",
    color: int = 0xD9D2C0,
    opacity: float = 0.85,
    arrow: float = 0.035,
) -> None:
    """Draw ``obj`` (Sphere or Cylinder), the ``contacts`` (n, 3) and −m at each.

    ``length`` (m) is the drawn cylinder's length (default: the cylinder's own, else 4 radii);
    ``arrow`` the normals' length (m); ``name`` the overlays' prefix (``viewer.clear`` removes the
    points and arrows; the object is ``<root>/overlays/<name>_object``)."""
    import meshcat.geometry as mg

    if not isinstance(obj, (Sphere, Cylinder)):
        raise TypeError(
            f"show_grasp draws a hand.Sphere or hand.Cylinder, got {type(obj).__name__}"
        )
    contacts = np.asarray(contacts, dtype=float).reshape(-1, 3)
    viewer.show_points(contacts, colors=(0.1, 0.65, 0.2), name=f"{name}_points")
    viewer.show_arrows(
        contacts,
        -arrow * np.array([obj.normal(c) for c in contacts]),
        colors=(0.9, 0.2, 0.1),
        name=f"{name}_normals",
    )
    if isinstance(obj, Cylinder):
        h = length or obj.length or 4.0 * obj.radius
        geom = mg.Cylinder(h, obj.radius)
    else:
        geom = mg.Sphere(obj.radius)
    node = viewer.scene[viewer.root.removeprefix("/meshcat/") + f"/overlays/{name}_object"]
    node.set_object(
        geom, mg.MeshLambertMaterial(color=color, opacity=opacity, transparent=opacity < 1.0)
    )
    node.set_transform(object_transform(obj))
