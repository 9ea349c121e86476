"""The meshcat server subprocess of :mod:`anthroarm.viewer` (run by file path, not imported).

    python _server.py --port 7000 --parent-pid 1234

* HTTP and websocket are bound to 127.0.0.1 only (meshcat's own server listens on every
  interface).  The page is at ``http://127.0.0.1:PORT/static/``; ``/`` redirects there.
* ``--port N``: that port or a one-line error ``error port_in_use N`` and exit status 3
  (instead of meshcat's silent move to the next port, which leaves a browser tab on the old
  port looking at a 404 or at someone else's page).  Without ``--port`` the first free port
  from 7000 is used.
* ZeroMQ REP socket on ``tcp://127.0.0.1:<random>``; the first stdout line is
  ``ready zmq_url=... web_url=...``.
* The process exits when its parent dies (checked twice a second), so a crashed or killed
  Python session does not leave a server behind (meshcat-python#138).
"""

from __future__ import annotations

import argparse
import errno
import os
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
MESHCAT_COMMANDS = {"set_transform", "set_object", "delete", "set_property", "set_animation",
                    "anthroarm_batch", "anthroarm_color"}


class PageHandler(tornado.web.RequestHandler):
    def initialize(self, bridge):
        self.bridge = bridge

    def get(self):
        self.set_header("Cache-Control", "no-store")
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.write(page_html(live=True))


class StaticNoCache(tornado.web.StaticFileHandler):
    def set_extra_headers(self, path):
        self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")


class WebSocket(tornado.websocket.WebSocketHandler):
    def initialize(self, bridge):
        self.bridge = bridge

    def get(self, *args, **kwargs):
        if self.request.headers.get("Upgrade", "").lower() != "websocket":
            self.redirect("/static/")
            return None
        return super().get(*args, **kwargs)

    def open(self):
        self.bridge.clients.add(self)
        for packed in self.bridge.store.commands():
            self.write_message(packed, binary=True)

    def on_message(self, message):
        pass  # image capture is not supported

    def on_close(self):
        self.bridge.clients.discard(self)


class Bridge:
    def __init__(self, port: int | None, parent_pid: int | None):
        self.store = SceneStore()
        self.clients: set[WebSocket] = set()
        self.parent_pid = parent_pid
        app = tornado.web.Application([
            (r"/static/", PageHandler, {"bridge": self}),
            (r"/static/index.html", PageHandler, {"bridge": self}),
            (r"/static/(.*)", StaticNoCache, {"path": MESHCAT_DIST}),
            (r"/", WebSocket, {"bridge": self}),
        ])
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
            self.sock.send(b"ok")
        elif self.loop.time() >= deadline:
            self.sock.send(f"error: {len(self.clients)} of {n} browser tabs connected before the timeout".encode())
        else:
            self.loop.call_later(0.05, lambda: self._wait_clients(n, deadline))

    def handle(self, frames):
        cmd = frames[0].decode("utf-8")
        if cmd in MESHCAT_COMMANDS:
            if len(frames) != 3:
                self.sock.send(b"error: expected 3 frames")
                return
            data = frames[2]
            try:
                self.store.apply(umsgpack.unpackb(data), packed=data)
            except Exception as exc:  # a malformed command must not kill the server
                self.sock.send(f"error: {exc}".encode())
                return
            for ws in list(self.clients):
                try:
                    ws.write_message(data, binary=True)
                except tornado.websocket.WebSocketClosedError:
                    self.clients.discard(ws)
            self.sock.send(b"ok")
        elif cmd == "url":
            self.sock.send(self.web_url.encode())
        elif cmd == "clients":
            self.sock.send(str(len(self.clients)).encode())
        elif cmd == "wait":
            n = int(frames[1]) if len(frames) > 1 and frames[1] else 1
            seconds = float(frames[2]) if len(frames) > 2 and frames[2] else 30.0
            self._wait_clients(n, self.loop.time() + seconds)
        elif cmd == "get_scene":
            self.sock.send(self.store.static_html().encode("utf-8"))
        elif cmd == "shutdown":
            self.sock.send(b"ok")
            self.loop.call_later(0.01, self.loop.stop)
        else:
            self.sock.send(b"error: unknown command " + frames[0])


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, default=None)
    ap.add_argument("--parent-pid", type=int, default=None)
    a = ap.parse_args(argv)
    bridge = Bridge(a.port, a.parent_pid)
    print(f"ready zmq_url={bridge.zmq_url} web_url={bridge.web_url}", flush=True)
    try:
        bridge.loop.start()
    finally:
        bridge.stream.close()
        bridge.ctx.destroy(linger=0)


if __name__ == "__main__":
    main()
