"""Viewer protocol abuse against a real server on 127.0.0.1 (issue 12, items 3, 4 and 12).

* The ZeroMQ command socket answers every request — an error reply for a malformed one — and
  stays usable: after each abuse case the next real command still works.  Every wait is bounded.
* Only the user who started the server can drive it: every request carries the server's secret
  (given to the child process through its stdin) as its first frame; a request without it or
  with a wrong one is refused (and answered, so the socket stays usable).
* DNS rebinding: the page, the static files and the websocket accept only loopback ``Host``
  headers, and the websocket only loopback ``Origin`` headers (or none).
* Bad arguments to the viewer API are typed errors before anything is sent.

Every socket here has a timeout; every loop is bounded.
"""

from __future__ import annotations

import base64
import http.client
import math
import os
import socket
import time

import numpy as np
import pytest
import umsgpack
import zmq

import anthroarm as aa
from anthroarm.errors import AnthroarmError, ViewerError
from anthroarm.viewer import Viewer
from anthroarm.viewer.server import ServerProcess

REPLY_TIMEOUT = 5.0  # s, for every raw request below
CTX = zmq.Context.instance()


# ---------------------------------------------------------------------------------- helpers
def raw_request(url: str, frames: list[bytes], timeout: float = REPLY_TIMEOUT) -> bytes | None:
    """Send one multipart request from a fresh REQ socket; the reply, or None if none came
    within ``timeout`` (the socket is closed either way)."""
    s = CTX.socket(zmq.REQ)
    s.setsockopt(zmq.LINGER, 0)
    s.setsockopt(zmq.RCVTIMEO, int(timeout * 1000))
    s.setsockopt(zmq.SNDTIMEO, int(timeout * 1000))
    try:
        s.connect(url)
        s.send_multipart(frames)
        return s.recv()
    except zmq.Again:
        return None
    finally:
        s.close()


def transform(path="/meshcat/abuse/probe", x=0.0) -> dict:
    T = np.eye(4)
    T[0, 3] = x
    return {"type": "set_transform", "path": path, "matrix": T.T.ravel().tolist()}


def assert_healthy(srv: ServerProcess) -> None:
    """The owner's next commands are answered (a pose update and a query)."""
    srv.send_many([transform(x=0.1), transform("/meshcat/abuse/probe2", 0.2)])
    assert srv.clients() == 0


def _fresh_server() -> ServerProcess:
    return ServerProcess(timeout=REPLY_TIMEOUT)


@pytest.fixture(scope="module")
def _shared():
    box = {"srv": _fresh_server()}
    yield box
    box["srv"].close()


@pytest.fixture
def srv(_shared):
    """The module's server, replaced by a new one if a previous case wedged or killed it (so
    that one failure does not cascade into every later case)."""
    s = _shared["srv"]
    try:
        if not s.alive:
            raise ViewerError("dead")
        s.clients()
    except ViewerError:
        s.close()
        s = _shared["srv"] = _fresh_server()
    return s


def owner(srv: ServerProcess, *frames: bytes) -> list[bytes]:
    """A request as the owner sends it: the server's secret first."""
    return [srv.secret, *frames]


