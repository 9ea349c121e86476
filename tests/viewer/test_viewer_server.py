"""The live server: 127.0.0.1 only, explicit ports, port-in-use error, one message per pose,
cleanup on close and when the owning Python process dies."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import textwrap
import time
import urllib.request

import pytest

import anthroarm as aa
from anthroarm.errors import ViewerPortInUseError
from anthroarm.viewer import Viewer
from anthroarm.viewer.server import ServerProcess, port_is_free


def listening_addresses(port: int) -> set[str]:
    """Local addresses with a TCP socket LISTENing on ``port`` (from /proc/net/tcp{,6})."""
    out = set()
    for fname in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            with open(fname) as f:
                lines = f.read().splitlines()[1:]
        except OSError:
            continue
        for ln in lines:
            f = ln.split()
            addr, p = f[1].split(":")
            if int(p, 16) == port and f[3] == "0A":
                if len(addr) == 8:
                    out.add(socket.inet_ntoa(bytes.fromhex(addr)[::-1]))
                else:
                    out.add("v6:" + addr)
    return out


def pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie is dead for our purpose
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


@pytest.fixture(scope="module")
def server():
    s = ServerProcess()
    yield s
    s.close()


@pytest.mark.skipif(not os.path.exists("/proc/net/tcp"), reason="needs Linux /proc/net/tcp")
def test_server_listens_on_loopback_only(server):
    assert listening_addresses(server.port) == {"127.0.0.1"}
    assert server.web_url == f"http://127.0.0.1:{server.port}/static/"
    assert server.zmq_url.startswith("tcp://127.0.0.1:")
    zport = int(server.zmq_url.rsplit(":", 1)[1])
    assert listening_addresses(zport) == {"127.0.0.1"}


def test_page_and_redirect(server):
    page = urllib.request.urlopen(server.web_url, timeout=10).read().decode()
    assert "MeshCat.Viewer" in page and "anthroarm_batch" in page and "viewer.connect()" in page
    r = urllib.request.urlopen(f"http://127.0.0.1:{server.port}/", timeout=10)
    assert r.geturl().endswith("/static/")
    js = urllib.request.urlopen(server.web_url + "main.min.js", timeout=10).read()
    assert len(js) > 500_000


def test_explicit_port_in_use_is_a_clear_error():
    blocker = socket.socket()
    blocker.bind(("127.0.0.1", 0))
    blocker.listen()
    port = blocker.getsockname()[1]
    try:
        with pytest.raises(
            ViewerPortInUseError, match=f"port {port} on 127.0.0.1 is already in use"
        ):
            ServerProcess(port=port)
        with pytest.raises(ViewerPortInUseError):
            Viewer("planar2r", live=True, port=port)
    finally:
        blocker.close()


def test_explicit_free_port_is_used():
    port = free_ephemeral_port()
    with ServerProcess(port=port) as s:
        assert s.port == port and not port_is_free(port)
    assert port_is_free(port)


@pytest.mark.parametrize("bad", [0, 70000, -1, 1.5, "http"])
def test_bad_port_values(bad):
    with pytest.raises(ValueError, match="port"):
        ServerProcess(port=bad)


def free_ephemeral_port() -> int:
    """A free port from the OS's ephemeral range: other processes that take the first free
    port from 7000 (other viewers on this machine) will not grab it between our steps."""
    s0 = socket.socket()
    s0.bind(("127.0.0.1", 0))
    port = s0.getsockname()[1]
    s0.close()
    return port


def test_close_stops_the_process():
    s = ServerProcess(port=free_ephemeral_port())
    pid = s.proc.pid
    s.close()
    s.close()  # idempotent
    assert not pid_alive(pid)
    assert port_is_free(s.port)


def test_server_exits_when_its_python_dies(tmp_path):
    """A Python that is SIGKILLed (no atexit) must not leave the server behind."""
    script = textwrap.dedent("""
        import sys, time
        from anthroarm.viewer.server import ServerProcess
        s = ServerProcess()
        print(s.proc.pid, s.port, flush=True)
        time.sleep(60)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    try:
        pid, port = map(int, child.stdout.readline().split())
        assert pid_alive(pid)
        child.send_signal(signal.SIGKILL)
        child.wait(10)
        deadline = time.time() + 10
        while pid_alive(pid) and time.time() < deadline:
            time.sleep(0.1)
        assert not pid_alive(pid), "server outlived its parent"
    finally:
        if child.poll() is None:
            child.kill()


def test_pose_update_is_one_message_and_mirrors_the_scene():
    robot = aa.load("human_arm7")
    with Viewer(robot, live=True) as v:
        calls = []
        real = v.server._request

        def counting(frames):
            calls.append(frames[0])
            return real(frames)

        v.server._request = counting
        v.display(robot.random_q(rng=0))
        assert calls == [b"anthroarm_batch"]
        # the server's scene equals the in-process one (what a newly opened tab receives)
        assert v.server.static_html() == v.store.static_html()


def test_wait_timeout_leaves_the_server_usable(server):
    from anthroarm.errors import ViewerError

    with pytest.raises(ViewerError, match="0 of 1 browser tabs"):
        server.wait(1, timeout=0.3)
    assert server.clients() == 0  # the server still answers


def test_repr_html_is_live_iframe():
    with Viewer("planar2r", live=True) as v:
        h = v._repr_html_()
        assert f'src="{v.url}"' in h
        assert v.server.clients() == 0
