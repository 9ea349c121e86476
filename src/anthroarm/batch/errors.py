"""Typed errors of :mod:`anthroarm.batch`, each with the remedy in its message.

They take one message argument only, so that Dask can pickle them back from a worker."""

from __future__ import annotations

from ..errors import AnthroarmError


class BatchError(AnthroarmError):
    """Base class of the batch jobs' errors."""


class SchedulerUnreachableError(BatchError, ConnectionError):
    """The Dask scheduler address did not answer within the timeout."""


class RobotDescriptionError(BatchError, ValueError):
    """The robot cannot be described in a form a worker can rebuild (e.g. a robot made from an
    in-memory ``pin.Model`` with no URDF text and no catalog name)."""


class RobotRebuildError(BatchError):
    """A worker could not rebuild the robot from its description, or rebuilt a different one
    (its kinematic hash :meth:`anthroarm.chain.Chain.key` differs)."""


class JobTooLargeError(BatchError, MemoryError):
    """The job's *output* would not fit the memory budget (inputs are always chunked)."""


class BatchParameterError(BatchError, ValueError):
    """A job parameter that cannot be used (a voxel that is not a positive length or whose grid
    overflows, a count that is not a positive integer, an output path with the wrong suffix).
    The message names the parameter, its value and the remedy."""


class BatchResultError(BatchError, ValueError):
    """A batch result file (``.npz``) that cannot be loaded: not a regular file, beyond the size
    bound, not a zip, a damaged entry, metadata that is not the format's JSON, object arrays
    (never unpickled), or arrays whose shape does not match their dimensions' coordinates.
    ``path`` names the file (``None`` when the error came back through Dask), ``problem`` says
    what is wrong."""

    def __init__(self, problem: str, path=None):
        self.path = None if path is None else str(path)
        self.problem = problem
        super().__init__(problem if path is None else f"{self.path}: {problem}")
