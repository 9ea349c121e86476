"""The ``anthroarm`` command line.

User mistakes (unknown model, bad arguments, missing folders) print one line to stderr and
exit with status 2; failed checks exit with status 1.  No tracebacks for user mistakes.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import AnthroarmError


class UserError(Exception):
    """A mistake in the command line; printed as one line, exit status 2."""


def _add_check(sub):
    p = sub.add_parser(
        "check",
        help="cross-check the book's closed forms against Pinocchio",
        description="Cross-check every closed form against Pinocchio on random configurations inside the limits.",
        epilog="example: anthroarm check --models prosthetic_arm human_arm7 --samples 500 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--models", nargs="*", default=None, help="restrict to these catalog models")
    p.add_argument("--samples", type=int, default=200, help="random configurations per model (default 200)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.set_defaults(func=cmd_check)


def cmd_check(a) -> int:
    from . import crosscheck

    if a.samples < 1:
        raise UserError("--samples must be >= 1")
    rows = crosscheck.run(a.models, samples=a.samples, seed=a.seed, progress=not a.json and sys.stderr.isatty())
    print(crosscheck.to_json(rows) if a.json else crosscheck.format_table(rows))
    return 0 if all(r.ok for r in rows) else 1


def _add_models(sub):
    p = sub.add_parser(
        "models",
        help="list the model catalog",
        description="List the catalog: the book's models and the example-robot-data arms.",
        epilog="example: anthroarm models --json",
    )
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_models)


def cmd_models(a) -> int:
    from . import models

    out = []
    for n in models.names():
        if n in models.BOOK_MODELS:
            s = models.spec(n)
            out.append({"name": n, "nq": s.nq, "tool": s.tool_name, "source": s.source, "description": s.description})
        else:
            arm = models.ERD_ARMS[n]
            out.append({"name": n, "nq": len(arm.active) if arm.active else None, "tool": arm.tool,
                        "source": f"example-robot-data {arm.subpath}", "description": arm.description})
    if a.json:
        print(json.dumps(out, indent=1))
    else:
        w = max(len(o["name"]) for o in out)
        for o in out:
            print(f"{o['name']:<{w}}  nq={o['nq'] if o['nq'] is not None else '?':<2}  {o['description']}")
    return 0


def _add_urdf(sub):
    p = sub.add_parser(
        "urdf",
        help="write a catalog URDF with chosen parameters",
        description="Write the URDF of a book model; parameters are the model builder's keyword arguments.",
        epilog="example: anthroarm urdf human_arm7 -o arm.urdf --param height=1.62 --param mass=55 --param sex=female",
    )
    p.add_argument("model")
    p.add_argument("-o", "--output", required=True, help="output .urdf file")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE", help="builder parameter (repeatable)")
    p.set_defaults(func=cmd_urdf)


def _parse_params(items) -> dict:
    params = {}
    for it in items:
        if "=" not in it:
            raise UserError(f"--param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        try:
            params[k] = float(v)
        except ValueError:
            params[k] = v
    return params


def cmd_urdf(a) -> int:
    from . import models
    from ._io import atomic_write_text

    if a.model not in models.BOOK_MODELS:
        if a.model in models.ERD_ARMS:
            raise UserError(f"{a.model} comes from example-robot-data; its URDF is {models.urdf_path(a.model)}")
        raise UserError(f"unknown model {a.model!r}; the book models are: {', '.join(models.book_names())}")
    out = Path(a.output)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist")
    text = models.urdf_text(a.model, **_parse_params(a.param))
    atomic_write_text(out, text)
    print(f"wrote {out}")
    return 0


def _add_bench(sub):
    p = sub.add_parser(
        "bench",
        help="run benchmarks (JSON + markdown in benchmarks/results)",
        description="Run the benchmark suite side by side with the peers.",
        epilog="example: anthroarm bench fk --quick",
    )
    p.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    p.add_argument("--quick", action="store_true", help="fewer samples")
    p.add_argument("--list", action="store_true", help="list the benchmarks")
    p.set_defaults(func=cmd_bench)


def _benchmarks_module():
    root = Path(__file__).resolve().parents[2]
    if not (root / "benchmarks" / "__main__.py").is_file():
        raise UserError("the benchmarks/ folder is not available (run from a source checkout)")
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    import benchmarks.__main__ as bm

    return bm


def cmd_bench(a) -> int:
    bm = _benchmarks_module()
    if a.list:
        print("\n".join(bm.available()))
        return 0
    unknown = [n for n in a.names if n not in bm.available()]
    if unknown:
        raise UserError(f"unknown benchmark(s) {unknown}; available: {', '.join(bm.available())}")
    bm.run(a.names or None, quick=a.quick)
    return 0


# ---------------------------------------------------------------------------------- shared helpers
def _load_model(name, params=None):
    """Load a catalog model or URDF path; user mistakes become one-line UserErrors."""
    from . import load, models
    from .errors import UnknownModelError

    try:
        return load(name, **(params or {}))
    except UnknownModelError:
        raise UserError(f"unknown model {name!r}; the catalog has: {', '.join(models.names())}") from None


def _parse_q(robot, values, deg: bool, what: str = "--q"):
    import numpy as np

    if values is None:
        return robot.neutral()
    if len(values) != robot.nq:
        raise UserError(f"{what} needs {robot.nq} values for {robot.name} (joints: {', '.join(robot.joint_names)}), "
                        f"got {len(values)}")
    q = np.deg2rad(values) if deg else np.asarray(values, float)
    q = robot.check_q(q, what)
    if not robot.within_limits(q, tol=1e-9):
        bad = [robot.joint_names[i] for i in np.flatnonzero((q < robot.lower - 1e-9) | (q > robot.upper + 1e-9))]
        print(f"anthroarm: warning: {what} is outside the joint limits of {', '.join(bad)}", file=sys.stderr)
    return q


def _check_html_path(path):
    if path is None:
        return None
    out = Path(path)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist (for --html {path})")
    if out.is_dir():
        raise UserError(f"--html {path} is a folder; give a file name such as {out / 'scene.html'}")
    return out


def _progress(total: int, desc: str, enabled: bool):
    """A tqdm bar on stderr (only when stderr is a terminal and enabled)."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, file=sys.stderr, disable=not (enabled and sys.stderr.isatty()),
                leave=False)


