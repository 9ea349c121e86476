"""``anthroarm check``: every closed form against an independent oracle, on any robot.

:func:`run` loads the robots asked for (catalog names, example-robot-data names, URDF paths or
:class:`~anthroarm.robot.Robot` objects) and collects :class:`CheckRow` s from two kinds of
providers; each row compares one quantity over random samples and records the largest error.

* :data:`ROBOT_PROVIDERS` run on every robot: ``rows(robot, samples, rng) -> list[CheckRow]``
  (FK and Jacobians vs Pinocchio and yourdfpy, §6-6 error propagation, the Lagrange equations
  vs crba/rnea/aba, ``aa.ik.solve`` round trips).  A robot a provider cannot handle
  (:class:`~anthroarm.errors.UnsupportedModelError`) gets one row noting
  ``unsupported: <reason>``; a provider that raises anything else gets one row noting
  ``error: <exception>``.  Neither passes.
* :data:`PROVIDERS` are the book's rows: ``rows(names, samples, rng)`` with the catalog names
  among the models asked for, unless ``tool``/``locked`` change them (the book models' closed
  forms, IK and reach; the spatial mathematics and mechanisms, which need no model, always run).

``anthroarm check`` prints the rows and exits non-zero unless every row passes.  To add checks,
write a provider next to the code it checks and append ``"package.module:function"`` to the
list of its kind.
"""

from __future__ import annotations

import importlib
import json
import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
import pinocchio as pin
from tqdm.auto import tqdm

from . import ik
from . import models as catalog
from .check_rows import UNSUPPORTED, CheckRow  # CheckRow re-exported: aa.crosscheck.CheckRow
from .errors import UnsupportedModelError
from .loading import load
from .robot import Robot

#: providers run on every robot, ``rows(robot, samples, rng)``: dotted name -> what it checks
ROBOT_PROVIDERS: dict[str, str] = {
    "anthroarm.kinematics.checks:rows": "kinematics",
    "anthroarm.kinematics.checks:error_rows": "error propagation (6-118)",
    "anthroarm.dynamics.checks:model_rows": "dyn Lagrange equations",
    "anthroarm.crosscheck:ik_rows": "aa.ik.solve round trip",
    "anthroarm.ik.geometric:check_rows": "closed form by geometry (IK-Geo class)",
    "anthroarm.collision.checks:rows": "collision distances = coal, damper never violated",
}

#: providers of the book's rows, ``rows(catalog_names, samples, rng)``, run in this order
PROVIDERS: list[str] = [
    "anthroarm.design.structure:reach_rows",
    "anthroarm.spatial.checks:rows",
    "anthroarm.mechanisms.checks:rows",
    "anthroarm.ik.checks:rows",
    "anthroarm.ik.qp.checks:rows",
]


ERROR = "error"


def _load_provider(dotted: str):
    mod, _, fn = dotted.partition(":")
    return getattr(importlib.import_module(mod), fn)


def load_robots(models=None, tool: str | None = None, locked=None) -> list:
    """The robots of a check: ``models`` entries are catalog names, example-robot-data names,
    URDF paths or Robots (default: the catalog); ``tool=``/``locked=`` go to
    :func:`anthroarm.load` for every entry given by name or path."""
    entries = list(models) if models else catalog.names()
    kw = {k: v for k, v in (("tool", tool), ("locked", locked)) if v is not None}
    return [e if isinstance(e, Robot) else load(e, **kw) for e in entries]


def run(
    models=None,
    samples: int = 200,
    seed: int = 0,
    providers=None,
    progress: bool = False,
    tool: str | None = None,
    locked=None,
    workers: int = 1,
) -> list[CheckRow]:
    """Run the checks (see the module docstring) and return the rows.

    ``models``: names, URDF paths or Robots (default: the whole catalog); ``providers``: dotted
    names to run instead of all (robot providers are those in :data:`ROBOT_PROVIDERS`);
    ``tool``/``locked``: passed to :func:`anthroarm.load` for every named model.  ``workers``
    > 1 runs the checks in that many processes (each loads the models it checks by name; the
    rows come back in the same order and with the same values as one process gives, each check
    drawing from its own ``default_rng(seed)``); models given as Robots run in this process."""
    robots = load_robots(models, tool, locked)
    if not models:
        names = catalog.names()
    elif tool is None and locked is None:  # the book rows are about the catalog models as they are
        names = [str(m) for m in models if isinstance(m, (str, Path)) and str(m) in catalog.names()]
    else:
        names = []
    provs = list(providers) if providers is not None else [*ROBOT_PROVIDERS, *PROVIDERS]
    entries = list(models) if models else catalog.names()
    # the book's checks first: the longest single jobs, so that the pool's tail is short
    jobs = [(p, None) for p in provs if p not in ROBOT_PROVIDERS]
    jobs += [(p, k) for p in provs if p in ROBOT_PROVIDERS for k in range(len(robots))]
    by_name = all(isinstance(e, (str, Path)) for e in entries)
    if workers > 1 and by_name and len(jobs) > 1:
        args = [(p, None if k is None else str(entries[k]), names, samples, seed, tool, locked)
                for p, k in jobs]  # fmt: skip
        out = _in_processes(args, workers, progress)
    else:
        it = tqdm(jobs, desc="cross-check", unit="check", leave=False) if progress else jobs
        out = [_job(p, None if k is None else robots[k], names, samples, seed) for p, k in it]
    order = sorted(range(len(jobs)), key=lambda i: _original_order(jobs[i], provs))
    return [row for i in order for row in out[i]]


