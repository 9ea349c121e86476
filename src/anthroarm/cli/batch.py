"""``anthroarm batch``: batch jobs, locally or on a Dask cluster (parser; the run:
:mod:`.batch_run`)."""

from __future__ import annotations

from .common import add_json, add_model_argument, add_out


def add_parser(sub):
    p = sub.add_parser(
        "batch",
        help="batch jobs, locally or on a Dask cluster (reach, comfort, population, tolerance, ik, cells)",
        description="Run a batch job of anthroarm.batch in this process (default), on a LocalCluster "
        "(--scheduler local --workers N) or on a running Dask scheduler (--scheduler tcp://HOST:8786); "
        "the same numbers either way. The result is written atomically when the job has finished. "
        "A JSON summary is printed (with or without --json).",
        epilog="example: anthroarm batch reach human_arm7 --height 1.62 --n 1000000 "
        "--scheduler local --workers 2 -o reach.npz --plot reach.png",
    )
    p.add_argument("job", choices=["reach", "comfort", "population", "tolerance", "ik", "cells"])
    add_model_argument(p, optional=True)
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS|local",
        help="Dask scheduler address, or 'local' for a LocalCluster (default: this process)",
    )
    p.add_argument(
        "--workers", type=int, default=None, help="worker processes of --scheduler local"
    )
    p.add_argument(
        "--timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)"
    )
    p.add_argument(
        "--n",
        type=int,
        default=None,
        help="configurations (reach, comfort, population: per person), samples (tolerance), targets (ik)",
    )
    p.add_argument("--voxel", type=float, default=0.02, help="voxel side, m (default 0.02)")
    p.add_argument(
        "--chunk-size", type=int, default=None, help="work items per task (default: the job's)"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--heights",
        default="1.55,1.65,1.75,1.85",
        help="population: body heights, m (0.5–2.6; comma-separated)",
    )
    p.add_argument(
        "--masses", default="60,75", help="population: body masses, kg (10–300; comma-separated)"
    )
    p.add_argument("--sexes", default="female,male", help="population: sexes, male and/or female")
    p.add_argument(
        "--configs", type=int, default=10, help="tolerance: random configurations (default 10)"
    )
    p.add_argument(
        "--sigma-q", type=float, default=1e-3, help="tolerance: joint error, rad (default 1e-3)"
    )
    p.add_argument(
        "--sigma-l", type=float, default=1e-4, help="tolerance: link length error, m (default 1e-4)"
    )
    p.add_argument("--D", type=float, default=0.05, help="cells: lattice spacing, m (default 0.05)")
    add_out(p, metavar="FILE.npz", help="write the result here (atomically)")
    p.add_argument(
        "--plot",
        default=None,
        metavar="FILE.png",
        help="reach/comfort: a slice; population: volumes",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_json(p, "print the summary as JSON (the default: it is always JSON)")
    p.set_defaults(run="batch_run.run", model_params=True)
