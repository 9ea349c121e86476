"""Headless Chromium screenshots of viewer pages, and a pixel test that something is drawn.

Used by the real-browser tests and to make ``docs/human_arm_viewer.png``.  Needs Debian's
``chromium`` (or ``chromium-browser`` / ``google-chrome``) on PATH; WebGL runs on SwiftShader
(software), so no GPU or display is needed.

>>> png = screenshot("file:///tmp/arm.html", "/tmp/arm.png")
>>> drawn_fraction(png, baseline_png, region=(0.2, 0.1, 0.8, 0.9))   # share of changed pixels
>>> with live_tab(viewer.url) as tab:     # a tab connected to a live viewer (benchmarks)
...     viewer.wait(1, timeout=30)

Every browser runs in its own process group with a private profile folder; when it is done,
the whole group is stopped and *waited for* before the folder is removed (Chromium's helper
processes keep writing into the profile after the main process has exited, and removing it
under them failed with ``OSError: [Errno 39] Directory not empty``).  Removing the profile
never raises.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image
from tornado.websocket import websocket_connect

from .demo import REACH_POSTURES_DEG, demo_viewer, reach_demo

#: Flags that make headless Chromium render WebGL in software, offline and quietly.
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--hide-scrollbars",
    "--disable-default-apps",
    "--disable-extensions",
    "--mute-audio",
]


def find_chromium() -> str | None:
    """Path of a Chromium/Chrome executable, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        p = shutil.which(name)
        if p:
            return p
    return None


def screenshot(url, png, size=(800, 600), budget_ms: int = 6000, timeout: float = 120.0) -> Path:
    """Load ``url`` (http://, file://, or a local path) in headless Chromium and save a PNG.

    ``budget_ms`` is Chromium's virtual-time budget: how long the page may run (scripts,
    animation frames) before the picture is taken.  Raises RuntimeError if Chromium is
    missing or fails, naming the reason."""
    exe = find_chromium()
    if exe is None:
        raise RuntimeError("no chromium on PATH (Debian: apt-get install chromium)")
    url = str(url)
    if "://" not in url:
        url = Path(url).resolve().as_uri()
    png = Path(png)
    png.unlink(missing_ok=True)
    prof = tempfile.mkdtemp(prefix="anthroarm-chromium-")
    cmd = [
        exe,
        *CHROMIUM_FLAGS,
        f"--user-data-dir={prof}",
        f"--screenshot={png}",
        f"--window-size={int(size[0])},{int(size[1])}",
        f"--virtual-time-budget={int(budget_ms)}",
        url,
    ]
    # own process group: the renderer/GPU children are stopped with the browser
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        start_new_session=True,
    )
    err = b""
    try:
        _, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RuntimeError(f"chromium did not finish within {timeout} s on {url}") from None
    finally:
        stop_browser(proc)
        remove_profile(prof)
    if not png.is_file():
        tail = (err or b"").decode("utf-8", "replace").strip().splitlines()[-3:]
        raise RuntimeError(
            f"chromium wrote no screenshot (exit {proc.returncode}): {' | '.join(tail)}"
        )
    return png


@dataclass
class Tab:
    """A headless Chromium showing one page: ``proc`` (the browser, leader of its own process
    group) and ``profile`` (its private profile folder)."""

    proc: subprocess.Popen
    profile: str


