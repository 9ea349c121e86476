"""``anthroarm view``, ``teach`` and ``demo``: the runs (the parsers: :mod:`.view`), and serving
a live viewer until Ctrl-C."""

from __future__ import annotations

import json
import math
import time

from .. import models
from ..viewer import Viewer
from ..viewer.demo import demo_viewer, reach_demo
from ..viewer.server import in_use_message, port_is_free
from .common import MAX_SAMPLES, UserError, check_out_file
from .person import check_person
from .runtime import load_model, model_from_args, parse_params, parse_q, progress


def check_port_early(a):
    """Fail before any long work (and before a server or a browser starts) when an explicit
    --port is taken or invalid, or --seconds is not a finite number >= 0."""
    if a.seconds is not None and not (math.isfinite(a.seconds) and a.seconds >= 0):
        raise UserError(f"--seconds must be a finite number >= 0, got {a.seconds}")
    if a.out is None and a.port is not None:
        if not 1 <= a.port <= 65535:
            raise UserError(f"--port must be in 1..65535, got {a.port}")
        if not port_is_free(a.port):
            raise UserError(in_use_message(a.port))


def serve(viewer, open_browser: bool, seconds: float | None) -> int:
    """Keep a live viewer running until Ctrl-C (or ``seconds``)."""
    print(f"viewer at {viewer.url}  (Ctrl-C to stop)", flush=True)
    if open_browser:
        viewer.open()
    try:
        if seconds is None:
            while viewer.server is not None and viewer.server.alive:
                time.sleep(0.5)
        else:
            time.sleep(max(0.0, seconds))
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
    return 0


def export_or_serve(viewer, out, a, announce: bool = True) -> int:
    """Write the scene to ``out`` (``-o``), or serve it live until Ctrl-C / ``--seconds``."""
    if out is not None:
        viewer.export_html(out)
        if announce:
            print(f"wrote {out}")
        return 0
    return serve(viewer, not a.no_browser, a.seconds)


def view(a) -> int:
    out = check_out_file(a.out, "scene.html")
    check_port_early(a)
    robot = model_from_args(a)
    if not 0 <= a.workspace <= MAX_SAMPLES:
        raise UserError(f"--workspace must be in 0..{MAX_SAMPLES}, got {a.workspace}")
    q = parse_q(robot, a.q, a.deg)
    v = Viewer(robot, live=out is None, port=a.port, style=a.style, q=q)
    if a.frames:
        v.show_frames("joints")
    if a.workspace:
        v.show_workspace(a.workspace)
    if a.limits:
        v.show_limits()
    v.set_camera(a.camera, fit=a.fit)
    return export_or_serve(v, out, a)


def teach(a) -> int:
    out = check_out_file(a.out, "teach.html")
    check_port_early(a)
    robot = model_from_args(a)
    q = parse_q(robot, a.q, a.deg)
    v = Viewer(robot, live=out is None, port=a.port, style=a.style, q=q)
    if a.limits:
        v.show_limits()
    v.teach()
    v.set_camera(a.camera, fit=a.fit)
    return export_or_serve(v, out, a)


def demo(a) -> int:
    out = check_out_file(a.out, "demo.html")
    check_port_early(a)
    arm = models.PERSON_ARM
    person = check_person(a)
    params = parse_params(a.param, arm)
    twice = sorted(set(params) & set(person))
    if twice:
        raise UserError(f"give {twice[0]} once: --{twice[0]} (not --param {twice[0]}=...)")
    robot = load_model(arm, {**params, **person})
    bar = progress(6, "reaching", not a.json)

    def tick(done, total):
        bar.total = total
        bar.update(done - bar.n)

    try:
        res = reach_demo(robot, method=a.method, solver=a.solver, progress=tick)
    finally:
        bar.close()
    if a.json:
        targets = [{"name": n, "pos_err_m": pe, "rot_err_rad": re} for n, pe, re in res.errors]
        summary = dict(method=res.method, dt=res.dt, steps=int(len(res.Q)), targets=targets)
        print(json.dumps(summary, indent=1))
    else:
        print(f"IK: {res.method}; {len(res.Q)} steps of {res.dt * 1000:.0f} ms")
        for n, pe, re in res.errors:
            print(f"  {n:<18} position error {pe * 1000:8.3f} mm   orientation error {re:.2e} rad")
    v = demo_viewer(res, live=out is None, port=a.port)
    v.set_camera(a.camera, fit=a.fit)
    return export_or_serve(v, out, a, announce=not a.json)
