"""The README picture: the human upper limb holding an upright glass in front of the body
(:func:`anthroarm.hand.demo.cup_grasp`), drawn in the viewer with the grasp's contact points,
inward normals and the glass (:func:`anthroarm.hand.overlays.show_grasp`), and taken as a
headless-Chromium screenshot (:func:`anthroarm.viewer.browser.screenshot`)::

    python -m anthroarm.viewer.grasp_picture docs/hand_grasp_viewer.png

(It lived in ``anthroarm.hand.demo``, which finds the grasp; drawing it is the viewer's part.)
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from ..hand.demo import cup_grasp
from ..hand.grasp import grasp_errors
from ..hand.overlays import show_grasp
from ..ik.qp import IKConfiguration
from .browser import screenshot
from .viewer import Viewer


def grasp_viewer(robot=None) -> Viewer:
    """A :class:`~anthroarm.viewer.Viewer` of :func:`~anthroarm.hand.demo.cup_grasp`: the limb
    at the grasp, the glass, the contact points and normals, framed from the front-left."""
    robot, h, q, glass = cup_grasp(robot)
    _, _, contacts, _ = grasp_errors(h, IKConfiguration(robot, q), glass)
    v = Viewer(robot, q=q)
    show_grasp(v, glass, contacts)
    v.set_camera((0.5, 1.0, 0.25), fit="all")
    return v


def readme_picture(png, size=(960, 640)) -> Path:
    """Screenshot of :func:`grasp_viewer`, written to ``png``."""
    v = grasp_viewer()
    with tempfile.TemporaryDirectory() as d:
        html = v.export_html(Path(d) / "grasp.html")
        return screenshot(html, png, size=size, budget_ms=3000)


if __name__ == "__main__":  # pragma: no cover
    import sys

    print(readme_picture(sys.argv[1] if len(sys.argv) > 1 else "hand_grasp_viewer.png"))