def _serve(viewer, open_browser: bool, seconds: float | None) -> int:
    """Keep a live viewer running until Ctrl-C (or ``seconds``)."""
    import time

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


def _export_or_serve(viewer, out, a, announce: bool = True) -> int:
    """Write the scene to ``out`` (``--html``), or serve it live until Ctrl-C / ``--seconds``."""
    if out is not None:
        viewer.export_html(out)
        if announce:
            print(f"wrote {out}")
        return 0
    return _serve(viewer, not a.no_browser, a.seconds)


def _check_port_early(a):
    """Fail before any long work when an explicit --port is taken (or invalid)."""
    if getattr(a, "html", None) is None and a.port is not None:
        from .viewer.server import _in_use_message, port_is_free

        if not 1 <= a.port <= 65535:
            raise UserError(f"--port must be in 1..65535, got {a.port}")
        if not port_is_free(a.port):
            raise UserError(_in_use_message(a.port))


def _add_live_options(p):
    p.add_argument("--html", metavar="FILE", help="write a self-contained HTML file instead of starting a server")
    p.add_argument("--port", type=int, default=None, help="server port on 127.0.0.1 (default: first free from 7000)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser tab")
    p.add_argument("--seconds", type=float, default=None, help=argparse.SUPPRESS)  # tests: stop after N s


# ---------------------------------------------------------------------------------- view
def _add_view(sub):
    p = sub.add_parser(
        "view",
        help="show a model in the browser (meshcat) or write it to HTML",
        description="Show a catalog model (or a URDF file) in a meshcat viewer on 127.0.0.1, or write a "
                    "self-contained HTML file.  Angles are radians unless --deg.",
        epilog="examples:\n  anthroarm view human_arm7 --q 40 -20 10 70 0 0 10 --deg --limits\n"
               "  anthroarm view panda --html panda.html --workspace 3000",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("model", help="catalog name (see 'anthroarm models') or a .urdf path")
    p.add_argument("--q", nargs="+", type=float, metavar="Q", help="joint values, one per joint")
    p.add_argument("--deg", action="store_true", help="--q is in degrees")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="book-model parameter, e.g. height=1.62 (repeatable)")
    p.add_argument("--limits", action="store_true", help="colour links by joint-limit proximity")
    p.add_argument("--frames", action="store_true", help="draw the joint frames")
    p.add_argument("--workspace", type=int, default=0, metavar="N", help="draw N workspace points coloured by manipulability")
    p.add_argument("--style", choices=["auto", "generated", "urdf"], default="auto", help="visuals (default auto)")
    _add_live_options(p)
    p.set_defaults(func=cmd_view)


