"""The edge of the batch jobs: connect, run, write the result file and the plot (atomically,
only once the job has finished), close what was started.  ``anthroarm batch`` calls
:func:`run_job`; so can a script."""

from __future__ import annotations

import io
from pathlib import Path

from .._io import atomic_write_text
from . import engine
from .errors import BatchParameterError
from .jobs import (
    cell_table,
    comfort_map,
    ik_dataset,
    population_reach,
    reachability_map,
    tolerance_monte_carlo,
)
from .plot import population_plot, slice_plot
from .result import check_suffix

JOBS = {
    "reach": reachability_map,
    "comfort": comfort_map,
    "population": population_reach,
    "tolerance": tolerance_monte_carlo,
    "ik": ik_dataset,
    "cells": cell_table,
}


def run_job(
    job: str,
    *args,
    out=None,
    plot=None,
    scheduler=None,
    workers: int | None = None,
    client=None,
    timeout: float = engine.CONNECT_TIMEOUT,
    **kwargs,
):
    """Run ``JOBS[job](*args, client=..., **kwargs)`` and return its
    :class:`~anthroarm.batch.result.BatchResult`.

    ``scheduler``: None (in this process), ``"local"`` (a LocalCluster of ``workers`` processes,
    closed afterwards) or an address; or pass an open ``client``.  ``out``: a ``.npz`` path written
    atomically after the job finished (a job that fails or is interrupted — KeyboardInterrupt —
    writes nothing); ``plot``: a PNG of a slice (maps) or of the volumes (population)."""
    if job not in JOBS:
        raise BatchParameterError(f"unknown batch job {job!r}; choose one of {', '.join(JOBS)}")
    if out is not None:  # before the job runs: an hour's result is not lost to a wrong suffix
        check_suffix(out)
    if plot is not None and Path(plot).suffix.lower() != ".png":
        raise BatchParameterError(
            f"{plot}: the plot is a PNG image; give a name ending in .png, e.g. "
            f"{Path(plot).with_suffix('.png').name}"
        )
    for path in (out, plot):
        if path is not None and not Path(path).parent.is_dir():
            raise FileNotFoundError(
                f"folder {Path(path).parent} does not exist (cannot write {Path(path).name})"
            )
    own = None
    if client is None and scheduler is not None:
        client = own = engine.connect(scheduler, workers=workers, timeout=timeout)
    try:
        result = JOBS[job](*args, client=client, **kwargs)
    finally:
        if own is not None:
            engine.close(own)
    if out is not None:
        result.save(out)
    if plot is not None:
        _save_plot(result, plot)
    return result


def _save_plot(result, path) -> None:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    if result.job in ("reachability_map", "comfort_map"):
        fig = slice_plot(result, axis="x")
    elif result.job == "population_reach":
        fig = population_plot(result)
    else:
        raise ValueError(
            f"no plot for {result.job}: --plot applies to reach, comfort and population"
        )
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    atomic_write_text(Path(path), buf.getvalue())
