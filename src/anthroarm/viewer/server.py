"""Start, talk to and stop the viewer's meshcat server subprocess (``_server.py``).

>>> srv = ServerProcess(port=7000)       # raises ViewerPortInUseError if 7000 is taken
>>> srv.web_url
'http://127.0.0.1:7000/static/'
>>> srv.send_many([cmd1, cmd2])          # one ZeroMQ message, one websocket message
>>> srv.close()                          # also done at interpreter exit

The server listens on 127.0.0.1 only; it exits on its own when this process dies.  Only this
process can drive it: the server gets a random secret through its stdin (not its command line
or environment), and every request carries that secret as its first frame.  The web page and
websocket answer only loopback ``Host`` names (no DNS rebinding).
"""

from __future__ import annotations

import atexit
import math
import numbers
import os
import secrets
import selectors
import socket
import subprocess
import sys
import tempfile
import weakref

import umsgpack
import zmq

from ..errors import ParameterError, ViewerError, ViewerPortInUseError

_SERVER_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_server.py")
HOST = "127.0.0.1"
#: Longest wait (s) for a reply, for the server to start, or for browser tabs (the server's
#: own bound, ``_server.MAX_WAIT``); the most tabs :meth:`ServerProcess.wait` can wait for.
MAX_WAIT = 3600.0
MAX_TABS = 1024


def port_is_free(port: int) -> bool:
    """True if a TCP server could bind 127.0.0.1:``port`` right now."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.bind((HOST, port))
        return True
    except OSError:
        return False
    finally:
        s.close()


def check_port(port) -> int | None:
    """``None`` or an integer 1..65535 (a bool or a float is a TypeError, not port 1)."""
    if port is None:
        return None
    if isinstance(port, bool) or not isinstance(port, numbers.Integral):
        raise ParameterError(
            f"port must be an integer in 1..65535 (or None for the first free port from 7000), "
            f"got {port!r} of type {type(port).__name__}"
        )
    if not 1 <= int(port) <= 65535:
        raise ParameterError(f"port must be an integer in 1..65535, got {port!r}")
    return int(port)


def _check_seconds(value, name: str = "timeout") -> float:
    """A finite number of seconds in (0, MAX_WAIT]; ParameterError (TypeError/ValueError) otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(
            f"{name} must be a number of seconds, got {value!r} of type {type(value).__name__}"
        )
    v = float(value)
    if not (math.isfinite(v) and 0 < v <= MAX_WAIT):
        raise ParameterError(f"{name} must be finite, > 0 and <= {MAX_WAIT:g} s, got {value!r}")
    return v


def _check_tabs(n) -> int:
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        raise ParameterError(
            f"n (browser tabs) must be an integer in 1..{MAX_TABS}, got {n!r} of type {type(n).__name__}"
        )
    if not 1 <= int(n) <= MAX_TABS:
        raise ParameterError(f"n (browser tabs) must be an integer in 1..{MAX_TABS}, got {n!r}")
    return int(n)


def _stop(proc: subprocess.Popen, log) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=3)
        except subprocess.TimeoutExpired:  # pragma: no cover - terminate is enough on Linux
            proc.kill()
            proc.wait()
    for f in (proc.stdout, log):  # the pipe of the ready line, the stderr log
        try:
            if f is not None:
                f.close()
        except Exception:  # pragma: no cover
            pass


