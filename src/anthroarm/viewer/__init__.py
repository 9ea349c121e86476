"""meshcat browser viewer.

>>> import anthroarm as aa
>>> v = aa.viewer.Viewer("human_arm7")                  # scene in memory
>>> v.show_workspace(); v.show_limits(); v.export_html("arm.html")
>>> live = aa.viewer.Viewer("human_arm7", live=True)     # server on 127.0.0.1, browser tab
>>> live.open()

:class:`Viewer` — poses (one message per update), overlays (frames, IK target, workspace
coloured by manipulability, joint-limit colours, trace, point clouds, arrows), animation
playback, static HTML export, Jupyter cells; ``Viewer.scene`` is the underlying meshcat scene
(a meshcat ``Visualizer``, :class:`Scene`) for anything else.

The modules: :mod:`~anthroarm.viewer.viewer` (the :class:`Viewer`, composed of
:mod:`~anthroarm.viewer.scene`, :mod:`~anthroarm.viewer.overlays`,
:mod:`~anthroarm.viewer.teach`, :mod:`~anthroarm.viewer.export` and
:mod:`~anthroarm.viewer.live`); what it draws: :mod:`~anthroarm.viewer.visuals` (a robot's
bodies), :mod:`~anthroarm.viewer.shapes`, :mod:`~anthroarm.viewer.meshes`,
:mod:`~anthroarm.viewer.colors`, :mod:`~anthroarm.viewer.collision` (collision bodies),
:mod:`~anthroarm.viewer.muscles` (an OpenSim model's muscle paths); how: :mod:`~anthroarm.viewer.messages` (the commands),
:mod:`~anthroarm.viewer.checks` (argument checks); :mod:`~anthroarm.viewer.server` runs the
127.0.0.1-only server process; :mod:`~anthroarm.viewer.browser` takes headless-Chromium
screenshots (tests, docs); :mod:`~anthroarm.viewer.demo` is ``anthroarm demo``.
"""

from .collision import show_collisions
from .muscles import show_muscles
from .viewer import (
    Scene,
    Viewer,
    arrow_mesh,
    colormap_rgb,
    limit_color,
    limit_proximity,
    manipulability,
)

__all__ = [
    "Scene",
    "Viewer",
    "arrow_mesh",
    "colormap_rgb",
    "limit_color",
    "limit_proximity",
    "manipulability",
    "show",
    "show_collisions",
    "show_muscles",
]


def show(robot, q=None, **kwargs) -> Viewer:
    """One-liner: a :class:`Viewer` of ``robot`` (name or Robot) at ``q``."""
    v = Viewer(robot, **kwargs)
    if q is not None:
        v.display(q)
    return v