# ---------------------------------------------------------------------------------- item 3: malformed requests
MALFORMED = {
    "wait_n_not_a_number": [b"wait", b"abc"],
    "wait_seconds_inf": [b"wait", b"99", b"inf"],
    "wait_seconds_nan": [b"wait", b"1", b"nan"],
    "wait_seconds_negative": [b"wait", b"1", b"-5"],
    "wait_seconds_huge": [b"wait", b"99", b"1e308"],
    "wait_seconds_not_a_number": [b"wait", b"1", b"soon"],
    "wait_n_negative": [b"wait", b"-3", b"1"],
    "wait_n_zero": [b"wait", b"0", b"1"],
    "wait_n_float": [b"wait", b"1.5", b"1"],
    "wait_too_many_frames": [b"wait", b"1", b"1", b"x"],
    "wait_non_utf8_argument": [b"wait", b"\xff", b"1"],
    "non_utf8_command": [b"\xff\xfe\xfd"],
    "empty_command": [b""],
    "unknown_command": [b"rm -rf /"],
    "set_object_one_frame": [b"set_object"],
    "set_transform_two_frames": [b"set_transform", b"/x"],
    "set_transform_four_frames": [b"set_transform", b"/x", umsgpack.packb(transform()), b"extra"],
    "invalid_msgpack": [b"set_object", b"", b"\xc1\xc1\xc1"],
    "msgpack_not_a_dict": [b"set_transform", b"", umsgpack.packb(5)],
    "msgpack_without_path": [b"set_transform", b"", umsgpack.packb({"type": "set_transform"})],
    "msgpack_wrong_field_types": [
        b"set_transform",
        b"",
        umsgpack.packb({"type": "set_transform", "path": 5, "matrix": "x"}),
    ],
    "msgpack_unknown_type": [
        b"set_transform",
        b"",
        umsgpack.packb({"type": "format_disk", "path": "/x"}),
    ],
    "msgpack_array_length_bomb": [b"set_object", b"", b"\xdd\xff\xff\xff\xff"],
    "msgpack_deep_nesting": [b"set_object", b"", b"\x91" * 200_000 + b"\xc0"],
    "batch_commands_not_a_list": [
        b"anthroarm_batch",
        b"",
        umsgpack.packb({"type": "anthroarm_batch", "path": "", "commands": 5}),
    ],
    "batch_of_garbage": [
        b"anthroarm_batch",
        b"",
        umsgpack.packb({"type": "anthroarm_batch", "path": "", "commands": [1, "x", None]}),
    ],
    "ui_spec_not_a_map": [
        b"anthroarm_ui",
        b"",
        umsgpack.packb({"type": "anthroarm_ui", "path": "/u", "spec": "<script>"}),
    ],
    "ui_unknown_kind": [
        b"anthroarm_ui",
        b"",
        umsgpack.packb({"type": "anthroarm_ui", "path": "/u", "spec": {"kind": "html"}}),
    ],
    "huge_garbage_payload": [b"set_object", b"", b"\xc1" * (48 * 2**20)],
    "clients_with_arguments": [b"clients", b"x"],
    "ten_thousand_frames": [b"url"] + [b""] * 10_000,
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_malformed_request_gets_an_error_reply_and_the_socket_stays_usable(srv, case):
    t0 = time.monotonic()
    reply = raw_request(srv.zmq_url, owner(srv, *MALFORMED[case]))
    assert reply is not None, f"no reply within {REPLY_TIMEOUT} s: the REP socket is wedged"
    assert reply.startswith(b"error"), reply[:200]
    assert time.monotonic() - t0 < REPLY_TIMEOUT
    assert_healthy(srv)


def test_many_malformed_requests_pipelined_from_one_peer(srv):
    """200 garbage requests queued by a DEALER (no waiting for replies): every one is
    answered, and the owner is still served."""
    d = CTX.socket(zmq.DEALER)
    d.setsockopt(zmq.LINGER, 0)
    d.setsockopt(zmq.RCVTIMEO, int(REPLY_TIMEOUT * 1000))
    try:
        d.connect(srv.zmq_url)
        cases = list(MALFORMED.values())[:12]
        n = 200
        for k in range(n):
            frames = cases[k % len(cases)]
            d.send_multipart([b"", srv.secret, *frames] if k % 2 else [b"", *frames])
        got = 0
        deadline = time.monotonic() + 30
        while got < n and time.monotonic() < deadline:  # bounded
            try:
                msg = d.recv_multipart()
            except zmq.Again:
                break
            assert msg[-1].startswith(b"error"), msg[-1][:100]
            got += 1
        assert got == n
    finally:
        d.close()
    assert_healthy(srv)


def test_a_real_viewer_keeps_working_after_abuse():
    """The full path: Viewer(live=True).display after malformed requests from a stranger and
    from the owner."""
    v = Viewer("planar2r", live=True)
    try:
        for frames in ([b"wait", b"99", b"inf"], [b"\xff"], [b"wait", b"abc"]):
            assert (raw_request(v.server.zmq_url, frames) or b"").startswith(b"error")
            assert (raw_request(v.server.zmq_url, [v.server.secret, *frames]) or b"").startswith(
                b"error"
            )
        for q in v.robot.random_q(3, rng=1):
            v.display(q)
        assert v.server.clients() == 0
    finally:
        v.close()


# ---------------------------------------------------------------------------------- item 3: authentication
STRANGER = {
    "shutdown": [b"shutdown"],
    "get_scene": [b"get_scene"],
    "url": [b"url"],
    "wait_forever": [b"wait", b"99", b"inf"],
    "inject_object": [
        b"set_transform",
        b"/meshcat/injected",
        umsgpack.packb(transform("/meshcat/injected")),
    ],
}


@pytest.mark.parametrize("case", list(STRANGER))
def test_request_without_the_secret_is_refused(srv, case):
    reply = raw_request(srv.zmq_url, STRANGER[case])
    assert reply is not None and reply.startswith(b"error") and b"secret" in reply, reply
    assert srv.alive
    assert_healthy(srv)
    assert "injected" not in srv.static_html()


@pytest.mark.parametrize(
    "kind", ["wrong_same_length", "prefix", "longer", "empty", "secret_as_command"]
)
def test_request_with_a_wrong_secret_is_refused(srv, kind):
    good = srv.secret
    bad = {
        "wrong_same_length": bytes(len(good)),
        "prefix": good[:-1],
        "longer": good + b"0",
        "empty": b"",
        "secret_as_command": None,
    }[kind]
    frames = [b"get_scene", good] if bad is None else [bad, b"get_scene"]
    reply = raw_request(srv.zmq_url, frames)
    assert reply is not None and reply.startswith(b"error") and b"secret" in reply, (reply or b"")[
        :200
    ]
    assert b"<html" not in reply.lower()
    assert_healthy(srv)


def test_secret_is_not_on_the_command_line_or_in_the_environment(srv):
    """The child gets it through its stdin: not visible in ps / /proc/PID/cmdline, not in
    /proc/PID/environ of the child."""
    assert len(srv.secret) >= 32
    with open(f"/proc/{srv.proc.pid}/cmdline", "rb") as f:
        assert srv.secret not in f.read()
    with open(f"/proc/{srv.proc.pid}/environ", "rb") as f:
        assert srv.secret not in f.read()


def test_two_servers_have_different_secrets():
    with _fresh_server() as a, _fresh_server() as b:
        assert a.secret != b.secret
        reply = raw_request(a.zmq_url, [b.secret, b"url"])
        assert reply is not None and reply.startswith(b"error")


# ---------------------------------------------------------------------------------- item 4: DNS rebinding
def http_status(port: int, path: str, host: str | None, extra: dict | None = None) -> int:
    """Status of one raw HTTP/1.1 request with exactly the given Host header (None: no Host)."""
    with socket.create_connection(("127.0.0.1", port), timeout=REPLY_TIMEOUT) as s:
        s.settimeout(REPLY_TIMEOUT)
        lines = [f"GET {path} HTTP/1.1"]
        if host is not None:
            lines.append(f"Host: {host}")
        for k, v in (extra or {}).items():
            lines.append(f"{k}: {v}")
        lines.append("Connection: close")
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode("latin-1"))
        head = b""
        deadline = time.monotonic() + REPLY_TIMEOUT
        while b"\r\n" not in head and time.monotonic() < deadline:  # bounded
            chunk = s.recv(4096)
            if not chunk:
                break
            head += chunk
    status = head.split(b"\r\n", 1)[0].split()
    return int(status[1]) if len(status) > 1 else 0