@contextlib.contextmanager
def live_tab(url, size=(800, 600)):
    """A headless Chromium tab on ``url`` (e.g. a live viewer's page) for the duration of the
    ``with`` block.  On exit the browser and every process it started are stopped and waited
    for (bounded), then the profile folder is removed (never raises).  RuntimeError if there
    is no Chromium.  :class:`DevTools` ``(tab)`` drives the page (scripts, mouse events)."""
    exe = find_chromium()
    if exe is None:
        raise RuntimeError("no chromium on PATH (Debian: apt-get install chromium)")
    url = str(url)
    if "://" not in url:
        url = Path(url).resolve().as_uri()
    prof = tempfile.mkdtemp(prefix="anthroarm-chromium-")
    try:
        proc = subprocess.Popen(
            [
                exe,
                *CHROMIUM_FLAGS,
                f"--user-data-dir={prof}",
                f"--window-size={int(size[0])},{int(size[1])}",
                "--remote-debugging-port=0",
                "--remote-debugging-address=127.0.0.1",
                url,
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )
    except BaseException:
        remove_profile(prof)
        raise
    try:
        yield Tab(proc, prof)
    finally:
        stop_browser(proc)
        remove_profile(prof)


class DevTools:
    """A Chrome DevTools Protocol connection (over a websocket on 127.0.0.1) to the page of a
    :func:`live_tab`: run JavaScript in it (:meth:`evaluate`) and send it real input events
    (:meth:`drag`), as a person's mouse would.  Used by the viewer's teach-slider tests.

    >>> with live_tab(url) as tab, DevTools(tab) as page:
    ...     page.wait_for("window.anthroarm_ready === true")
    ...     page.drag((x0, y), (x1, y))
    """

    def __init__(self, tab: Tab, timeout: float = 60.0):
        self.timeout = float(timeout)
        deadline = time.monotonic() + self.timeout
        port_file = Path(tab.profile) / "DevToolsActivePort"
        while not port_file.is_file() or not port_file.read_text().strip():
            if tab.proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("chromium did not open its DevTools port")
            time.sleep(0.05)
        port = int(port_file.read_text().split()[0])
        page = None
        while page is None:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
                targets = json.loads(r.read().decode())
            page = next(
                (t for t in targets if t.get("type") == "page" and t.get("webSocketDebuggerUrl")),
                None,
            )
            if page is None:
                if time.monotonic() > deadline:
                    raise RuntimeError("chromium shows no page to drive")
                time.sleep(0.05)
        self._json = json
        self._loop = asyncio.new_event_loop()

        async def connect():
            return await websocket_connect(
                page["webSocketDebuggerUrl"], max_message_size=64 * 2**20
            )

        self._conn = self._loop.run_until_complete(asyncio.wait_for(connect(), self.timeout))
        self._id = 0

    def call(self, method: str, **params):
        """One DevTools command; its ``result`` (RuntimeError with the protocol's message on an error)."""
        self._id += 1
        mid = self._id

        async def read():
            return await self._conn.read_message()

        self._conn.write_message(self._json.dumps({"id": mid, "method": method, "params": params}))
        while True:
            msg = self._loop.run_until_complete(asyncio.wait_for(read(), self.timeout))
            if msg is None:
                raise RuntimeError("the DevTools connection closed")
            data = self._json.loads(msg)
            if data.get("id") == mid:
                if "error" in data:
                    raise RuntimeError(f"{method}: {data['error']}")
                return data.get("result", {})

    def evaluate(self, expression: str):
        """The JSON value of a JavaScript expression in the page (RuntimeError if it throws)."""
        r = self.call(
            "Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True
        )
        if "exceptionDetails" in r:
            raise RuntimeError(
                f"the page threw: {r['exceptionDetails'].get('exception', {}).get('description', r['exceptionDetails'])}"
            )
        return r.get("result", {}).get("value")

    def wait_for(self, expression: str, timeout: float = 30.0):
        """Poll ``expression`` until it is truthy (RuntimeError after ``timeout`` s); its value."""
        deadline = time.monotonic() + timeout
        while True:
            v = self.evaluate(expression)
            if v:
                return v
            if time.monotonic() > deadline:
                raise RuntimeError(f"timed out waiting for {expression!r}")
            time.sleep(0.05)

    def drag(self, start, end, steps: int = 8) -> None:
        """Press the left mouse button at ``start`` (x, y CSS pixels), move to ``end`` in
        ``steps`` moves, release: Chromium's own input pipeline, like a person's drag."""
        x0, y0 = (float(c) for c in start)
        x1, y1 = (float(c) for c in end)
        self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x0, y=y0)
        self.call(
            "Input.dispatchMouseEvent",
            type="mousePressed",
            x=x0,
            y=y0,
            button="left",
            buttons=1,
            clickCount=1,
        )
        for k in range(1, steps + 1):
            t = k / steps
            self.call(
                "Input.dispatchMouseEvent",
                type="mouseMoved",
                x=x0 + t * (x1 - x0),
                y=y0 + t * (y1 - y0),
                button="left",
                buttons=1,
            )
        self.call(
            "Input.dispatchMouseEvent",
            type="mouseReleased",
            x=x1,
            y=y1,
            button="left",
            buttons=1,
            clickCount=1,
        )

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._conn.close()
        with contextlib.suppress(Exception):
            self._loop.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def live_processes():
    """(pid, process group, command line) of every live (not zombie) process; Linux /proc."""
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat", "rb") as f:
                fields = f.read().rsplit(b")", 1)[1].split()
            with open(f"/proc/{d}/cmdline", "rb") as f:
                cmdline = f.read().replace(b"\0", b" ")
        except (OSError, IndexError):
            continue
        if len(fields) > 2 and fields[0] not in (b"Z", b"X"):
            yield int(d), int(fields[2]), cmdline