def cmd_view(a) -> int:
    from .viewer import Viewer

    out = _check_html_path(a.html)
    _check_port_early(a)
    robot = _load_model(a.model, _parse_params(a.param))
    q = _parse_q(robot, a.q, a.deg)
    if a.workspace < 0:
        raise UserError("--workspace must be >= 0")
    v = Viewer(robot, live=out is None, port=a.port, style=a.style, q=q)
    if a.frames:
        v.show_frames("joints")
    if a.workspace:
        v.show_workspace(a.workspace)
    if a.limits:
        v.show_limits()
    return _export_or_serve(v, out, a)


# ---------------------------------------------------------------------------------- demo
def _add_demo(sub):
    p = sub.add_parser(
        "demo",
        help="the human arm reaching for a sequence of targets (QP IK), in the browser or to HTML",
        description="The §6-3 human arm (human_arm7) reaches for five hand poses in turn and returns to rest, "
                    "driven by QP differential IK (anthroarm.ik.qp; damped least squares if that layer is missing). "
                    "The motion plays as a looping meshcat animation with the targets and the hand's path.",
        epilog="examples:\n  anthroarm demo\n  anthroarm demo --html demo.html",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="human_arm7 parameter, e.g. height=1.62 (repeatable)")
    p.add_argument("--method", choices=["auto", "qp", "dls"], default="auto", help="IK stepper (default auto: qp)")
    p.add_argument("--solver", default="osqp", help="QP solver for --method qp (default osqp)")
    p.add_argument("--json", action="store_true", help="print the per-target errors as JSON")
    _add_live_options(p)
    p.set_defaults(func=cmd_demo)


def cmd_demo(a) -> int:
    from .viewer.demo import demo_viewer, reach_demo

    out = _check_html_path(a.html)
    _check_port_early(a)
    robot = _load_model("human_arm7", _parse_params(a.param))
    bar = _progress(6, "reaching", not a.json)

    def tick(done, total):
        bar.total = total
        bar.update(done - bar.n)

    try:
        res = reach_demo(robot, method=a.method, solver=a.solver, progress=tick)
    finally:
        bar.close()
    if a.json:
        print(json.dumps({"method": res.method, "dt": res.dt, "steps": int(len(res.Q)),
                          "targets": [{"name": n, "pos_err_m": pe, "rot_err_rad": re} for n, pe, re in res.errors]},
                         indent=1))
    else:
        print(f"IK: {res.method}; {len(res.Q)} steps of {res.dt * 1000:.0f} ms")
        for n, pe, re in res.errors:
            print(f"  {n:<18} position error {pe * 1000:8.3f} mm   orientation error {re:.2e} rad")
    v = demo_viewer(res, live=out is None, port=a.port)
    return _export_or_serve(v, out, a, announce=not a.json)


# ---------------------------------------------------------------------------------- ik
def _add_ik(sub):
    p = sub.add_parser(
        "ik",
        help="inverse kinematics of a tool pose",
        description="Joint values that put the tool frame at a pose given by a position (m) and roll-pitch-yaw "
                    "angles (R = Rz(yaw) Ry(pitch) Rx(roll); radians unless --deg), in the model's base frame.  "
                    "Uses aa.ik.solve when available, the book's closed form (every branch) for the book arms, "
                    "else damped least squares with restarts.  Exit status 1 when no solution is found.",
        epilog="example (hand to mouth): anthroarm ik human_arm7 --xyz 0.151 0.193 0.141 --rpy 179.5 6.1 -71.3 --deg --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("model", help="catalog name or .urdf path")
    p.add_argument("--xyz", nargs=3, type=float, required=True, metavar=("X", "Y", "Z"), help="position, m")
    p.add_argument("--rpy", nargs=3, type=float, default=[0.0, 0.0, 0.0], metavar=("R", "P", "Y"),
                   help="roll pitch yaw (default 0 0 0)")
    p.add_argument("--deg", action="store_true", help="--rpy, --q0 and the printed q are in degrees")
    p.add_argument("--q0", nargs="+", type=float, metavar="Q", help="initial guess (one value per joint)")
    p.add_argument("--frame", default=None, help="frame to place (default: the model's tool)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE", help="book-model parameter")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=cmd_ik)


