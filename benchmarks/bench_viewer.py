"""Viewer pose-update rate: frames per second of ``Viewer.display(q)`` (FK + every link transform).

Variants, each on a live server on 127.0.0.1 (a separate process, as in use):
* **batched** — anthroarm's path: all link transforms in ONE ZeroMQ message / ONE websocket
  message (``anthroarm_batch``);
* **batched + browser** — the same with a headless Chromium tab connected and rendering
  (software WebGL; it competes for the same 2 CPU cores);
* **one message per link** — the same transforms sent one ZeroMQ round trip each, the pattern of
  meshcat-python's ``set_transform`` and Pinocchio's ``MeshcatVisualizer.display`` (peers.md §4.4
  measured the latter at 3.9 ms per frame on the panda, 11 geometries);
* **in memory** — no server: FK and command building only (the floor of the cost).

The notes give the size of the panda's Jupyter cell (a static page: meshcat's JavaScript and
the scene), with packed meshes and with the mesh files as they are.

Frames are random configurations inside the limits (fixed seed); per-frame time is the median
of 5 runs of N consecutive frames.  Target (issue 7): >= 60 fps for human_arm7.
"""

from __future__ import annotations

import time
from statistics import median

import anthroarm as aa
from anthroarm.errors import ViewerError
from anthroarm.viewer import Viewer, browser

MODELS = ["human_arm7", "panda"]


def _per_frame(fn, Q, repeat=5) -> float:
    fn(Q[0])
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for q in Q:
            fn(q)
        runs.append((time.perf_counter() - t0) / len(Q))
    return median(runs)


def _per_link(v: Viewer):
    def f(q):
        for cmd in v._pose_commands(q):
            v.store.apply(cmd)
            v.server.send(cmd)

    return f


def _browser_frame_time(v: Viewer, Q) -> float | None:
    """Per-frame time with a headless Chromium tab connected and rendering; None without
    Chromium or when the tab does not connect within 30 s.  The browser and all its helper
    processes are stopped and waited for before its profile is removed (browser.live_tab), so
    the measurement is never lost to cleanup."""
    if browser.find_chromium() is None:
        return None
    with browser.live_tab(v.url):
        try:
            v.wait(1, timeout=30)
        except ViewerError:
            return None
        time.sleep(1.0)  # let the page finish loading the scene
        return _per_frame(v.display, Q)


def page_sizes(name: str = "panda") -> tuple[int, int]:
    """Bytes of the Jupyter cell (static page in an iframe) of ``Viewer(name)``: meshes packed
    (default ``mesh_triangles``) and sent as the files are (``mesh_triangles=None``)."""
    robot = aa.load(name)
    return (
        len(Viewer(robot)._repr_html_().encode()),
        len(Viewer(robot, mesh_triangles=None)._repr_html_().encode()),
    )


def run(quick: bool = False) -> dict:
    n = 100 if quick else 600
    packed, raw = page_sizes("panda")
    rows = []
    for name in MODELS:
        robot = aa.load(name)
        Q = robot.random_q(n, rng=0)
        mem = Viewer(robot)
        with Viewer(robot, live=True) as v:
            nb = sum(1 for b in v.bodies if b.joint is not None or b.frame is not None)
            t_mem = _per_frame(mem.display, Q)
            t_batch = _per_frame(v.display, Q)
            t_link = _per_frame(_per_link(v), Q[: max(20, n // 4)])
            t_browser = _browser_frame_time(v, Q)
        for label, t, msgs in (
            ("batched (anthroarm)", t_batch, 1),
            ("batched + headless Chromium tab", t_browser, 1),
            ("one message per link (meshcat-python style)", t_link, nb),
            ("in memory, no server (FK + commands)", t_mem, 0),
        ):
            if t is None:
                rows.append([name, label, nb, msgs, "n/a (no chromium)", "n/a"])
            else:
                rows.append([name, label, nb, msgs, round(t * 1e3, 3), round(1.0 / t)])
    return {
        "title": "Viewer pose updates: ms per frame and frames per second",
        "columns": ["model", "path", "moving bodies", "messages/frame", "ms/frame", "fps"],
        "rows": rows,
        "notes": (
            "Viewer.display(q): Pinocchio FK, one 4x4 per moving body, sent to the 127.0.0.1 server "
            "(ZeroMQ REQ/REP round trip) which forwards it to every connected tab.  The browser draws at "
            "its own requestAnimationFrame rate; these numbers are the rate at which complete poses "
            "reach it.  Target: >= 60 fps for human_arm7.  Peer: Pinocchio MeshcatVisualizer.display "
            "3.9 ms/frame on the panda (peers.md §4.4).  Jupyter cell of Viewer('panda') (static page): "
            f"{packed / 2**20:.2f} MB with the meshes packed (mesh_triangles=5000), {raw / 2**20:.1f} MB with "
            "the mesh files as they are (mesh_triangles=None)."
        ),
    }