class ServerProcess:
    """A meshcat-compatible server on 127.0.0.1 in a subprocess, and a ZeroMQ client to it.

    Parameters
    ----------
    port : int, optional
        HTTP/websocket port.  ``None``: the first free port from 7000.  A given port that is
        taken raises :class:`~anthroarm.errors.ViewerPortInUseError` (no silent fallback).
    timeout : float
        Seconds to wait for the server to start, and for each reply (finite, at most
        :data:`MAX_WAIT`).

    ``secret`` (bytes) is the per-server token every request starts with.
    """

    context = zmq.Context.instance()

    def __init__(self, port: int | None = None, timeout: float = 20.0):
        port = check_port(port)
        timeout = _check_seconds(timeout)
        if port is not None and not port_is_free(port):
            raise ViewerPortInUseError(in_use_message(port))
        self._log = tempfile.TemporaryFile(mode="w+")
        args = [sys.executable, "-u", _SERVER_SCRIPT, "--parent-pid", str(os.getpid())]
        if port is not None:
            args += ["--port", str(port)]
        self.secret = secrets.token_hex(32).encode("ascii")
        self.proc = subprocess.Popen(
            args,
            stdout=subprocess.PIPE,
            stderr=self._log,
            stdin=subprocess.PIPE,
            start_new_session=True,
        )
        self._finalizer = weakref.finalize(self, _stop, self.proc, self._log)
        atexit.register(self._finalizer)
        try:  # the secret travels through the pipe: not in argv or the environment (ps, /proc)
            self.proc.stdin.write(self.secret + b"\n")
            self.proc.stdin.close()
        except OSError:  # the child died at once; its first line (or stderr) says why
            pass
        line = self._read_line(timeout)
        if line.startswith("error port_in_use"):
            self._finalizer()
            raise ViewerPortInUseError(in_use_message(port))
        if not line.startswith("ready "):
            self._finalizer()
            raise ViewerError(f"the viewer server did not start: {line or self._stderr_tail()}")
        fields = dict(kv.split("=", 1) for kv in line.split()[1:])
        self.zmq_url = fields["zmq_url"]
        self.web_url = fields["web_url"]
        self.port = int(self.web_url.rsplit(":", 1)[1].split("/")[0])
        self.timeout_ms = int(timeout * 1000)
        self._connect()

    # ------------------------------------------------------------------ plumbing
    def _read_line(self, timeout: float) -> str:
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        try:
            if not sel.select(timeout):
                return f"no answer within {timeout} s"
            return self.proc.stdout.readline().decode("utf-8", "replace").strip()
        finally:
            sel.close()

    def _stderr_tail(self) -> str:
        try:
            self._log.seek(0)
            lines = [ln for ln in self._log.read().splitlines() if ln.strip()]
            return lines[-1] if lines else "no output"
        except Exception:  # pragma: no cover
            return "no output"

    def _connect(self) -> None:
        self.sock = self.context.socket(zmq.REQ)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.setsockopt(zmq.RCVTIMEO, self.timeout_ms)
        self.sock.connect(self.zmq_url)

    def _request(self, frames: list[bytes]) -> bytes:
        if not self.alive:
            raise ViewerError("the viewer server is not running (closed, or it exited)")
        self.sock.send_multipart([self.secret, *frames])
        try:
            reply = self.sock.recv()
        except zmq.Again:
            self.sock.close()
            self._connect()
            raise ViewerError("the viewer server did not answer") from None
        if reply.startswith(b"error"):
            raise ViewerError(f"the viewer server refused a command: {reply.decode()}")
        return reply

    # ------------------------------------------------------------------ API
    @property
    def alive(self) -> bool:
        return self.proc.poll() is None

    def send(self, cmd: dict) -> None:
        """Send one lowered meshcat command (``SetObject(...).lower()`` etc.)."""
        self._request([cmd["type"].encode(), cmd.get("path", "").encode(), umsgpack.packb(cmd)])

    def send_many(self, cmds: list[dict]) -> None:
        """Send several commands as ONE message; the browser applies them together."""
        if not cmds:
            return
        if len(cmds) == 1:
            return self.send(cmds[0])
        batch = {"type": "anthroarm_batch", "path": "", "commands": cmds}
        self._request([b"anthroarm_batch", b"", umsgpack.packb(batch)])

    def clients(self) -> int:
        """Number of browser tabs connected."""
        return int(self._request([b"clients"]))

    def wait(self, n: int = 1, timeout: float = 30.0) -> None:
        """Block until ``n`` browser tabs are connected (ViewerError after ``timeout`` s).  The
        server answers at its own deadline, so a timed-out wait leaves it usable.  ``n`` is an
        integer in 1..:data:`MAX_TABS`, ``timeout`` finite in (0, :data:`MAX_WAIT`] s
        (:class:`~anthroarm.errors.ParameterError`, a TypeError/ValueError, otherwise)."""
        n = _check_tabs(n)
        timeout = _check_seconds(timeout)
        self.sock.setsockopt(zmq.RCVTIMEO, int(timeout * 1000) + self.timeout_ms)
        try:
            self._request([b"wait", str(n).encode(), repr(float(timeout)).encode()])
        finally:
            if not self.sock.closed:
                self.sock.setsockopt(zmq.RCVTIMEO, self.timeout_ms)

    def static_html(self) -> str:
        return self._request([b"get_scene"]).decode("utf-8")

    def close(self) -> None:
        """Stop the server process (idempotent)."""
        try:
            if self.alive:
                self.sock.setsockopt(zmq.RCVTIMEO, 1000)
                self.sock.send_multipart([self.secret, b"shutdown"])
                self.sock.recv()
        except Exception:
            pass
        try:
            self.sock.close()
        except Exception:  # pragma: no cover
            pass
        self._finalizer()
        try:
            atexit.unregister(self._finalizer)
        except Exception:  # pragma: no cover
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def in_use_message(port) -> str:
    """What to tell a user whose ``port`` is taken."""
    return (
        f"port {port} on 127.0.0.1 is already in use (another viewer or program); "
        f"choose a free one with --port / port=, or leave it unset to pick the first free port from 7000"
    )


#: The old private name, still imported by ``anthroarm.cli`` (``_check_port_early``).
_in_use_message = in_use_message
