"""Running a job's tasks locally or on a Dask cluster, with one calling convention.

A job is a list of *tasks* ``(function, robot description, payload)``: ``function(robot,
payload)`` is a module-level function (importable on every worker) that returns a small
partial result.  :func:`run` executes them

* locally (``client=None``): in order, in this process, with a tqdm progress bar;
* on Dask (``client`` a :class:`distributed.Client`): submitted with explicit keys, at most
  :func:`window` tasks in flight (the client never holds more than that many partial results),
  gathered as they complete; the robot is rebuilt on each worker from its description and
  cached there (:func:`anthroarm.batch.describe.robot_from`).

Partial results are handed to the job's ``consume(index, part)`` as they arrive; every job
combines them either with an order-independent reduction (integer counts, min, max) or by
storing them under their task index and combining in index order at the end, so the result is
the same bit for bit whatever the number of workers or the order of completion.  Random jobs
draw from one :class:`numpy.random.SeedSequence` child per task (:func:`chunk_seeds`), and the
task boundaries depend only on the job's size and ``chunk_size``, never on the cluster.

A worker that dies mid-job loses its running tasks; the scheduler re-runs them elsewhere
(tasks are pure), and each task index is consumed exactly once.  An exception in a task, in
``consume`` or in the caller's ``callback`` (a ``KeyboardInterrupt`` too) cancels every
pending task before it propagates; the jobs write no file, and the CLI writes its output only
after the job returns (atomically), so a cancelled job leaves no partial file.
"""

from __future__ import annotations

import ctypes
import itertools
import uuid

import numpy as np
from tqdm.auto import tqdm

from .describe import robot_from
from .errors import SchedulerUnreachableError

#: seconds a connection to a scheduler may take before SchedulerUnreachableError
CONNECT_TIMEOUT = 10.0


#: Dask settings of the workers of a local cluster: no statistical profiler (it samples every
#: thread's stack every 10 ms under the GIL; a reachability task ran 12 % slower with it).  A
#: cluster you start yourself keeps its own settings (docs/batch.md says how to set this one).
LOCAL_WORKER_CONFIG = {"distributed.worker.profile.enabled": False}