def cmd_ik(a) -> int:
    import math

    import numpy as np
    import pinocchio as pin

    robot = _load_model(a.model, _parse_params(a.param))
    if not all(math.isfinite(x) for x in [*a.xyz, *a.rpy]):
        raise UserError("--xyz and --rpy must be finite numbers")
    rpy = np.deg2rad(a.rpy) if a.deg else np.asarray(a.rpy, float)
    T = np.eye(4)
    T[:3, :3] = pin.rpy.rpyToMatrix(*rpy)
    T[:3, 3] = a.xyz
    if a.frame is not None:
        robot.frame_id(a.frame)  # UnknownFrameError (one line, lists the frames)
    q0 = _parse_q(robot, a.q0, a.deg, "--q0") if a.q0 is not None else None
    bar = _progress(1, "ik", not a.json)
    try:
        res = solve_pose(robot, T, q0=q0, frame=a.frame)
    finally:
        bar.close()
    conv = (lambda x: np.rad2deg(x)) if a.deg else (lambda x: np.asarray(x))
    if a.json:
        out = {"model": robot.name, "frame": a.frame or robot.tool, "xyz": list(a.xyz), "rpy": list(a.rpy),
               "units": "deg" if a.deg else "rad", **res.to_dict(conv, robot.joint_names)}
        print(json.dumps(out, indent=1))
    else:
        unit = "deg" if a.deg else "rad"
        print(f"{robot.name}: {'solved' if res.success else 'NOT solved'} ({res.status}) by {res.method}")
        if res.q is not None:
            for n, v in zip(robot.joint_names, conv(res.q)):
                print(f"  {n:<22} {v: .6f} {unit}")
            print(f"  position error {res.pos_err:.3e} m, orientation error {res.rot_err:.3e} rad")
        if len(res.solutions) > 1:
            print(f"  {len(res.solutions)} closed-form branches inside the limits (--json lists them)")
    return 0 if res.success else 1


# ---------------------------------------------------------------------------------- ik glue
class _IKOutcome:
    """What ``anthroarm ik`` reports, whichever solver produced it."""

    def __init__(self, q, success, status, pos_err, rot_err, iterations, method, solutions=()):
        self.q, self.success, self.status = q, bool(success), str(status)
        self.pos_err, self.rot_err, self.iterations, self.method = pos_err, rot_err, int(iterations), method
        self.solutions = list(solutions)

    def to_dict(self, conv, joint_names) -> dict:
        as_list = lambda x: [float(v) for v in conv(x)]  # noqa: E731
        return {"success": self.success, "status": self.status, "method": self.method,
                "q": dict(zip(joint_names, as_list(self.q))) if self.q is not None else None,
                "pos_err_m": self.pos_err, "rot_err_rad": self.rot_err, "iterations": self.iterations,
                "closed_form_solutions": [as_list(q) for q in self.solutions]}


def _pose_err(robot, q, T, frame):
    import numpy as np
    import pinocchio as pin

    F = robot.fk(q, frame)
    return float(np.linalg.norm(F[:3, 3] - T[:3, 3])), float(np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3])))


def solve_pose(robot, T, q0=None, frame=None, tol=1e-6) -> _IKOutcome:
    """IK for the CLI: ``aa.ik.solve`` when it exists; else the closed form (all branches) of a
    book arm; else damped least squares with random restarts.  Errors are recomputed here
    from ``robot.fk`` whatever the solver says."""
    import numpy as np

    from . import ik

    sols = []
    if frame is None and hasattr(ik, "has_analytic") and ik.has_analytic(robot):
        ana = ik.analytic(robot, T)
        sols = list(np.atleast_2d(ana.solutions)) if len(ana.solutions) else []
    solve = getattr(ik, "solve", None)
    if callable(solve):
        r = solve(robot, T, q0=q0, frame=frame)
        pe, re = _pose_err(robot, r.q, T, frame)
        return _IKOutcome(r.q, r.success, r.status, pe, re, r.iterations, "aa.ik.solve", sols)
    if sols:
        ref = robot.neutral() if q0 is None else q0
        q = min(sols, key=lambda s: float(np.linalg.norm(s - ref)))
        pe, re = _pose_err(robot, q, T, frame)
        ok = pe <= tol and re <= tol
        return _IKOutcome(q, ok, "success" if ok else "not_converged", pe, re, 0, "closed form", sols)
    if frame is None and hasattr(ik, "has_analytic") and ik.has_analytic(robot):
        return _IKOutcome(None, False, f"no closed-form solution: {ana.reason}", float("nan"), float("nan"), 0,
                          "closed form")
    return _dls_restarts(robot, T, q0, frame, tol)