def group_members(pgid: int) -> list[int]:
    """Live (not zombie) processes of process group ``pgid`` (Linux: from /proc; elsewhere
    ``[pgid]`` while the group exists)."""
    if not os.path.isdir("/proc/self"):
        try:
            os.killpg(pgid, 0)
            return [pgid]
        except (ProcessLookupError, PermissionError):
            return []
    return [pid for pid, group, _ in live_processes() if group == pgid]


def stop_browser(proc: subprocess.Popen, grace: float = 5.0, timeout: float = 10.0) -> None:
    """Stop a browser started with ``start_new_session=True`` and every process of its group,
    and wait until none is left (at most ``grace + timeout`` seconds): SIGTERM, ``grace`` s for
    a clean exit, then SIGKILL for whatever is left (helpers still writing, a stopped child)."""
    pgid = proc.pid
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, signal.SIGTERM)
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        pass
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout)
    deadline = time.monotonic() + timeout
    while group_members(pgid) and time.monotonic() < deadline:  # bounded
        time.sleep(0.05)
    for f in (proc.stdout, proc.stderr):
        with contextlib.suppress(Exception):
            if f is not None:
                f.close()


def remove_profile(path, attempts: int = 5) -> bool:
    """Remove a browser profile folder; a few attempts, then what can be removed.  Never
    raises (a benchmark or a screenshot must not lose its result to cleanup); returns True if
    the folder is gone, else prints one line to stderr."""
    for k in range(attempts):
        try:
            shutil.rmtree(path)
            return True
        except FileNotFoundError:
            return True
        except OSError:
            time.sleep(0.1 * (k + 1))
    shutil.rmtree(path, ignore_errors=True)
    if os.path.exists(path):
        print(f"anthroarm: warning: could not remove the browser profile {path}", file=sys.stderr)
        return False
    return True


def load_rgb(png) -> np.ndarray:
    """The PNG as an (H, W, 3) int16 RGB array."""
    with Image.open(png) as im:
        return np.asarray(im.convert("RGB")).astype(np.int16)


def changed_mask(png, baseline_png, tol: int = 40) -> np.ndarray:
    """Boolean image: pixels whose colour differs from the baseline by more than ``tol``
    (sum of |ΔR|+|ΔG|+|ΔB|)."""
    a, b = load_rgb(png), load_rgb(baseline_png)
    if a.shape != b.shape:
        raise ValueError(f"screenshots differ in size: {a.shape} vs {b.shape}")
    return np.abs(a - b).sum(axis=2) > tol


def region_slice(shape, region) -> tuple[slice, slice]:
    """``region`` = (x0, y0, x1, y1) as fractions of the width and height."""
    h, w = shape[:2]
    x0, y0, x1, y1 = region
    return slice(int(y0 * h), int(y1 * h)), slice(int(x0 * w), int(x1 * w))


def drawn_fraction(png, baseline_png, region=(0.0, 0.0, 1.0, 1.0), tol: int = 40) -> float:
    """Share of the pixels inside ``region`` that differ from the baseline screenshot (the same
    page without the robot)."""
    m = changed_mask(png, baseline_png, tol)
    ys, xs = region_slice(m.shape, region)
    return float(m[ys, xs].mean())


def docs_screenshot(png, size=(960, 640)) -> Path:
    """The README picture: the §6-3 human arm reaching forward, the demo's targets and the
    hand's path, joint-limit colours on.  ``python -m anthroarm.viewer.browser docs/x.png``."""
    res = reach_demo()
    v = demo_viewer(res)
    v.stop()  # a still picture: the pose below, not the animation
    v.show_limits()
    v.display(np.deg2rad(REACH_POSTURES_DEG["reach forward"]))
    v.set_camera((1.0, 0.7, 0.45), fit="reach", fill=1.0)  # front-right, whole reach in view
    with tempfile.TemporaryDirectory() as d:
        html = v.export_html(Path(d) / "arm.html")
        return screenshot(html, png, size=size, budget_ms=3000)


if __name__ == "__main__":  # pragma: no cover
    print(docs_screenshot(sys.argv[1] if len(sys.argv) > 1 else "human_arm_viewer.png"))
