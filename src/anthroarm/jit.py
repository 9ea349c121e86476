"""Compiled scalar kernels: the Python source of a kernel, compiled by Numba.

A kernel written here once (plain Python on floats, tuples and small numpy arrays) is the one
source of its formula: Numba compiles *that* source to machine code on first use
(https://numba.readthedocs.io, ``numba.njit``), and ``py_func`` of the compiled object is
the same function run by the Python interpreter (what the tests compare against where they
want the interpreter's answer).  There is no second copy to keep in step.

Disk cache: the compiled code of every kernel is kept by Numba's per-function cache in the
subfolder ``numba`` of anthroarm's cache (:func:`anthroarm.cache.root`; ``$ANTHROARM_CACHE``
moves it), unless ``$NUMBA_CACHE_DIR`` is already set or Numba was imported before anthroarm.
Numba keys each entry by the source file's path, modification time and size, the function's
bytecode and signature, the target CPU and its own version, and recompiles when any of them
changes.  A compiled kernel also holds the code of the kernels it calls, which may live in other
modules (the class solvers call the subproblems of :mod:`anthroarm.ik.subproblems`), and Numba
does not look at those; so the stamp of every entry here also holds the SHA-256 of the sources
of all the kernel modules of its package (:func:`kernel_sources_digest`): an edited subproblem
recompiles its callers instead of leaving them with the old code.  Like every entry of anthroarm's cache, each data file is *verified before it is
loaded*: it is written atomically with the SHA-256 of its contents in front
(:class:`VerifiedCacheFile`), and a file that does not match (truncated, edited, half-copied) or
an index that cannot be read is dropped and the kernel compiled again — never loaded.  The
first call of a kernel in a fresh cache compiles it (about a second per kernel family), later
processes load it in milliseconds.  ``anthroarm cache clear`` empties it.

Kernels are compiled with ``nogil=True`` (threads run them in parallel; they hold no state) and
``error_model="numpy"`` (a division by zero gives inf/NaN as in numpy, checked by the kernel,
instead of raising).
"""

from __future__ import annotations

import os

from . import cache as _cache

#: the cache subfolder of the compiled kernels
CACHE_SUBFOLDER = "numba"

if "NUMBA_CACHE_DIR" not in os.environ and "numba" not in __import__("sys").modules:
    os.environ["NUMBA_CACHE_DIR"] = str(_cache.root() / CACHE_SUBFOLDER)

import functools  # noqa: E402
import hashlib  # noqa: E402
import pickle  # noqa: E402
from pathlib import Path  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402
from numba import types  # noqa: E402
from numba.core import caching, cgutils  # noqa: E402
from numba.core.imputils import impl_ret_borrowed  # noqa: E402
from numba.extending import intrinsic  # noqa: E402
from numba.np.arrayobj import populate_array  # noqa: E402

OPTIONS = dict(nogil=True, error_model="numpy")
_MAGIC = b"anthroarm-sha256\n"


class VerifiedCacheFile(caching.IndexDataCacheFile):
    """Numba's index and data files of one kernel, each data file prefixed by the SHA-256 of
    its payload and checked before it is unpickled; a damaged index reads as empty."""

    def _load_index(self):
        try:
            return super()._load_index()
        except Exception:  # noqa: BLE001 - truncated/edited index: compile again
            return {}

    def _save_data(self, name, data):
        payload = self._dump(data)
        with self._open_for_write(self._data_path(name)) as f:  # temp file + os.replace
            f.write(_MAGIC + hashlib.sha256(payload).digest() + payload)

    def _load_data(self, name):
        path = self._data_path(name)
        with open(path, "rb") as f:
            raw = f.read()
        head = len(_MAGIC) + 32
        if (
            not raw.startswith(_MAGIC)
            or hashlib.sha256(raw[head:]).digest() != raw[len(_MAGIC) : head]
        ):
            try:
                os.remove(path)
            except OSError:
                pass
            return None  # not verified: compiled again, never loaded
        return pickle.loads(raw[head:])


