"""A :class:`~anthroarm.viewer.Viewer`'s scene out of Python: animations (:meth:`ExportMixin.play`),
the self-contained HTML page, and Jupyter cells.

:class:`ExportMixin` is one part of :class:`~anthroarm.viewer.Viewer`.

Function-local import (optional: Jupyter's IPython, not a dependency of anthroarm):
``IPython.display`` in :meth:`ExportMixin.jupyter_cell`.
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np
import pinocchio as pin

from .._io import atomic_write_text
from .messages import stop_animation


class ExportMixin:
    """Animation playback, static HTML and Jupyter output (a part of
    :class:`~anthroarm.viewer.Viewer`)."""

    def stop(self) -> None:
        """Stop and forget the animation set by :meth:`play` (``display`` does this too)."""
        self._animating = False
        self._send([stop_animation()])

    def play(self, Q, dt: float = 1 / 30, loop: bool = True, trace: bool = True) -> None:
        """Play the joint trajectory ``Q`` (N, nq), one row every ``dt`` seconds, as a meshcat
        animation (also stored in :meth:`static_html`).  ``trace`` draws the tool path.  The
        camera then frames the robot over the whole motion (``fit="all"`` of
        :meth:`~anthroarm.viewer.scene.SceneMixin.set_camera`), unless it was placed at a given
        distance."""
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
        self._animation_extent(Q)  # the camera frames every pose (unless given a distance)
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

    def _iframe(self, height: int) -> str:
        if self.server is not None:
            src = f'src="{self.url}"'
        else:
            src = f'srcdoc="{html.escape(self.static_html(), quote=True)}"'
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
