"""The meshcat server subprocess of :mod:`anthroarm.viewer` (run by file path, not imported).

    python _server.py --port 7000 --parent-pid 1234

* HTTP and websocket are bound to 127.0.0.1 only (meshcat's own server listens on every
  interface).  The page is at ``http://127.0.0.1:PORT/static/``; ``/`` redirects there.
* ``--port N``: that port or a one-line error ``error port_in_use N`` and exit status 3
  (instead of meshcat's silent move to the next port, which leaves a browser tab on the old
  port looking at a 404 or at someone else's page).  Without ``--port`` the first free port
  from 7000 is used.
* The page, the static files and the websocket answer only requests whose ``Host`` header is a
  loopback name (``127.0.0.1``, ``localhost``, ``[::1]``, any port): anything else gets 403, so
  a page on another site cannot reach the server through DNS rebinding.  The websocket also
  refuses an ``Origin`` that is not a loopback ``http(s)://`` origin (no Origin: accepted).
* ZeroMQ REP socket on ``tcp://127.0.0.1:<random>``; the first stdout line is
  ``ready zmq_url=... web_url=...``.
* The secret: the first line of stdin (written by the parent, then closed).  Every request's
  first frame must be that secret (compared in constant time), so only the process that
  started the server can drive it; other requests are answered ``error: refused ...``.
* Every request gets exactly one reply — an ``error: ...`` reply for a malformed one — so one
  bad request never wedges the REP socket; a ``wait`` is bounded by :data:`MAX_WAIT` seconds.
* The process exits when its parent dies (checked twice a second), so a crashed or killed
  Python session does not leave a server behind (meshcat-python#138).
"""

from __future__ import annotations

import argparse
import errno
import hmac
import math
import os
import re
import sys

import tornado.ioloop
import tornado.web
import tornado.websocket
import umsgpack
import zmq
from zmq.eventloop.zmqstream import ZMQStream

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _store import MESHCAT_DIST, SceneStore, page_html  # noqa: E402

HOST = "127.0.0.1"
MESHCAT_COMMANDS = {
    "set_transform",
    "set_object",
    "delete",
    "set_property",
    "set_animation",
    "anthroarm_batch",
    "anthroarm_color",
    "anthroarm_ui",
}
#: the kinds of HTML overlay the page builds (``anthroarm_ui``)
UI_KINDS = {"legend", "note", "teach"}
#: Longest ``wait`` (s) and most browser tabs a ``wait`` may ask for.
MAX_WAIT = 3600.0
MAX_TABS = 1024

_LOOPBACK_HOST = re.compile(r"(?:127\.0\.0\.1|localhost|\[::1\])(?::(\d{1,5}))?")
_LOOPBACK_ORIGIN = re.compile(r"https?://(?:127\.0\.0\.1|localhost|\[::1\])(?::(\d{1,5}))?/?")


def loopback_host(value) -> bool:
    """True for a ``Host`` header naming this machine by a loopback name: 127.0.0.1, localhost
    or [::1], with an optional port (case-insensitive)."""
    m = _LOOPBACK_HOST.fullmatch(value.strip().lower()) if isinstance(value, str) else None
    return m is not None and (m.group(1) is None or 0 < int(m.group(1)) <= 65535)


def loopback_origin(value) -> bool:
    """True for an ``Origin`` of a page served from a loopback name (``http(s)://``)."""
    m = _LOOPBACK_ORIGIN.fullmatch(value.strip().lower()) if isinstance(value, str) else None
    return m is not None and (m.group(1) is None or 0 < int(m.group(1)) <= 65535)


def _refuse_foreign_host(handler) -> bool:
    """Answer 403 unless the request's Host header is a loopback name; True if refused."""
    host = handler.request.headers.get("Host")
    if loopback_host(host):
        return False
    handler.set_status(403)
    handler.set_header("Content-Type", "text/plain; charset=utf-8")
    handler.finish("403: this viewer answers only requests to 127.0.0.1, localhost or [::1]\n")
    return True


class LoopbackOnly(tornado.web.RequestHandler):
    def prepare(self):
        _refuse_foreign_host(self)


class PageHandler(LoopbackOnly):
    def initialize(self, bridge):
        self.bridge = bridge

    def get(self):
        self.set_header("Cache-Control", "no-store")
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.write(page_html(live=True))


class StaticNoCache(tornado.web.StaticFileHandler):
    def prepare(self):
        _refuse_foreign_host(self)

    def set_extra_headers(self, path):
        self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")