def _package_root(func) -> str:
    """The folder of the top-level package that defines ``func`` (its own folder for a module
    outside a package)."""
    import sys

    mod = sys.modules.get(func.__module__.split(".")[0])
    path = getattr(mod, "__path__", None)
    if path:
        return str(Path(list(path)[0]).resolve())
    return str(Path(func.__code__.co_filename).resolve().parent)


@functools.lru_cache(maxsize=None)
def kernel_sources_digest(root: str) -> str:
    """SHA-256 over the sources of the modules below ``root`` (a package folder) that define
    kernels (their text holds ``@kernel``), with their paths relative to ``root``; read once per
    process and folder."""
    base = Path(root)
    h = hashlib.sha256()
    for p in sorted(base.rglob("*.py")):
        try:
            text = p.read_bytes()
        except OSError:
            continue
        if b"@kernel" in text:
            h.update(str(p.relative_to(base)).encode() + b"\0" + hashlib.sha256(text).digest())
    return h.hexdigest()


class VerifiedCache(caching.FunctionCache):
    """Numba's per-function cache on :class:`VerifiedCacheFile`; an entry that verifies but
    cannot be rebuilt (another build of the same version) is compiled again as well.  The
    source stamp is Numba's (the function's file) and :func:`kernel_sources_digest` (the
    kernels it may call)."""

    def __init__(self, py_func):
        super().__init__(py_func)
        stamp = (
            self._impl.locator.get_source_stamp(),
            kernel_sources_digest(_package_root(py_func)),
        )
        self._cache_file = VerifiedCacheFile(
            cache_path=self._cache_path, filename_base=self._impl.filename_base, source_stamp=stamp
        )

    def load_overload(self, sig, target_context):
        try:
            return super().load_overload(sig, target_context)
        except Exception:  # noqa: BLE001 - any unreadable entry: compile again
            return None


def kernel(func=None, *, counted: bool = True, inline: bool = False):
    """Compile ``func`` with Numba (:data:`OPTIONS`, the verified disk cache); the result is
    called like ``func``, and its ``py_func`` is ``func`` itself.

    ``@kernel(counted=False)`` compiles an entry point without Numba's reference counting
    (``_nrt=False``): every array it or a kernel it calls touches is an argument or a
    :func:`local` array, so no array is allocated on the heap, and the atomic reference counts
    of each view (a large part of a call on small inputs) are not made.  A heap allocation in
    any kernel it calls fails to compile.  Numba keeps one compiled body of a kernel per
    argument types, whichever entry point compiled it first, so a kernel that such an entry
    point calls must not return an array (a view returned uncounted to a counting caller would
    be released once too often): a kernel that returns views is ``inline=True`` (compiled
    into each caller's body, ``numba.njit(inline="always")``)."""

    def wrap(f):
        options = OPTIONS if counted else dict(OPTIONS, _nrt=False)
        if inline:
            options = dict(options, inline="always")
        dispatcher = numba.njit(**options)(f)
        dispatcher._cache = VerifiedCache(f)  # numba.njit(cache=True) with our cache file
        return dispatcher

    return wrap if func is None else wrap(func)


def entry_point(dispatcher, *args):
    """The compiled body of kernel ``dispatcher`` for the Numba types of ``args`` (example
    arguments; compiled, or loaded from the disk cache, now if it is not yet), as a function
    called with arguments of exactly those types.  It skips the dispatcher's resolution of the
    argument types on every call (about 40 ns an array argument) — and its checks: an array of
    another dtype, dimension, layout or alignment, or of a size the kernel does not expect, is
    undefined behaviour.  For a hot call whose caller has checked its arguments (the one-pose
    closed-form IK, :func:`anthroarm.ik.closed_form.analytic`)."""
    return dispatcher.compile(tuple(numba.typeof(a) for a in args))


