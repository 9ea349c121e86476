"""Viewer pages for the applications' reports (the viewer draws; the applications compute and
never import the viewer, a face above them):

* :func:`activities_html`: the activities of a prosthesis sizing study
  (:class:`anthroarm.prosthesis.study.Study`) as one looping animation, the fragment
  :func:`anthroarm.prosthesis.report.render` embeds (``viewer=``);
* :func:`motion_viewer`: a Viewer playing a joint trajectory sampled every ``every`` frames (the
  arm of an EMG-driven simulation, :class:`anthroarm.emg.simulate.PoweredHandResult`).
"""

from __future__ import annotations

import html

import numpy as np

from .viewer import Viewer


def _e(x) -> str:
    return html.escape(str(x), quote=True)


def activities_html(study, max_frames: int = 600) -> str:
    """An HTML fragment: an ``<iframe srcdoc>`` with the viewer page in which every usable
    activity of ``study`` plays in turn in one looping animation (at most ``max_frames``
    frames, so meshcat's JavaScript, ~1 MB, is in the report once), and a note of when each
    activity starts.  For ``anthroarm.prosthesis.report.write(study, path, viewer=...)``."""
    acts = [a for a in study.envelope.activities if len(a.q) >= 2]
    if not acts:
        return '<p class="note">no usable activity to animate</p>'
    total = sum(len(a.q) for a in acts)
    step = max(1, int(np.ceil(total / max_frames)))
    Q = np.concatenate([a.q[::step] for a in acts])
    dt = float(np.median(np.concatenate([np.diff(a.t) for a in acts]))) * step
    v = Viewer(study.robot)
    v.play(Q, dt=dt, loop=True, trace=True)
    page = v.static_html(title=f"anthroarm — {study.robot.name} activities")
    starts, t = [], 0.0
    for a in acts:
        starts.append(f"{_e(a.name)} at {t:.1f} s")
        t += len(a.q[::step]) * dt
    return (
        f'<iframe srcdoc="{_e(page)}" loading="lazy"></iframe>'
        f'<p class="note screen">One animation, {len(acts)} activities in turn (loops): '
        f"{'; '.join(starts)}. Drag to rotate, scroll to zoom.</p>"
    )


def motion_viewer(robot, Q, dt: float, every: int = 4, trace: bool = False) -> Viewer:
    """A :class:`~anthroarm.viewer.Viewer` of ``robot`` playing ``Q`` (N, nq), every
    ``every``-th row (``dt`` s apart in ``Q``), looping; ``viewer.static_html()`` is a
    self-contained page."""
    k = max(1, int(every))
    v = Viewer(robot)
    v.play(np.asarray(Q)[::k], dt=dt * k, loop=True, trace=trace)
    return v