class WebSocket(tornado.websocket.WebSocketHandler):
    def initialize(self, bridge):
        self.bridge = bridge

    def get(self, *args, **kwargs):
        if _refuse_foreign_host(self):  # before the upgrade: no websocket for a foreign Host
            return None
        if self.request.headers.get("Upgrade", "").lower() != "websocket":
            self.redirect("/static/")
            return None
        return super().get(*args, **kwargs)

    def check_origin(self, origin):
        """Only pages served from a loopback name (tornado calls this when there is an Origin)."""
        return loopback_origin(origin)

    def open(self):
        self.bridge.clients.add(self)
        for packed in self.bridge.store.commands():
            self.write_message(packed, binary=True)

    def on_message(self, message):
        pass  # image capture is not supported

    def on_close(self):
        self.bridge.clients.discard(self)


class Bridge:
    def __init__(self, port: int | None, parent_pid: int | None, secret: bytes):
        self.secret = secret
        self.store = SceneStore()
        self.clients: set[WebSocket] = set()
        self.parent_pid = parent_pid
        app = tornado.web.Application(
            [
                (r"/static/", PageHandler, {"bridge": self}),
                (r"/static/index.html", PageHandler, {"bridge": self}),
                (r"/static/(.*)", StaticNoCache, {"path": MESHCAT_DIST}),
                (r"/", WebSocket, {"bridge": self}),
            ]
        )
        if port is not None:
            try:
                app.listen(port, address=HOST)
            except OSError as exc:
                if exc.errno in (errno.EADDRINUSE, errno.EACCES):
                    print(f"error port_in_use {port}", flush=True)
                    sys.exit(3)
                raise
            self.port = port
        else:
            for p in range(7000, 7100):
                try:
                    app.listen(p, address=HOST)
                    self.port = p
                    break
                except OSError:
                    continue
            else:
                print("error no_free_port 7000-7099", flush=True)
                sys.exit(3)
        self.ctx = zmq.Context()
        self.sock = self.ctx.socket(zmq.REP)
        zport = self.sock.bind_to_random_port(f"tcp://{HOST}")
        self.zmq_url = f"tcp://{HOST}:{zport}"
        self.web_url = f"http://{HOST}:{self.port}/static/"
        self.stream = ZMQStream(self.sock)
        self.stream.on_recv(self.handle)
        self.loop = tornado.ioloop.IOLoop.current()
        if parent_pid:
            tornado.ioloop.PeriodicCallback(self.watch_parent, 500).start()

    def watch_parent(self):
        if os.getppid() != self.parent_pid:
            self.loop.stop()

    def _wait_clients(self, n, deadline):
        """Reply when ``n`` tabs are connected, or with an error at ``deadline`` (loop time):
        the REP socket must answer every request, or it would take no further commands."""
        if len(self.clients) >= n:
            self._reply(b"ok")
        elif self.loop.time() >= deadline:
            self._reply(
                f"error: {len(self.clients)} of {n} browser tabs connected before the timeout".encode()
            )
        else:
            self.loop.call_later(0.05, lambda: self._wait_clients(n, deadline))

    def _reply(self, data: bytes) -> None:
        # through the stream, not the socket: ZMQStream then re-checks the (edge-triggered)
        # socket for requests that arrived meanwhile; a reply sent on the raw socket from a
        # timer (a deferred ``wait``) left the next request unnoticed
        self.stream.send(data)

    def handle(self, frames):
        """One request -> exactly one reply (now, or later for a pending ``wait``)."""
        try:
            reply = self._dispatch(frames)
        except Exception as exc:  # noqa: BLE001 - a malformed request must get an answer, not kill the socket
            msg = " ".join(f"{type(exc).__name__}: {exc}".split())[:300]
            reply = f"error: bad request ({msg})".encode("utf-8", "replace")
        if reply is not None:
            self._reply(reply)

    def _dispatch(self, frames) -> bytes | None:
        if not frames or not hmac.compare_digest(frames[0], self.secret):
            return (
                b"error: refused: the request does not start with this viewer's secret "
                b"(only the process that started the server can drive it)"
            )
        frames = frames[1:]
        if not frames:
            return b"error: no command after the secret"
        try:
            cmd = frames[0].decode("utf-8")
        except UnicodeDecodeError:
            return b"error: the command is not UTF-8 text"
        nargs = len(frames) - 1
        if cmd in MESHCAT_COMMANDS:
            if nargs != 2:
                return f"error: {cmd} takes 3 frames (command, path, msgpack data), got {nargs + 1}".encode()
            data = frames[2]
            command = umsgpack.unpackb(data)
            _check_command(command, top=True)
            self.store.apply(command, packed=data)
            for ws in list(self.clients):
                try:
                    ws.write_message(data, binary=True)
                except tornado.websocket.WebSocketClosedError:
                    self.clients.discard(ws)
            return b"ok"
        if cmd in ("url", "clients", "get_scene", "shutdown") and nargs:
            return f"error: {cmd} takes no arguments, got {nargs}".encode()
        if cmd == "url":
            return self.web_url.encode()
        if cmd == "clients":
            return str(len(self.clients)).encode()
        if cmd == "get_scene":
            return self.store.static_html().encode("utf-8")
        if cmd == "shutdown":
            self.loop.call_later(0.01, self.loop.stop)
            return b"ok"
        if cmd == "wait":
            if nargs > 2:
                return (
                    f"error: wait takes at most 2 arguments (tabs, seconds), got {nargs}".encode()
                )
            n = _int_arg(frames[1], "tabs", 1, MAX_TABS) if nargs >= 1 and frames[1] else 1
            seconds = _seconds_arg(frames[2]) if nargs >= 2 and frames[2] else 30.0
            self._wait_clients(n, self.loop.time() + seconds)
            return None
        return f"error: unknown command {cmd[:60]!r}".encode("utf-8", "replace")