def ws_status(port: int, host: str | None, origin: str | None) -> int:
    key = base64.b64encode(os.urandom(16)).decode()
    extra = {
        "Upgrade": "websocket",
        "Connection": "Upgrade",
        "Sec-WebSocket-Key": key,
        "Sec-WebSocket-Version": "13",
    }
    if origin is not None:
        extra["Origin"] = origin
    with socket.create_connection(("127.0.0.1", port), timeout=REPLY_TIMEOUT) as s:
        s.settimeout(REPLY_TIMEOUT)
        lines = (
            ["GET / HTTP/1.1"]
            + ([f"Host: {host}"] if host is not None else [])
            + [f"{k}: {v}" for k, v in extra.items()]
        )
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode("latin-1"))
        head = s.recv(4096)
    status = head.split(b"\r\n", 1)[0].split()
    return int(status[1]) if len(status) > 1 else 0


BAD_HOSTS = [
    "evil.example",
    "evil.example:{port}",
    "127.0.0.1.evil.example:{port}",
    "localhost.evil.example",
    "10.0.0.1:{port}",
    "0.0.0.0:{port}",
    "",
    "127.0.0.1:{port}@evil.example",
    "[::1].evil.example",
]
GOOD_HOSTS = [
    "127.0.0.1:{port}",
    "127.0.0.1",
    "localhost:{port}",
    "LocalHost",
    "[::1]:{port}",
    "[::1]",
]