def _local_array(dtype, ndim: int):
    """A Numba intrinsic ``f(*shape)`` (``ndim`` literal sizes) that makes a C-order array of
    ``dtype`` in the calling kernel's stack frame (LLVM ``alloca`` in its entry block: made once
    per call, freed at its return; no heap, no reference count).  Its contents are undefined."""

    def typer(typingctx, *sizes):
        if len(sizes) != ndim or not all(isinstance(n, types.IntegerLiteral) for n in sizes):
            raise numba.errors.RequireLiteralValue(f"a local array takes {ndim} literal sizes")
        shape = [n.literal_value for n in sizes]
        arrty = types.Array(dtype, ndim, "C")

        def codegen(context, builder, sig, args):
            ary = context.make_array(arrty)(context, builder)
            llty = context.get_data_type(dtype)
            size = context.get_abi_sizeof(llty)
            intp = functools.partial(context.get_constant, types.intp)
            strides = [size * int(np.prod(shape[i + 1 :])) for i in range(ndim)]
            populate_array(
                ary,
                data=cgutils.alloca_once(builder, llty, size=int(np.prod(shape))),
                shape=[intp(n) for n in shape],
                strides=[intp(s) for s in strides],
                itemsize=intp(size),
                meminfo=None,
            )
            return ary._getvalue()

        return arrty(*sizes), codegen

    if ndim == 1:
        return intrinsic(lambda typingctx, n: typer(typingctx, n))
    return intrinsic(lambda typingctx, rows, cols: typer(typingctx, rows, cols))


def _view_array(ndim: int):
    """A Numba intrinsic ``f(a, *shape)`` (``ndim`` integer sizes): the first prod(shape) entries
    of the C-order array ``a`` (in memory order) as a C-order array of that shape (same data,
    dtype and owner; :data:`view2`)."""

    def typer(typingctx, arr, sizes):
        if not (isinstance(arr, types.Array) and arr.layout == "C") or not all(
            isinstance(n, types.Integer) for n in sizes
        ):
            raise numba.errors.TypingError(f"a view takes a C-order array and {ndim} integer sizes")
        outty = arr.copy(ndim=ndim, layout="C")

        def codegen(context, builder, sig, args):
            src = context.make_array(sig.args[0])(context, builder, args[0])
            shape = [
                context.cast(builder, v, t, types.intp) for v, t in zip(args[1:], sig.args[1:])
            ]
            strides = [src.itemsize]
            for n in shape[:0:-1]:
                strides.insert(0, builder.mul(strides[0], n))
            out = context.make_array(outty)(context, builder)
            populate_array(
                out,
                data=src.data,
                shape=shape,
                strides=strides,
                itemsize=src.itemsize,
                meminfo=src.meminfo,
                parent=src.parent,
            )
            return impl_ret_borrowed(context, builder, outty, out._getvalue())

        return outty(arr, *sizes), codegen

    if ndim == 2:
        return intrinsic(lambda typingctx, arr, rows, cols: typer(typingctx, arr, (rows, cols)))
    return intrinsic(lambda typingctx, arr, d0, d1, d2: typer(typingctx, arr, (d0, d1, d2)))


#: ``view2(a, rows, cols)`` / ``view3(a, d0, d1, d2)``: ``a.ravel()[:k].reshape(shape)`` of a
#: C-order array ``a`` (:func:`_view_array`) without reshape's run-time layout search (a call
#: of Numba's C helper: the dozen a one-pose IK kernel made on every call took 0.25 µs of its
#: 1.6).  Unchecked: the sizes must fit in ``a``.
view2 = _view_array(2)
view3 = _view_array(3)


#: ``local(n)`` / ``local2(rows, cols)``: float64 scratch arrays of literal sizes in the stack
#: frame of the kernel that makes them (:func:`_local_array`); ``local_flags(n)`` booleans,
#: ``local_ints2(rows, cols)`` int64.  Such an array must not outlive its kernel: it is never
#: returned (copy out its values).
local = _local_array(types.float64, 1)
local2 = _local_array(types.float64, 2)
local_flags = _local_array(types.boolean, 1)
local_ints2 = _local_array(types.int64, 2)


__all__ = [
    "CACHE_SUBFOLDER",
    "OPTIONS",
    "VerifiedCache",
    "VerifiedCacheFile",
    "entry_point",
    "kernel",
    "kernel_sources_digest",
    "local",
    "local2",
    "local_flags",
    "local_ints2",
    "view2",
    "view3",
]