def connect(
    scheduler="local",
    workers: int | None = None,
    timeout: float = CONNECT_TIMEOUT,
    threads_per_worker: int = 1,
):
    """A :class:`distributed.Client`: ``"local"`` starts a ``LocalCluster`` of ``workers``
    processes (default: one per core) with ``threads_per_worker`` threads each; anything else is
    a scheduler address (``tcp://host:8786``).  The caller closes it (``with connect(...) as c``;
    a local cluster closes with its client).

    An address that does not answer within ``timeout`` seconds raises
    :class:`~anthroarm.batch.errors.SchedulerUnreachableError` naming the address and the remedy."""
    from dask import config as dask_config
    from distributed import Client

    if scheduler in (None, "local"):  # the client owns the cluster: closing it stops the workers
        with dask_config.set(LOCAL_WORKER_CONFIG):
            return Client(
                n_workers=workers,
                threads_per_worker=threads_per_worker,
                processes=True,
                dashboard_address=":0",
                set_as_default=False,
            )
    try:
        return Client(scheduler, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise SchedulerUnreachableError(
            f"no Dask scheduler answered at {scheduler!r} within {timeout:g} s "
            f"({type(exc).__name__}: {exc}). Remedy: start one (`dask scheduler`, or your "
            "dask-jobqueue / dask-kubernetes cluster) and pass its address as tcp://HOST:PORT, or "
            "run locally with --scheduler local"
        ) from None


def close(client) -> None:
    """Close a client from :func:`connect` (and the local cluster it started)."""
    client.close()


def chunk_seeds(seed, n: int) -> list[np.random.SeedSequence]:
    """``n`` independent child seeds of ``seed`` (an int, a SeedSequence or None = 0), one per
    task: task ``i`` draws from ``chunk_seeds(seed, n)[i]`` wherever it runs."""
    ss = (
        seed
        if isinstance(seed, np.random.SeedSequence)
        else np.random.SeedSequence(0 if seed is None else seed)
    )
    return ss.spawn(n)


def iter_seeds(seed, n: int):
    """The children of :func:`chunk_seeds` one at a time (the same seeds, in the same order;
    a SeedSequence given is advanced as ``spawn(n)`` advances it), spawned in blocks of
    :data:`SEED_BLOCK` as they are consumed: a job of 10**6 tasks never holds 10**6 seeds."""
    ss = (
        seed
        if isinstance(seed, np.random.SeedSequence)
        else np.random.SeedSequence(0 if seed is None else seed)
    )
    for a in range(0, n, SEED_BLOCK):
        yield from ss.spawn(min(SEED_BLOCK, n - a))


#: seeds spawned at a time by :func:`iter_seeds`
SEED_BLOCK = 1024


def chunks(n: int, size: int) -> list[tuple[int, int]]:
    """``[(start, stop), ...]`` covering ``range(n)`` in pieces of ``size`` (the last shorter)."""
    return list(iter_chunks(n, size))


def iter_chunks(n: int, size: int):
    """The pieces of :func:`chunks`, one at a time (no list of 10**6 pairs for a long job)."""
    size = int(size)
    if size <= 0:
        raise ValueError(f"chunk_size must be a positive integer, got {size}")
    return ((a, min(a + size, n)) for a in range(0, n, size))


def n_chunks(n: int, size: int) -> int:
    """``len(chunks(n, size))`` without making the list."""
    return -(-int(n) // int(size))


class Tasks:
    """A job's tasks, made lazily: ``len(tasks)`` is known up front, and iterating calls
    ``make()`` for a fresh generator of ``(fn, description, payload)``.  :func:`run` keeps at
    most :func:`window` of them alive on Dask (one locally), so the memory of a job does not
    grow with its number of tasks (``n = 10**12`` configurations are ~10**6 tasks)."""

    def __init__(self, n: int, make):
        self.n = int(n)
        self._make = make

    def __len__(self) -> int:
        return self.n

    def __iter__(self):
        return iter(self._make())


def window(client) -> int:
    """Tasks kept in flight on ``client``: 4 per worker thread (at least 8)."""
    try:
        threads = sum(client.nthreads().values())
    except Exception:
        threads = 2
    return max(8, 4 * threads)


#: glibc's M_TRIM_THRESHOLD set on a worker (bytes), see :func:`_relax_malloc_trim`
WORKER_TRIM_THRESHOLD = 64 << 20
#: glibc's M_MMAP_THRESHOLD set on a worker (bytes), see :func:`_relax_malloc_trim`
WORKER_MMAP_THRESHOLD = 32 << 20
_trim_relaxed = [False]


def _relax_malloc_trim() -> None:
    """Once per worker process: raise glibc's malloc trim threshold to
    :data:`WORKER_TRIM_THRESHOLD`.  Dask's nanny starts workers with
    ``MALLOC_TRIM_THRESHOLD_=65536`` so that they hand freed memory back to the OS at once; with
    the megabyte-sized temporaries of the batched FK that makes every free a trim and every
    allocation fresh page faults: a reachability task ran 1.4-1.5x slower on a worker than in the
    client's process.  64 MiB keeps the worker's footprint bounded while its arrays are reused.
    A no-op where glibc's ``mallopt`` is not available."""
    if _trim_relaxed[0]:
        return
    _trim_relaxed[0] = True
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-1, WORKER_TRIM_THRESHOLD)  # M_TRIM_THRESHOLD = -1
        # the nanny's environment variable also freezes the mmap threshold at 128 KiB (glibc
        # raises it after the first large free otherwise): every temporary of the batched FK
        # was a fresh mmap, 20 000 page faults per task; 32 MiB (glibc's own dynamic maximum
        # on 64-bit) serves them from the heap, as in the client's process
        libc.mallopt(-3, WORKER_MMAP_THRESHOLD)  # M_MMAP_THRESHOLD = -3
    except (OSError, AttributeError):
        pass


def _execute(fn, desc, payload):
    """One task: the cached robot, then ``fn``."""
    return fn(robot_from(desc) if desc is not None else None, payload)


def _execute_on_worker(fn, desc, payload):
    """Worker side of one task (:func:`_relax_malloc_trim`, then :func:`_execute`)."""
    _relax_malloc_trim()
    return _execute(fn, desc, payload)


def run(
    tasks, consume, *, client=None, progress: bool = True, desc: str = "batch", callback=None
) -> int:
    """Run ``tasks`` (a sequence of ``(fn, robot_description, payload)``, or :class:`Tasks`
    made as they are submitted) and hand each result to ``consume(index, part)``; returns the
    number of tasks.

    ``callback(done, total)`` is called after each task (raise to cancel);
    ``progress`` shows a tqdm bar."""
    if not isinstance(tasks, Tasks):
        tasks = list(tasks)
    total = len(tasks)
    bar = None
    if progress:
        bar = tqdm(total=total, desc=desc, unit="task", leave=False)
    try:
        if client is None:
            for i, (fn, d, payload) in enumerate(tasks):
                consume(i, _execute(fn, d, payload))
                if bar is not None:
                    bar.update(1)
                if callback is not None:
                    callback(i + 1, total)
        else:
            _run_dask(client, tasks, consume, bar, callback, desc)
    finally:
        if bar is not None:
            bar.close()
    return total


def _run_dask(client, tasks, consume, bar, callback, desc):
    from distributed import as_completed

    token = uuid.uuid4().hex[:12]
    index = {}
    todo = iter(enumerate(tasks))

    def submit(i, task):
        fn, d, payload = task
        f = client.submit(
            _execute_on_worker, fn, d, payload, key=f"anthroarm-{desc}-{token}-{i}", pure=False
        )
        index[f.key] = i
        return f

    live = {}
    for i, t in itertools.islice(todo, window(client)):
        f = submit(i, t)
        live[f.key] = f
    ac = as_completed(list(live.values()), loop=client.loop)
    done = 0
    seen = set()
    try:
        for f in ac:
            i = index[f.key]
            part = f.result()  # re-raises a task's exception with its own type
            live.pop(f.key, None)
            f.release()
            if i in seen:  # never happens with explicit keys; guard all the same
                continue
            seen.add(i)
            consume(i, part)
            done += 1
            if bar is not None:
                bar.update(1)
            if callback is not None:
                callback(done, len(tasks))
            nxt = next(todo, None)
            if nxt is not None:
                g = submit(*nxt)
                live[g.key] = g
                ac.add(g)
    except BaseException:
        client.cancel(list(live.values()))
        raise
    if done != len(tasks):  # pragma: no cover - as_completed yields each future once
        raise RuntimeError(f"{desc}: {done} of {len(tasks)} tasks came back")