def _int_arg(frame: bytes, what: str, lo: int, hi: int) -> int:
    text = frame.decode("ascii")
    if not re.fullmatch(r"[0-9]{1,9}", text) or not lo <= int(text) <= hi:
        raise ValueError(f"{what} must be an integer in {lo}..{hi}, got {text[:30]!r}")
    return int(text)


def _seconds_arg(frame: bytes) -> float:
    text = frame.decode("ascii")
    s = float(text)
    if not (math.isfinite(s) and 0 < s <= MAX_WAIT):
        raise ValueError(f"seconds must be finite, > 0 and <= {MAX_WAIT:g}, got {text[:30]!r}")
    return s


_PATHLESS = {"anthroarm_batch", "set_animation"}


def _check_command(cmd, top: bool) -> None:
    """A lowered meshcat command the store and the browser can take; ValueError otherwise
    (before anything is applied: a batch is checked whole)."""
    if not isinstance(cmd, dict):
        raise ValueError(f"a command must be a map, got {type(cmd).__name__}")
    kind = cmd.get("type")
    if kind not in MESHCAT_COMMANDS or (kind == "anthroarm_batch" and not top):
        raise ValueError(f"unknown or misplaced command type {str(kind)[:40]!r}")
    path = cmd.get("path")
    if not isinstance(path, str) and not (path is None and kind in _PATHLESS):
        raise ValueError(f"{kind}: path must be a string")
    if kind == "anthroarm_batch":
        subs = cmd.get("commands")
        if not isinstance(subs, list):
            raise ValueError("anthroarm_batch: commands must be a list")
        for c in subs:
            _check_command(c, top=False)
    elif kind == "set_transform":
        m = cmd.get("matrix")
        if not (
            isinstance(m, list)
            and len(m) == 16
            and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                for x in m
            )
        ):
            raise ValueError("set_transform: matrix must be 16 finite numbers")
    elif kind == "set_property":
        if not isinstance(cmd.get("property"), str):
            raise ValueError("set_property: property must be a string")
    elif kind == "set_object":
        if not isinstance(cmd.get("object"), dict):
            raise ValueError("set_object: object must be a map")
    elif kind == "anthroarm_ui":
        spec = cmd.get("spec")
        if not (isinstance(spec, dict) and spec.get("kind") in UI_KINDS):
            raise ValueError(f"anthroarm_ui: spec must be a map with kind in {sorted(UI_KINDS)}")
    elif kind == "anthroarm_color":
        c = cmd.get("color")
        if not (
            isinstance(c, list) and len(c) in (3, 4) and all(isinstance(x, (int, float)) for x in c)
        ):
            raise ValueError("anthroarm_color: color must be 3 or 4 numbers")


def _read_secret() -> bytes:
    """The first line of stdin (the parent writes it and closes the pipe)."""
    line = sys.stdin.buffer.readline(1024).strip()
    if len(line) < 32:
        print("error no_secret (expected the secret as the first line of stdin)", flush=True)
        sys.exit(3)
    return line


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, default=None)
    ap.add_argument("--parent-pid", type=int, default=None)
    a = ap.parse_args(argv)
    secret = _read_secret()
    bridge = Bridge(a.port, a.parent_pid, secret)
    print(f"ready zmq_url={bridge.zmq_url} web_url={bridge.web_url}", flush=True)
    try:
        bridge.loop.start()
    finally:
        bridge.stream.close()
        bridge.ctx.destroy(linger=0)


if __name__ == "__main__":
    main()