def _original_order(job, provs) -> tuple:
    """Where a job's rows go: every robot provider over the robots, then the book's checks."""
    p, k = job
    return (0, provs.index(p), k) if k is not None else (1, provs.index(p), 0)


def _job(dotted: str, robot, names, samples: int, seed: int) -> list[CheckRow]:
    """The rows of one provider (on ``robot``, or the book's on the catalog ``names``); a
    provider that cannot apply to the robot gives an unsupported row, one that crashes a
    failed row (a traceback would hide every other row)."""
    rng = np.random.default_rng(seed)
    if robot is None:
        return list(_load_provider(dotted)(names, samples, rng))
    try:
        return list(_load_provider(dotted)(robot, samples, rng))
    except UnsupportedModelError as exc:
        return [CheckRow.unsupported(robot.name, ROBOT_PROVIDERS[dotted], str(exc))]
    except Exception as exc:  # noqa: BLE001 - a check that crashes on a user's robot is a failed row, not a traceback
        return [
            CheckRow(
                robot.name,
                ROBOT_PROVIDERS[dotted],
                math.nan,
                0.0,
                0,
                "-",
                f"{ERROR}: {type(exc).__name__}: {' '.join(str(exc).split())}",
            )
        ]


def _job_by_name(args) -> list[CheckRow]:
    """:func:`_job` in a worker process: the robot loaded there by its name or path."""
    dotted, entry, names, samples, seed, tool, locked = args
    robot = None if entry is None else load_robots([entry], tool, locked)[0]
    return _job(dotted, robot, names, samples, seed)


def _in_processes(args, workers: int, progress: bool) -> list:
    """:func:`_job_by_name` of each item of ``args`` in ``workers`` fresh processes (spawned:
    nothing of this process's state is copied), results in the order of ``args``."""
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futures = [pool.submit(_job_by_name, a) for a in args]
        if progress:
            for _ in tqdm(as_completed(futures), total=len(futures), desc="cross-check",
                          unit="check", leave=False):  # fmt: skip
                pass
        return [f.result() for f in futures]


def ik_rows(robot, samples: int, rng) -> list[CheckRow]:
    """``aa.ik.solve`` round trip on any robot: random configurations inside the limits →
    Pinocchio FK of the tool → solve → Pinocchio FK of the answer.  The row reports the largest
    position (m) or rotation (rad) error; a failure or an answer outside the limits counts as
    an infinite error."""
    n = max(3, min(int(samples), 20))
    model, data, fid = robot.model, robot.model.createData(), robot.tool_id
    worst, solved = 0.0, 0
    for q in robot.random_q(n, rng):
        pin.framesForwardKinematics(model, data, q)
        T = data.oMf[fid].homogeneous.copy()
        res = ik.solve(robot, T, max_time=1.0)  # correctness, not speed (the benchmarks time it): a
        # first call also builds the robot's seed table
        if not (res.success and robot.within_limits(res.q)):
            worst = math.inf
            continue
        solved += 1
        pin.framesForwardKinematics(model, data, res.q)
        M = data.oMf[fid]
        worst = max(
            worst,
            float(np.linalg.norm(M.translation - T[:3, 3])),
            float(np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3]))),
        )
    return [
        CheckRow(
            robot.name,
            "aa.ik.solve: FK(solve(T)) = T within limits",
            worst,
            1e-6,
            n,
            "pinocchio FK",
            f"{solved}/{n} solved; pos (m) / rot (rad), worst of both",
        )
    ]


def format_table(rows: list[CheckRow]) -> str:
    """Plain-text table: model, quantity, max abs err, tol, samples, oracle, status; then the
    reasons of unsupported rows and a summary line."""
    head = ("model", "quantity", "max_abs_err", "tol", "samples", "oracle", "ok")
    body = [
        (
            r.model,
            r.quantity,
            f"{r.max_abs_err:.3e}",
            f"{r.tol:.0e}",
            str(r.samples),
            r.oracle,
            r.status,
        )
        for r in rows
    ]
    widths = [
        max(len(h), *(len(b[i]) for b in body)) if body else len(h) for i, h in enumerate(head)
    ]
    fmt = "  ".join(f"{{:<{w}}}" for w in widths)
    lines = [fmt.format(*head).rstrip(), fmt.format(*("-" * w for w in widths))]
    lines += [fmt.format(*b).rstrip() for b in body]
    unsupported = [r for r in rows if r.status == UNSUPPORTED]
    for r in rows:
        if r.note.startswith((UNSUPPORTED + ":", ERROR + ":")):
            lines.append(f"{r.model}: {r.quantity}: {r.note}")
    n_ok = sum(r.ok for r in rows)
    lines.append(
        f"{n_ok} passed, {len(rows) - n_ok - len(unsupported)} failed, {len(unsupported)} "
        "unsupported"
    )
    return "\n".join(lines)


def to_json(rows: list[CheckRow]) -> str:
    return json.dumps([r.as_dict() for r in rows], indent=1)
