"""The limits of the batch jobs, each a documented constant: the memory budget of a job's
outputs, the voxel sizes a grid accepts, and the checks of the counts.  A job whose *inputs*
grow (``n = 10**12`` configurations) is not refused: its tasks are made as they are submitted
(:class:`~anthroarm.batch.engine.Tasks`), so its memory is the window of tasks in flight plus
its outputs; only outputs beyond :data:`MEMORY_BUDGET` are refused."""

from __future__ import annotations

import math

import numpy as np

from .errors import BatchParameterError, JobTooLargeError

#: bytes the *outputs* of one job may take (inputs are streamed in chunks)
MEMORY_BUDGET = 4 * 2**30


def _check_memory(nbytes: float, what: str, remedy: str) -> None:
    if nbytes > MEMORY_BUDGET:
        raise JobTooLargeError(
            f"{what} would take {nbytes / 2**30:.1f} GiB (budget {MEMORY_BUDGET / 2**30:.0f} GiB, "
            f"anthroarm.batch.limits.MEMORY_BUDGET). Remedy: {remedy}"
        )


def _positive_int(x, name):
    if not (isinstance(x, (int, np.integer)) and not isinstance(x, bool) and x > 0):
        raise BatchParameterError(f"{name} must be a positive integer, got {x!r}")
    return int(x)


#: the largest voxel side accepted, m (a larger one is no workspace voxel; the bound keeps every
#: grid corner and coordinate finite)
MAX_VOXEL = 1e3
#: voxels along one axis of a grid at most (checked before the grid's size is computed, so a
#: subnormal voxel is refused rather than overflowing)
MAX_VOXELS_PER_AXIS = 1 << 20


def _voxel(voxel) -> float:
    """``voxel`` (m) as a float in (0, :data:`MAX_VOXEL`], else BatchParameterError."""
    try:
        v = float(voxel)
    except (TypeError, ValueError, OverflowError):
        raise BatchParameterError(f"voxel must be a length in m, got {voxel!r}") from None
    if not (math.isfinite(v) and 0 < v <= MAX_VOXEL):
        raise BatchParameterError(
            f"voxel must be a positive length in m, at most {MAX_VOXEL:g}, got {voxel!r}"
        )
    return v


def _voxels_per_side(extent: float, voxel: float) -> int:
    """ceil(extent / voxel), refused (JobTooLargeError) beyond :data:`MAX_VOXELS_PER_AXIS`."""
    m = extent / voxel
    if not m <= MAX_VOXELS_PER_AXIS:
        raise JobTooLargeError(
            f"a voxel of {voxel:g} m puts {m:.3g} voxels across {extent:g} m, more than "
            f"{MAX_VOXELS_PER_AXIS} per axis. Remedy: use a coarser voxel (voxel= in m)"
        )
    return int(math.ceil(m))