@pytest.mark.parametrize("path", ["/static/", "/static/index.html", "/static/main.min.js", "/"])
@pytest.mark.parametrize("host", BAD_HOSTS)
def test_http_with_a_foreign_host_is_forbidden(srv, path, host):
    # 403 from the viewer; tornado itself answers 400 to a Host header that is not a host name
    assert http_status(srv.port, path, host.format(port=srv.port)) in (400, 403)


def test_http_without_a_host_header_is_forbidden(srv):
    with socket.create_connection(("127.0.0.1", srv.port), timeout=REPLY_TIMEOUT) as s:
        s.settimeout(REPLY_TIMEOUT)
        s.sendall(b"GET /static/ HTTP/1.0\r\n\r\n")
        head = s.recv(4096)
    assert head.split()[1] == b"403", head[:100]


@pytest.mark.parametrize("host", GOOD_HOSTS)
def test_http_with_a_loopback_host_is_served(srv, host):
    assert http_status(srv.port, "/static/", host.format(port=srv.port)) == 200
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=REPLY_TIMEOUT)
    try:
        conn.request("GET", "/static/", headers={"Host": host.format(port=srv.port)})
        r = conn.getresponse()
        assert r.status == 200 and b"MeshCat" in r.read()
    finally:
        conn.close()


@pytest.mark.parametrize(
    "host,origin",
    [
        ("evil.example:{port}", "http://evil.example:{port}"),  # the rebinding attack itself
        ("evil.example:{port}", None),
        ("127.0.0.1:{port}", "http://evil.example:{port}"),
        ("127.0.0.1:{port}", "null"),
        ("127.0.0.1:{port}", "http://127.0.0.1.evil.example"),
        ("localhost:{port}", "https://localhost.evil.example:{port}"),
        (None, None),
    ],
)
def test_websocket_from_a_foreign_host_or_origin_is_refused(srv, host, origin):
    fmt = lambda x: None if x is None else x.format(port=srv.port)
    assert ws_status(srv.port, fmt(host), fmt(origin)) != 101


@pytest.mark.parametrize(
    "host,origin",
    [
        ("127.0.0.1:{port}", "http://127.0.0.1:{port}"),
        ("localhost:{port}", "http://localhost:{port}"),
        ("[::1]:{port}", "http://[::1]:{port}"),
        ("127.0.0.1:{port}", None),  # a non-browser client
    ],
)
def test_websocket_from_loopback_is_accepted(srv, host, origin):
    fmt = lambda x: None if x is None else x.format(port=srv.port)
    assert ws_status(srv.port, fmt(host), fmt(origin)) == 101


