"""Compiled scalar kernels: the Python source of a kernel, compiled by Numba.

A kernel written here once (plain Python on floats, tuples and small numpy arrays) is the one
source of its formula: Numba compiles *that* source to machine code on first use
(https://numba.readthedocs.io, ``numba.njit``), and :attr:`py_func` of the compiled object is
the same function run by the Python interpreter (what the tests compare against where they
want the interpreter's answer).  There is no second copy to keep in step.

Disk cache: Numba keeps the compiled code of every kernel (``cache=True``) in the subfolder
``numba`` of anthroarm's cache (:func:`anthroarm.cache.root`; ``$ANTHROARM_CACHE`` moves it),
unless ``$NUMBA_CACHE_DIR`` is already set or Numba was imported before anthroarm.  Numba
keys each entry by the source file's path, modification time and size, the function's
signature, the target CPU and its own version, and recompiles when any of them changes; the
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

import numba  # noqa: E402

OPTIONS = dict(cache=True, nogil=True, error_model="numpy")


def kernel(func):
    """Compile ``func`` with Numba (:data:`OPTIONS`); the result is called like ``func``."""
    return numba.njit(**OPTIONS)(func)


__all__ = ["CACHE_SUBFOLDER", "OPTIONS", "kernel"]
