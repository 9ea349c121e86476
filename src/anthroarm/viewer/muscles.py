"""An OpenSim model's muscles in the viewer (issue 34): each muscle's path at ``q`` — its active
path points and, where it wraps, the tangent points and the arc on the wrap surface
(:func:`anthroarm.muscles.path_points`) — drawn as a thin shaded tube, coloured by activation
from relaxed (blue) to fully active (red) when activations are given.

>>> import anthroarm as aa
>>> from anthroarm.viewer import Viewer
>>> from anthroarm.viewer.muscles import show_muscles
>>> robot = aa.load(aa.osim.path("arm26"))
>>> v = Viewer(robot)
>>> drawn = show_muscles(v, robot.default_q(), activations=[0, 0.2, 0.2, 1, 1, 0.5])

The paths are drawn at ``q`` (they do not follow later :meth:`~anthroarm.viewer.Viewer.display`
calls: call :func:`show_muscles` again, which replaces the previous drawing).  Units: m, the
model's ground frame (the robot's base frame).
"""

from __future__ import annotations

import meshcat.geometry as mg
import numpy as np

from .. import muscles as mus
from ..errors import MuscleError
from .checks import positive_length
from .messages import delete, safe_name, set_object
from .shapes import tube_mesh

#: colour of a muscle drawn without activations, of a relaxed one (a = 0), of a fully active
#: one (a = 1); in between the linear blend (1 − a) RELAXED + a ACTIVE
MUSCLE_RGB = (0.75, 0.22, 0.18)
RELAXED_RGB = (0.20, 0.30, 0.85)
ACTIVE_RGB = (0.90, 0.10, 0.08)
#: how much shorter (m) a drawn cylinder or sphere arc may be than the arc (its chord count)
DRAW_TOLERANCE = 1e-6


def activation_rgb(a) -> np.ndarray:
    """RGB (M, 3) of activations ``a`` (M,) in [0, 1]: (1 − a) RELAXED_RGB + a ACTIVE_RGB."""
    a = np.asarray(a, float)[:, None]
    return (1.0 - a) * np.asarray(RELAXED_RGB) + a * np.asarray(ACTIVE_RGB)


def _activations(activations, names: list) -> np.ndarray | None:
    """``activations`` (a sequence in the drawn muscles' order, or ``{name: a}`` for all of
    them) as an (M,) array in [0, 1]; :class:`~anthroarm.errors.MuscleError` otherwise."""
    if activations is None:
        return None
    if isinstance(activations, dict):
        missing = [n for n in names if n not in activations]
        extra = [n for n in activations if n not in names]
        if missing or extra:
            raise MuscleError(
                f"activations: no value for {missing}" if missing else f"no muscle {extra}"
            )
        activations = [activations[n] for n in names]
    try:
        a = np.asarray(activations, dtype=float)
    except (TypeError, ValueError) as exc:
        raise MuscleError(f"activations must be numbers in [0, 1], got {activations!r}") from exc
    if a.shape != (len(names),):
        raise MuscleError(f"activations: one per muscle drawn ({len(names)}), got shape {a.shape}")
    bad = ~((a >= 0.0) & (a <= 1.0))  # NaN fails both
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MuscleError(f"activation of {names[i]!r} is {a[i]}: not in [0, 1]")
    return a


def show_muscles(
    viewer,
    q=None,
    activations=None,
    muscles=None,
    *,
    radius: float | None = None,
    name: str = "muscles",
) -> dict:
    """Draw the muscles of ``viewer.robot`` (an OpenSim model) at ``q`` (default: the viewer's
    current configuration), replacing the previous drawing of overlay ``name``.

    ``muscles``: which ones — None (all the model's), a list of names, or anything
    :func:`anthroarm.muscles.muscle_set` takes; ``activations`` (optional): one value in [0, 1]
    per muscle drawn, in that order, or ``{name: a}``; outside [0, 1], NaN, or the wrong count:
    :class:`~anthroarm.errors.MuscleError`.  ``radius``: the tube's, m (default 0.4 % of the
    viewer's reach).  Each muscle is one shaded mesh at ``<overlay>/<muscle name>``, 8 vertices
    round each of its path's points.  Returns ``{muscle name: number of path points drawn}``.
    """
    robot = viewer.robot
    q = viewer.q if q is None else robot.check_q(q, "q")
    if isinstance(muscles, (list, tuple)):
        ms = mus.muscle_set(robot).select(list(muscles))
    else:
        ms = mus.muscle_set(robot, muscles)
    a = _activations(activations, ms.names)
    r = positive_length(radius, 0.004 * viewer.radius, "radius")
    paths = mus.path_points(robot, ms, q, tolerance=DRAW_TOLERANCE)
    root = viewer._overlay_path(name)
    cmds = [delete(root)]
    drawn = {}
    every = []
    for i, (mname, mp) in enumerate(paths.items()):
        rgb = MUSCLE_RGB if a is None else activation_rgb(a[i : i + 1])[0]
        mesh = tube_mesh(mp.points, r, rgb)
        if mesh is not None:
            material = mg.MeshPhongMaterial(vertexColors=True)
            cmds.append(set_object(f"{root}/{safe_name(mname)}", mesh, material=material))
        drawn[mname] = len(mp.points)
        every.append(mp.points)
    viewer._send(cmds)
    if every:
        viewer._add_extent(safe_name(name), np.concatenate(every))  # framing "all" sees them
    return drawn


__all__ = ["show_muscles", "activation_rgb", "MUSCLE_RGB", "RELAXED_RGB", "ACTIVE_RGB"]