def _dls_restarts(robot, T, q0, frame, tol, restarts=20, iters=200):
    """Damped least squares (λ = 1e-3 m) on the LOCAL_WORLD_ALIGNED Jacobian, q clipped into
    the limits, from q0 / neutral and then random seeds (fixed RNG)."""
    import numpy as np
    import pinocchio as pin

    rng = np.random.default_rng(0)
    seeds = [q0 if q0 is not None else robot.neutral()] + list(robot.random_q(restarts, rng=rng))
    best, best_err, total = None, (np.inf, np.inf), 0
    for q in seeds:
        q = np.array(q, float)
        for _ in range(iters):
            total += 1
            F = robot.fk(q, frame)
            e = np.concatenate([T[:3, 3] - F[:3, 3], F[:3, :3] @ pin.log3(F[:3, :3].T @ T[:3, :3])])
            if np.linalg.norm(e[:3]) <= tol and np.linalg.norm(e[3:]) <= tol:
                break
            J = robot.jacobian(q, frame)
            q = np.clip(q + J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(6), e), robot.lower, robot.upper)
        err = _pose_err(robot, q, T, frame)
        if sum(err) < sum(best_err):
            best, best_err = q, err
        if err[0] <= tol and err[1] <= tol:
            break
    ok = best_err[0] <= tol and best_err[1] <= tol
    return _IKOutcome(best, ok, "success" if ok else "not_converged", *best_err, total, "damped least squares")


# ---------------------------------------------------------------------------------- cache
def _add_cache(sub):
    p = sub.add_parser(
        "cache",
        help="show or empty the cache of generated code",
        description="The disk cache of generated Lagrange code and compiled C kernels "
                    "($ANTHROARM_CACHE, else $XDG_CACHE_HOME/anthroarm, else the user cache folder).",
        epilog="examples: anthroarm cache info --json; anthroarm cache clear",
    )
    p.add_argument("action", choices=["info", "clear"], help="info: folder, entries and size; clear: delete them")
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.set_defaults(func=cmd_cache)


def cmd_cache(a) -> int:
    from . import cache

    if a.action == "clear":
        where = str(cache.root())
        n = cache.clear()
        print(json.dumps({"folder": where, "removed": n}) if a.json else f"removed {n} entries from {where}")
        return 0
    i = cache.info()
    if a.json:
        print(json.dumps(i, indent=1))
    else:
        print(f"folder  {i['folder']}")
        print(f"entries {i['entries']} ({i['bytes'] / 1e6:.2f} MB)")
        for sub, (n, size) in i["by_folder"].items():
            print(f"  {sub:<9} {n:4d} entries {size / 1e6:8.2f} MB")
        print(f"status  {i['status']}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="anthroarm",
        description="anthroarm: the book's arms, kinematics, IK and dynamics, proven against Pinocchio.",
        epilog="run 'anthroarm COMMAND --help' for the options and an example of each command",
    )
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    for add in (_add_check, _add_models, _add_ik, _add_view, _add_demo, _add_urdf, _add_bench, _add_cache):
        add(sub)
    return ap


def main(argv=None) -> int:
    ap = build_parser()
    a = ap.parse_args(argv)
    if not getattr(a, "command", None):
        ap.print_help()
        return 2
    try:
        return int(a.func(a) or 0)
    except (UserError, AnthroarmError, ValueError, FileNotFoundError) as exc:
        msg = " ".join(str(exc).split())  # one line
        print(f"anthroarm {a.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"anthroarm {a.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` etc.
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
