"""What the camera frames (:meth:`~anthroarm.viewer.Viewer.set_camera`): named views, the
subject (``fit``), the hand of a limb, and the extents of the overlays.

meshcat's orbit camera always looks at the world origin; the Viewer moves the robot's scene
root so that the centre of the subject's box sits there (``viewer.center``, base frame), then
puts the camera at the distance where the whole box fills ``fill`` of the 75° vertical field of
view and of the horizontal one of a 4:3 view (:func:`framing_distance`).  The camera is then
outside the box: every corner lies in front of it.

Subjects (``fit``):

* ``"pose"``: the robot as displayed now (the bounding boxes of its drawn pieces);
* ``"all"``: the robot and everything drawn around it (points, voxel maps, targets, traces and
  the poses of an animation);
* ``"reach"``: the box around the robot's workspace (128 random configurations);
* ``"hand"``: the hand (:func:`hand_joints`) of a limb that ends in one, else the pose;
* ``"auto"`` (the default): the hand of a limb whose hand is small beside the limb
  (``human_upper_limb``: the fingers are readable at first sight), as long as nothing else is
  drawn; otherwise ``"all"``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

#: Named camera directions (base frame, z up; +x is in front of the catalog's person).
VIEWS = {
    "iso": (0.9, 1.0, 0.45),
    "front": (1.0, 0.0, 0.12),
    "back": (-1.0, 0.0, 0.12),
    "side": (0.0, 1.0, 0.12),
    "top": (0.02, 0.0, 1.0),
}

#: What the camera can frame (see the module docstring).
FITS = ("auto", "pose", "all", "reach", "hand")

#: ``fit="auto"`` zooms on the hand when its box is at most this fraction of the pose's box.
HAND_ZOOM_RATIO = 0.5

#: Width / height of the 3-D pane beside an open teach panel (about 560 px of the page's width
#: go to the panel; 0.7 is a 1000 × 700 page, wider pages leave a wider pane).
TEACH_ASPECT = 0.7

#: Most points of one overlay kept for the framing (a subsample and its extremes).
EXTENT_POINTS = 4096

#: Most configurations of an animation whose poses count in its extent.
ANIMATION_SAMPLES = 24


def view_direction(view) -> np.ndarray:
    """The unit direction (3,) from the subject to the camera: a name of :data:`VIEWS` or a
    non-zero finite 3-vector (base-frame axes)."""
    if isinstance(view, str):
        if view not in VIEWS:
            raise ParameterError(f"camera view must be one of {sorted(VIEWS)}, got {view!r}")
        view = VIEWS[view]
    d = np.asarray(view, float)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) < 1e-9:
        raise ParameterError(
            f"camera direction must be a view name {sorted(VIEWS)} or a non-zero finite "
            f"3-vector, got {view!r}"
        )
    return d / np.linalg.norm(d)


def check_fit(fit: str) -> str:
    if fit not in FITS:
        raise ParameterError(f"fit must be one of {list(FITS)}, got {fit!r}")
    return fit


def hand_joints(chain) -> frozenset[int] | None:
    """Chain-joint indices of the hand of a limb: when the model branches into three or more
    tips (fingers) below a common joint, that joint (it moves the palm) and every joint below
    it.  None for a serial arm or a model that branches at its base (a hand on its own)."""
    paths = [chain.path(t) for t in chain.tips]
    if len(paths) < 3:
        return None
    common = 0
    while all(len(p) > common for p in paths) and len({p[common] for p in paths}) == 1:
        common += 1
    if common == 0:
        return None
    top = paths[0][common - 1]
    below, stack = {top}, [top]
    while stack:
        for c in chain.children(stack.pop()):
            below.add(c)
            stack.append(c)
    return frozenset(below)


def body_joint(chain, body) -> int | None:
    """The chain joint that moves ``body`` (a viewer Body), None when fixed to the base."""
    if body.joint is not None:
        return int(body.joint)
    if body.frame is not None:
        j = chain.frames[body.frame].joint
        return int(j) if j >= 0 else None
    return None


def box_diagonal(points) -> float:
    P = np.asarray(points, float)
    return float(np.linalg.norm(P.max(0) - P.min(0))) if len(P) else 0.0


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
