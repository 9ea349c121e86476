"""``anthroarm check``: the run (the parser: :mod:`.check`)."""

from __future__ import annotations

import sys

import numpy as np

from .. import crosscheck
from ..muscles import checks as muscle_checks
from ..osim import checks as osim_checks
from ..threads import cpus
from .common import MAX_SAMPLES, UserError, parse_locked
from .runtime import load_model

#: most processes ``--jobs`` may start
MAX_JOBS = 64
#: without ``--jobs``, models given from which the checks run in one process per CPU
PARALLEL_MODELS = 4


def run(a) -> int:
    if not 1 <= a.samples <= MAX_SAMPLES:
        raise UserError(f"--samples must be in 1..{MAX_SAMPLES}, got {a.samples}")
    names = [n for item in [*a.model, *(a.models or [])] for n in item.split(",") if n]
    if (a.tool is not None or a.locked is not None) and not names:
        raise UserError(
            "--tool and --locked apply to the models given: name one (e.g. anthroarm check ur10 --tool tool0)"
        )
    if a.jobs is not None:
        jobs = a.jobs
    else:  # a process takes ~2 s to start: worth it for the catalog or several models
        jobs = cpus() if not names or len(names) >= PARALLEL_MODELS else 1
    if not 1 <= jobs <= MAX_JOBS:
        raise UserError(f"--jobs must be in 1..{MAX_JOBS}, got {a.jobs}")
    osim = [n for n in names if n.lower().endswith(".osim")]  # OpenSim models: their own rows
    rows = (
        []
        if names and len(osim) == len(names)
        else crosscheck.run(
            [n for n in names if n not in osim] or None,
            samples=a.samples,
            seed=a.seed,
            progress=not a.json and sys.stderr.isatty(),
            tool=a.tool,
            locked=parse_locked(a.locked),
            workers=jobs,
        )
    )
    for path in osim:
        rows += osim_rows(path, a)
    print(crosscheck.to_json(rows) if a.json else crosscheck.format_table(rows))
    return 0 if all(r.ok for r in rows) else 1


def osim_rows(path, a) -> list:
    """An OpenSim model: its import report (printed), the osim rows (against Pinocchio, and
    against OpenSim when installed), the muscle rows (:mod:`anthroarm.muscles.checks`) and,
    without coupled coordinates, every robot's rows (those that cannot apply, such as
    yourdfpy's, left out)."""
    robot = load_model(path, tool=a.tool, locked=parse_locked(a.locked))
    if not a.json:
        print(robot.report.text())
    rows = osim_checks.rows(robot, a.samples, np.random.default_rng(a.seed))
    # the muscles' lengths and moment arms (the algorithms layer: not imported by osim.checks)
    rows += muscle_checks.rows(robot, a.samples, np.random.default_rng(a.seed))
    if robot.coupling is None:
        more = crosscheck.run([robot], a.samples, a.seed, list(crosscheck.ROBOT_PROVIDERS))
        rows += [r for r in more if r.status != "unsupported"]
    return rows
