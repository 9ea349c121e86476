"""Row-parallel execution of compiled kernels on the cores of this machine.

A compiled kernel (:mod:`anthroarm.jit`) releases the GIL, so the rows of a large batch can be
split across threads of one process.  :func:`run_rows` cuts ``N`` rows into one contiguous
slice per worker and calls ``fn(start, stop)`` for each, in a thread pool shared by the
process (created on first use; it holds no references to robots or results).

How many threads: ``$ANTHROARM_THREADS`` if set (1 switches it off), else the number of CPUs
this process may use (``os.sched_getaffinity``; ``os.cpu_count()`` elsewhere).  Batches below
:data:`MIN_ROWS_PER_THREAD` rows per thread run in the calling thread (the hand-off costs
~20 µs).  Thread-safe: the pool is created under a lock; each call waits for its own slices.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

#: fewer rows than this per thread: no threads
MIN_ROWS_PER_THREAD = 2048
ENV = "ANTHROARM_THREADS"
_LOCK = threading.Lock()
_POOL: dict = {}  # "pool": the ThreadPoolExecutor, "size": its max_workers


def workers() -> int:
    """The number of threads a large batch is split across (see the module docstring)."""
    env = os.environ.get(ENV, "").strip()
    if env:
        try:
            return max(1, int(env))
        except ValueError:
            raise ValueError(f"${ENV} must be a whole number of threads, got {env!r}") from None
    return cpus()


def cpus() -> int:
    """The CPUs this process may use (``os.sched_getaffinity``; ``os.cpu_count()`` elsewhere)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _pool(n: int) -> ThreadPoolExecutor:
    with _LOCK:
        pool = _POOL.get("pool")
        if pool is None or _POOL["size"] < n:  # grow when $ANTHROARM_THREADS rises
            if pool is not None:
                pool.shutdown(wait=False)
            pool = _POOL["pool"] = ThreadPoolExecutor(max_workers=n, thread_name_prefix="anthroarm")
            _POOL["size"] = n
        return pool


def run_rows(fn, n_rows: int) -> None:
    """Call ``fn(start, stop)`` on contiguous slices covering ``range(n_rows)``, in parallel
    threads when the batch is large enough; exceptions propagate (the first one raised)."""
    k = n_rows // MIN_ROWS_PER_THREAD
    if k > 1:  # a large batch: ask how many threads
        k = min(workers(), k)
    if k <= 1:
        fn(0, n_rows)
        return
    edges = [round(i * n_rows / k) for i in range(k + 1)]
    futures = [_pool(k).submit(fn, a, b) for a, b in zip(edges[:-1], edges[1:])]
    for f in futures:
        f.result()


__all__ = ["ENV", "MIN_ROWS_PER_THREAD", "run_rows", "workers"]
