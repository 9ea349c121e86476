"""Batch jobs that run locally or on a Dask cluster with one calling convention.

>>> import anthroarm as aa
>>> from anthroarm import batch
>>> res = batch.reachability_map("human_arm7", n=10**6, voxel=0.02)          # local, tqdm bar
>>> with batch.connect("local", workers=2) as client:                          # or "tcp://host:8786"
...     same = batch.reachability_map("human_arm7", n=10**6, voxel=0.02, client=client)
>>> res.equals(same)
True
>>> res.save("reach.npz")                                                       # atomic

Jobs: :func:`reachability_map`, :func:`comfort_map`, :func:`population_reach`,
:func:`tolerance_monte_carlo`, :func:`ik_dataset`, :func:`cell_table` (see
:mod:`anthroarm.batch.jobs` for the convention, :mod:`anthroarm.batch.engine` for how tasks
run and why results do not depend on the cluster).  Running on Slurm/PBS/Kubernetes:
``docs/batch.md``.
"""

from .describe import RobotDescription, describe
from .engine import chunk_seeds, close, connect
from .errors import (
    BatchError,
    BatchParameterError,
    BatchResultError,
    JobTooLargeError,
    RobotDescriptionError,
    RobotRebuildError,
    SchedulerUnreachableError,
)
from .jobs import (
    cell_table,
    comfort_map,
    discomfort,
    ik_dataset,
    population_reach,
    reachability_map,
    to_cell_table,
    tolerance_monte_carlo,
    voxel_grid,
)
from .result import BatchResult, load
from .runner import JOBS, run_job

__all__ = [
    "BatchError",
    "BatchParameterError",
    "BatchResultError",
    "BatchResult",
    "JOBS",
    "JobTooLargeError",
    "RobotDescription",
    "RobotDescriptionError",
    "RobotRebuildError",
    "SchedulerUnreachableError",
    "cell_table",
    "chunk_seeds",
    "close",
    "comfort_map",
    "connect",
    "describe",
    "discomfort",
    "ik_dataset",
    "load",
    "population_reach",
    "reachability_map",
    "run_job",
    "to_cell_table",
    "tolerance_monte_carlo",
    "voxel_grid",
]
