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