# ---------------------------------------------------------------------------------- item 12: bad arguments
@pytest.mark.parametrize(
    "port", [True, False, 1.0, 7000.0, "7000", -1, 0, 65536, 10**20, float("nan"), [7000]]
)
def test_bad_viewer_ports_are_typed_errors_and_start_nothing(port):
    exc = TypeError if isinstance(port, (bool, float, str, list)) else ValueError
    with pytest.raises(exc, match="port") as ei:
        Viewer("planar2r", live=True, port=port)
    assert isinstance(ei.value, AnthroarmError)


def test_numpy_integer_port_is_accepted():
    s0 = socket.socket()
    s0.bind(("127.0.0.1", 0))
    port = s0.getsockname()[1]
    s0.close()
    with ServerProcess(port=np.int64(port)) as s:
        assert s.port == port


@pytest.mark.parametrize("timeout", [math.inf, math.nan, -1.0, 0.0, True, "5", 1e9])
def test_bad_server_timeouts_are_typed_errors(timeout):
    with pytest.raises((TypeError, ValueError), match="timeout") as ei:
        ServerProcess(timeout=timeout)
    assert isinstance(ei.value, AnthroarmError)


@pytest.fixture(scope="module")
def live_viewer():
    v = Viewer("planar2r", live=True)
    yield v
    v.close()


@pytest.mark.parametrize(
    "kw",
    [
        {"timeout": math.inf},
        {"timeout": math.nan},
        {"timeout": -1.0},
        {"timeout": 1e9},
        {"timeout": "1"},
        {"n": 0},
        {"n": -2},
        {"n": 1.5},
        {"n": True},
        {"n": 10**12},
        {"n": "1"},
    ],
)
def test_bad_wait_arguments_are_typed_errors(live_viewer, kw):
    t0 = time.monotonic()
    with pytest.raises((TypeError, ValueError)) as ei:
        live_viewer.wait(**kw)
    assert isinstance(ei.value, AnthroarmError)
    assert time.monotonic() - t0 < 2.0
    live_viewer.display(live_viewer.robot.neutral())
    assert live_viewer.server.clients() == 0


def test_wait_times_out_with_a_viewer_error(live_viewer):
    t0 = time.monotonic()
    with pytest.raises(ViewerError, match="0 of 1"):
        live_viewer.wait(1, timeout=0.3)
    assert time.monotonic() - t0 < 3.0
    live_viewer.display(live_viewer.robot.neutral())


@pytest.mark.parametrize(
    "q",
    [
        np.zeros(3),
        np.zeros((2, 2)),
        np.array([np.nan, 0.0]),
        np.array([np.inf, 0.0]),
        "abc",
        None,
        [[0.0, 0.0]],
        np.zeros(0),
    ],
)
def test_bad_display_configurations_are_value_errors_and_the_viewer_keeps_working(live_viewer, q):
    with pytest.raises(ValueError):
        live_viewer.display(q)
    live_viewer.display(live_viewer.robot.neutral())


@pytest.mark.parametrize(
    "kw",
    [
        {"background": "red"},
        {"background": ((0, 0, 0),)},
        {"background": ((0, 0, "x"), (1, 1, 1))},
        {"background": ((0, 0, np.nan), (1, 1, 1))},
        {"background": ((0, 0, 300), (1, 1, 1))},
        {"style": 5},
    ],
)
def test_bad_viewer_arguments_are_typed_errors(kw):
    with pytest.raises((TypeError, ValueError), match="background|style"):
        Viewer("planar2r", **kw)


def test_viewer_of_something_that_is_not_a_robot_is_a_type_error():
    with pytest.raises(TypeError, match="Robot"):
        Viewer(12345)


def test_a_robot_viewer_still_loads_after_all_this():
    v = Viewer(aa.load("planar2r"))
    v.display([0.1, 0.2])
    assert "set_transform" in v.static_html() or len(v.static_html()) > 1000
