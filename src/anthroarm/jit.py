"""Compiled kernels: one Python source per formula, compiled by Numba off the caller's clock.

A kernel (``@kernel``) is plain Python on floats, tuples and small numpy arrays: the one source
of its formula.  It runs two ways, with the same answers:

- **compiled**: Numba (https://numba.readthedocs.io, ``numba.njit``) compiles that source to
  machine code, kept in Numba's per-function disk cache (the subfolder ``numba`` of anthroarm's
  cache, :func:`anthroarm.cache.root`; ``$ANTHROARM_CACHE`` moves it, unless
  ``$NUMBA_CACHE_DIR`` is set; when Numba was imported before anthroarm, its configuration is
  reloaded with that folder, where the kernels a program decorates with ``cache=True`` after
  importing anthroarm keep their files too);
- **reference**: the same source run by the Python interpreter (:func:`reference`), with
  Numba's float semantics where the interpreter would raise (``error_model="numpy"``: a
  domain error of ``math`` gives NaN, not ``ValueError``), and ``local`` arrays made by
  :func:`numpy.empty`.  About 400 times slower than compiled (~1.3 ms for one pose of a 6R arm),
  but it needs no compilation.

**Who compiles, and when** (``$ANTHROARM_JIT``):

``auto`` (default)
    A kernel called from Python runs compiled once the kernels of this version of the sources
    are compiled in the cache — the *ready stamp* (:func:`ready_name`: the SHA-256 of the kernel
    sources, Numba's and Python's versions and the CPU) with the SHA-256 of every file Numba
    wrote.  Until then it runs its reference while **one background process**
    (``python -m anthroarm.warmup``, started by the first kernel call of any process; a lock
    file keeps it single) compiles every kernel through the public entry points and writes the
    stamp.  Each process watches for the stamp (a daemon thread), verifies the files against it,
    loads the compiled kernels it has used (still on that thread) and switches: no compilation
    and no cache loading on the caller's clock.  A time budget (``aa.ik.solve(max_time=)``)
    therefore never counts compilation.
``compile``
    Numba's own behaviour: a kernel compiles (or loads from the cache) on its first call, in the
    calling thread.  The background process runs in this mode.
``reference``
    Never compile: every kernel runs its reference (a machine where LLVM cannot run, debugging).

**Integrity.**  Numba keys each entry by the source file's path, modification time and size,
the function's bytecode and signature, the target CPU and its own version.  A kernel also holds
the code of the kernels it calls, which Numba does not look at; the ready stamp holds the digest
of all kernel sources (:func:`kernel_sources_digest`), so an edited kernel makes a new stamp and
everything is compiled again.  Numba's files are pickles: before a process uses compiled code it
checks every file in the folder against the SHA-256 the stamp lists; a file that does not match
(truncated, edited, planted, foreign) or is not listed is deleted and the kernels are compiled
again in the background — never loaded.  ``anthroarm cache clear`` empties the folder.

Kernels are compiled with ``nogil=True`` (threads run them in parallel; they hold no state) and
``error_model="numpy"`` (a division by zero gives inf/NaN as in numpy, checked by the kernel,
instead of raising).

**State.**  The registry of kernels and the mode of the process are module-level state by
design (like the disk cache): compiled code is per process.  :data:`STATE` says which mode the
process is in; it changes once, from reference to compiled, under a lock.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
from pathlib import Path

from . import cache as _cache

#: the cache subfolder of the compiled kernels
CACHE_SUBFOLDER = "numba"
#: the cache subfolder of the ready stamps
STAMP_SUBFOLDER = "kernels"


#: a module that builds a :func:`switch` of kernels (its table is compiled into the callers)
_SWITCH = re.compile(rb"\bswitch\(")
#: a relative import: ``from ..search.constants import X`` (dots, module path)
_RELATIVE = re.compile(rb"^from (\.+)([\w.]*) import ([\w, ]*)", re.M)


def kernel_files(root: str) -> list[Path]:
    """The sources compiled into anthroarm's kernels, below ``root`` (a package folder): the
    modules that define kernels (their text holds ``@kernel``) or build a :func:`switch` of
    kernels (a registry whose order is compiled into its callers), ``jit.py`` and
    ``jit_arrays.py`` (the intrinsics), and every module of the package those import from by a
    relative import (the constants a kernel reads as globals are frozen into its code:
    ``search/constants.py``)."""
    return sorted(_kernel_sources(root))


def _kernel_sources(root: str) -> dict[Path, bytes]:
    """:func:`kernel_files` with their texts, each file read once."""
    base = Path(root)
    texts = {}
    for p in sorted(base.rglob("*.py")):
        try:
            texts[p] = p.read_bytes()
        except OSError:
            continue
    picked = set()
    for p, text in texts.items():
        if not (
            b"@kernel" in text or _SWITCH.search(text) or p.name in ("jit.py", "jit_arrays.py")
        ):
            continue
        picked.add(p)
        if p.name in ("jit.py", "jit_arrays.py"):
            continue  # what they import is not compiled into a kernel
        for dots, mod, names in _RELATIVE.findall(text):
            where = p.parent
            for _ in range(len(dots) - 1):
                where = where.parent
            if mod:  # from .x.y import names: the module x/y
                mods = [where.joinpath(*mod.decode().split("."))]
            else:  # from . import a, b: the modules a and b
                mods = [where / n.strip().split(" ")[0] for n in names.decode().split(",")]
            for q in mods:
                picked.update(c for c in (q.with_suffix(".py"), q / "__init__.py") if c in texts)
    return {p: texts[p] for p in picked}


@functools.lru_cache(maxsize=None)
def kernel_sources_digest(root: str) -> str:
    """SHA-256 over the sources compiled into the kernels below ``root`` (:func:`kernel_files`),
    with their paths relative to ``root``; read once per process and folder."""
    base = Path(root)
    h = hashlib.sha256()
    for p, text in sorted(_kernel_sources(root).items()):
        h.update(str(p.relative_to(base)).encode() + b"\0" + hashlib.sha256(text).digest())
    return h.hexdigest()


#: Numba's folder for anthroarm's kernels: one subfolder per digest of the kernel sources.  Numba
#: keys a cached kernel by its own file only, but its code holds the kernels it calls from other
#: modules: an edited subproblem must not leave its callers' old code in the cache, so a new
#: digest starts an empty folder (``anthroarm cache clear`` removes the old ones).
OWN_FOLDER = (
    _cache.root()
    / CACHE_SUBFOLDER
    / kernel_sources_digest(str(Path(__file__).resolve().parent))[:20]
)

_NUMBA_FIRST = "numba" in sys.modules
if "NUMBA_CACHE_DIR" not in os.environ:
    os.environ["NUMBA_CACHE_DIR"] = str(OWN_FOLDER)

import atexit  # noqa: E402
import functools  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402
import types as pytypes  # noqa: E402
import warnings  # noqa: E402

import llvmlite  # noqa: E402
import numba  # noqa: E402
import numpy as np  # noqa: E402
from llvmlite import binding as llvm  # noqa: E402
from numba.extending import overload, typeof_impl  # noqa: E402

from .jit_arrays import PY_FORMS as _PY_FORMS  # noqa: E402
from .jit_arrays import (  # noqa: E402 - the kernels' scratch arrays and views, exported
    borrow,
    local,
    local2,
    local_flags,
    local_ints2,
    part,
    part2,
    view2,
    view3,
)

if _NUMBA_FIRST:  # Numba read its environment before the line above set its cache folder
    numba.config.reload_config()

OPTIONS = dict(nogil=True, error_model="numpy", cache=True)
MODES = _cache.BUILD_MODES
#: seconds between two looks for the ready stamp by a waiting process
POLL = 0.25


def mode() -> str:
    """The mode asked by ``$ANTHROARM_JIT`` (:func:`anthroarm.cache.build_mode`)."""
    return _cache.build_mode()


# --------------------------------------------------------------------------- the reference
def _nan_on_error(f):
    """``f`` of ``math`` returning what Numba's compiled call returns where CPython raises:
    NaN for a domain error, ±inf for an overflow or a pole."""

    @functools.wraps(f)
    def g(*args):
        try:
            return f(*args)
        except ValueError:
            return math.nan
        except (OverflowError, ZeroDivisionError):
            return math.inf

    return g


#: ``math`` as compiled kernels see it (``error_model="numpy"``)
MATH = pytypes.SimpleNamespace(
    **{
        k: (_nan_on_error(v) if callable(v) and not isinstance(v, type) else v)
        for k, v in vars(math).items()
        if not k.startswith("__")
    }
)


def _float_floor(x):
    return math.nan if math.isnan(x) else (math.floor(x) if math.isfinite(x) else x)


MATH.floor = _float_floor
MATH.ceil = lambda x: math.nan if math.isnan(x) else (math.ceil(x) if math.isfinite(x) else x)


@functools.lru_cache(maxsize=None)
def _reference_of(kernel) -> pytypes.FunctionType:
    f = kernel.py_func
    glob: dict = {}
    ref = pytypes.FunctionType(f.__code__, glob, f.__name__, f.__defaults__, f.__closure__)
    ref.__doc__, ref.__qualname__, ref.__module__ = f.__doc__, f.__qualname__, f.__module__
    glob.update(f.__globals__)
    for k, v in f.__globals__.items():
        if v is math:
            glob[k] = MATH
        elif id(v) in _PY_FORMS:
            glob[k] = _PY_FORMS[id(v)]
    names = set(_names(f.__code__))
    for k, v in f.__globals__.items():  # the kernels it calls: their references, called as is
        if k in names and isinstance(v, Kernel) and v is not kernel:
            glob[k] = _reference_of(v)
        elif k in names and getattr(v, "is_switch", False):
            glob[k] = _switch_reference(v)
    glob[f.__name__] = ref if f.__globals__.get(f.__name__) is kernel else glob.get(f.__name__)
    return ref


@functools.lru_cache(maxsize=None)
def _switch_reference(sw) -> pytypes.FunctionType:
    """The reference of a :func:`switch`: the references of its kernels, picked by the index."""
    return _by_index(tuple(_reference_of(k) for k in sw.kernels))


def _by_index(fns: tuple) -> pytypes.FunctionType:
    """``f(i, *args)``: ``fns[i](*args)``, ``fns[-1]`` for an index out of range (the
    ``else`` of a :func:`switch`'s compiled if-chain)."""
    last = len(fns) - 1

    def f(i, *args):
        return fns[i if 0 <= i < last else last](*args)

    return f


def _names(code) -> list[str]:
    """The global names a code object and its nested code objects read."""
    out, todo = [], [code]
    while todo:
        c = todo.pop()
        out.extend(c.co_names)
        todo.extend(x for x in c.co_consts if isinstance(x, pytypes.CodeType))
    return out


def reference(kernel) -> pytypes.FunctionType:
    """The reference of ``kernel``: its source run by the interpreter, with :data:`MATH` for
    ``math`` and :func:`numpy.empty` for ``local`` arrays (see the module docstring)."""
    return _reference_of(kernel)


@functools.lru_cache(maxsize=None)
def _quiet(kernel):
    """:func:`reference` as Python callers run it: numpy's floating-point warnings off, as the
    compiled kernel gives inf/NaN without a word (its callers check them)."""
    ref = _reference_of(kernel)

    @functools.wraps(ref)
    def run(*args):
        with np.errstate(all="ignore"):
            return ref(*args)

    return run


# --------------------------------------------------------------------------- kernels
class Kernel:
    """A compiled kernel: Numba's dispatcher (:attr:`dispatcher`) for the kernels that call it
    (Numba types it as that dispatcher), and, called from Python, whichever of compiled code or
    :func:`reference` the process runs (:data:`STATE`).  ``py_func`` is the source function; the
    kernel carries its name, module, docstring and ``__wrapped__`` (``functools.wraps``), so
    ``inspect.signature``, ``inspect.unwrap`` and the docs see the function.  ``fn`` is what a
    call runs now (its first call, the reference, or Numba's dispatcher once compiled): a hot
    caller may call ``k.fn(...)`` to skip the kernel's own Python call (~0.2 µs)."""

    __slots__ = ("dispatcher", "py_func", "fn", "seen", "__dict__")

    def __init__(self, dispatcher):
        self.dispatcher = dispatcher
        self.py_func = dispatcher.py_func
        functools.update_wrapper(self, self.py_func)
        self.seen = None  # the Numba types of its first call from Python (loaded at the switch)
        self.fn = self._first

    def __call__(self, *args):
        return self.fn(*args)

    def _first(self, *args):
        start()
        with STATE.lock:
            if self.fn == self._first:  # made after the process chose its mode
                if STATE.compiled:
                    self.fn = self.dispatcher
                else:
                    self.fn = _quiet(self)
                    if self.seen is None:  # what the switch must load
                        self.seen = tuple(numba.typeof(a) for a in args)
        return self.fn(*args)

    def __get__(self, obj, objtype=None):
        """A kernel read from a class or an instance is the kernel itself (it binds nothing,
        like :class:`staticmethod`); defining this makes it a routine to ``inspect``, so
        tools that document or list functions (autodoc, ``help``) take it as one."""
        return self

    @property
    def signatures(self):
        return self.dispatcher.signatures

    @property
    def targetoptions(self) -> dict:
        """Numba's options of the kernel (:data:`OPTIONS`, ``inline``): Numba's inliner takes a
        global with this attribute as a dispatcher and inlines the source (:attr:`py_func`) of
        an ``inline="always"`` one into its caller — without it, an ``@kernel(inline=True)``
        was called as a function, its tuples of arrays passed and returned by reference
        counts (``_pose_plan``, ``_verify_pose``: a third of the one-pose IK's call)."""
        return self.dispatcher.targetoptions

    def __repr__(self):
        return f"<kernel {self.__module__}.{self.__qualname__}>"


@typeof_impl.register(Kernel)
def _typeof_kernel(val, c):
    return numba.typeof(val.dispatcher)


class Entry:
    """The compiled body of a kernel for fixed argument types (:func:`entry_point`), or its
    reference until the process switches to compiled code."""

    __slots__ = ("kernel", "sig", "fn")

    def __init__(self, kernel, sig):
        self.kernel, self.sig = kernel, sig
        self.fn = self._body()

    def _body(self):
        if STATE.compiled:
            return self.kernel.dispatcher.compile(self.sig)
        return _quiet(self.kernel)

    def __call__(self, *args):
        return self.fn(*args)


def kernel(func=None, *, inline: bool = False, cache: bool | None = None):
    """Make ``func`` a :class:`Kernel` (Numba :data:`OPTIONS`, its disk cache for anthroarm's
    own kernels; ``cache=True/False`` decides for another package's); called like ``func``.  ``inline=True`` compiles it into each caller's body
    (``numba.njit(inline="always")``)."""

    def wrap(f):
        options = dict(OPTIONS, inline="always") if inline else dict(OPTIONS)
        if cache is not None:
            options["cache"] = bool(cache)
        elif f.__module__.split(".")[0] != __name__.split(".")[0]:
            # another package's kernel: anthroarm's cache is keyed by anthroarm's sources (see
            # OWN_FOLDER), not by that package's, so it compiles in each process unless it
            # asks for the cache (``cache=True``: Numba's keys, its own file only)
            options["cache"] = False
        k = Kernel(numba.njit(**options)(f))
        STATE.kernels.append(k)
        return k

    return wrap if func is None else wrap(func)


def switch(kernels) -> pytypes.FunctionType:
    """``f(i, *args)``: ``kernels[i](*args)`` — a kernel chosen by an index known at run time
    (``kernels[-1]`` for an index out of range), as a kernel may call it.  Numba cannot call
    one of several kernels picked from a tuple without making them first-class function objects
    (an experimental feature), so in a compiled kernel ``f`` is Numba's ``overload`` of it
    written out from the tuple, ``if i == 0: return K0(*args) elif i == 1: …`` — a direct call
    of each kernel, compiled and cached with its caller — and called from Python (or by a
    reference) it is the line above.  The one table of kernels is ``f.kernels``: a registry
    that adds a kernel adds it to the dispatch."""
    kernels = tuple(kernels)
    last = len(kernels) - 1
    if last < 0 or not all(isinstance(k, Kernel) for k in kernels):
        raise TypeError("switch takes a non-empty tuple of kernels")

    f = _by_index(kernels)

    def written_out(i, *args):
        lines = ["def dispatch(i, *args):"]
        lines += [f"    if i == {j}:\n        return K{j}(*args)" for j in range(last)]
        lines.append(f"    return K{last}(*args)")
        scope = {f"K{j}": k for j, k in enumerate(kernels)}
        exec(compile("\n".join(lines), f"<switch of {len(kernels)} kernels>", "exec"), scope)
        return scope["dispatch"]

    overload(f)(written_out)
    f.kernels, f.is_switch = kernels, True
    return f


def callees(k: Kernel) -> list[Kernel]:
    """The kernels ``k``'s source calls by a global name (compiled with it), and those of a
    :func:`switch` it calls."""
    g = k.py_func.__globals__
    names = sorted(set(_names(k.py_func.__code__)))
    out = [g[n] for n in names if isinstance(g.get(n), Kernel) and g[n] is not k]
    for n in names:
        if getattr(g.get(n), "is_switch", False):
            out += list(g[n].kernels)
    return out


def entry_point(k: Kernel, *args) -> Entry:
    """The body of kernel ``k`` for the Numba types of ``args`` (example arguments), called
    with arguments of exactly those types: compiled (``dispatcher.compile``, which skips the
    dispatcher's resolution of the argument types on every call, about 40 ns an array
    argument, and its checks: an array of another dtype, dimension, layout or alignment is
    undefined behaviour) once the process runs compiled code, its reference until then.  For a
    hot call whose caller has checked its arguments (the one-pose closed-form IK,
    :func:`anthroarm.ik.closed_form.analytic`)."""
    start()
    e = Entry(k, tuple(numba.typeof(a) for a in args))
    if k.seen is None:
        k.seen = e.sig
    with STATE.lock:
        STATE.entries.append(e)
    return e


# --------------------------------------------------------------------------- the switch
class _State:
    """The process's kernels and mode: ``compiled`` None (not started), False (reference,
    waiting for the background compilation) or True."""

    def __init__(self):
        self.lock = threading.RLock()
        self.kernels: list[Kernel] = []
        self.entries: list[Entry] = []
        self.compiled: bool | None = None
        self.reason = ""  # why the process runs the reference (for status())
        self.watcher: threading.Thread | None = None


#: the one state of this process (see the module docstring)
STATE = _State()


def ready_name() -> str:
    """The name of this build's ready stamp: the kernel sources, Numba, llvmlite, Python and
    the CPU it compiles for."""
    parts = (
        kernel_sources_digest(str(Path(__file__).resolve().parent)),
        numba.__version__,
        llvmlite.__version__,
        platform.python_version(),
        platform.machine(),
        llvm.get_host_cpu_name(),
        llvm.get_host_cpu_features().flatten(),
        os.environ.get("NUMBA_CACHE_DIR", ""),
    )
    return "ready-" + _cache.key(*parts) + ".json"


def numba_folder() -> Path:
    """The folder of Numba's cache files (``$NUMBA_CACHE_DIR``)."""
    return Path(os.environ["NUMBA_CACHE_DIR"])


def _files(folder: Path) -> dict[str, str]:
    out = {}
    if not folder.is_dir():
        return out
    for p in sorted(folder.rglob("*")):
        if p.suffix in (".nbi", ".nbc") and p.is_file() and not p.is_symlink():
            try:
                out[str(p.relative_to(folder))] = hashlib.sha256(p.read_bytes()).hexdigest()
            except OSError:
                continue
    return out


def _read_stamp() -> tuple[dict, bool]:
    data = _cache.read(STAMP_SUBFOLDER, ready_name())
    try:
        stamp = json.loads(data) if data is not None else {}
        files = {str(k): str(v) for k, v in dict(stamp.get("files", {})).items()}
        return files, stamp.get("complete") is True
    except (ValueError, TypeError, AttributeError):
        return {}, False


def write_stamp(complete: bool | None = None) -> dict:
    """Write the stamp: the SHA-256 of every Numba file in :func:`numba_folder` now, and whether
    the background compilation has compiled every kernel (``complete``; None: keep what the
    stamp said if none of its files changed).  The background compilation writes it complete;
    a process that compiled kernels itself adds its files at exit."""
    old, was = _read_stamp()
    files = _files(numba_folder())
    if complete is None:
        complete = was and all(files.get(k) == h for k, h in old.items())
    stamp = {"complete": bool(complete), "files": files}
    _cache.write(STAMP_SUBFOLDER, ready_name(), json.dumps(stamp).encode())
    return files


def verified(strict: bool = True) -> bool:
    """Check every Numba file against the stamp; True if the stamp is complete and every file
    it lists is there and matches.  A file that does not match, or (``strict``) that it does
    not list in the subfolders of listed files (Numba's, one per source folder; the folder may
    hold another program's kernels), is deleted — compiled again, never loaded — and the stamp
    rewritten incomplete.  The mode ``compile`` checks with ``strict=False``: files that
    processes compiling in their own threads wrote since the stamp are theirs to list at exit.
    Without a complete stamp the strict check deletes nothing (the background compilation is
    writing its files) and answers False."""
    listed, complete = _read_stamp()
    if strict and not complete:  # a compilation runs (or none yet): its files are not listed
        return False  # until its stamp, and nothing is loaded meanwhile; nothing is deleted
    folder = numba_folder()
    found = _files(folder)
    if not strict:
        found = {k: h for k, h in found.items() if k in listed}
    else:  # the subfolders of anthroarm's modules (another program's kernels may share it)
        ours = {str(Path(k).parent) for k in listed}
        found = {k: h for k, h in found.items() if str(Path(k).parent) in ours}
    bad = [k for k, h in found.items() if listed.get(k) != h]
    for k in bad:
        try:
            (folder / k).unlink()
        except OSError:
            pass
    if bad or any(k not in found for k in listed):
        write_stamp(complete=False)
        return False
    return complete


def _at_exit() -> None:
    """Add the files this process compiled to the stamp (see :func:`write_stamp`)."""
    try:
        if any(sum(k.dispatcher.stats.cache_misses.values()) for k in STATE.kernels):
            write_stamp()
    except Exception:  # noqa: BLE001 - never fail an exit; unlisted files are compiled again
        pass


def lock_path() -> Path | None:
    """The lock file of the background compilation for this stamp (its process id), or None
    without a cache folder."""
    folder = _cache.folder(STAMP_SUBFOLDER)
    return None if folder is None else folder / (ready_name()[:-5] + ".lock")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def running() -> int:
    """The process id of the background compilation for this stamp if it runs, else 0."""
    lock = lock_path()
    try:
        pid = int(lock.read_text().strip() or 0) if lock is not None else 0
    except (OSError, ValueError):
        return 0
    return pid if pid > 0 and _alive(pid) else 0


#: how the background compilation is detached from the caller: its own process group (a Ctrl-C
#: in the caller's terminal does not reach it), in the caller's session.  A new session would
#: also put it in its own scheduling group on Linux (autogroup: every session gets an equal share
#: of the CPU whatever its nice value), where it took a whole core from a caller that needs both;
#: in the caller's session its ``nice`` (:func:`anthroarm.warmup.main`) holds.
_OWN_GROUP = {"process_group": 0} if sys.version_info >= (3, 11) else {"start_new_session": True}


def start_background() -> bool:
    """Start the background compilation (``python -m anthroarm.warmup``, in its own process group,
    its output in the lock's ``.log``) unless one runs for this stamp; True if one runs."""
    lock = lock_path()
    if lock is None:
        return False
    if running():
        return True
    env = dict(os.environ, ANTHROARM_JIT="compile")
    with open(lock.with_suffix(".log"), "wb") as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "anthroarm.warmup"],
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            env=env,
            **_OWN_GROUP,
        )
    lock.write_text(str(proc.pid))
    return True


def _switch() -> None:
    """Run compiled code from now on: load the compiled kernels this process has used (their
    first call's types), then point every kernel and entry point at compiled code."""
    with STATE.lock:
        if STATE.compiled:
            return
        loaded = {}
        for k in STATE.kernels:
            if k.seen is not None:
                try:
                    k.dispatcher.compile(k.seen)
                except Exception:  # noqa: BLE001 - it loads or compiles on its first call
                    pass
        for e in STATE.entries:
            loaded[id(e)] = e.kernel.dispatcher.compile(e.sig)
        STATE.compiled = True
        for k in STATE.kernels:
            k.fn = k.dispatcher
        for e in STATE.entries:
            e.fn = loaded[id(e)]
        STATE.reason = ""


def _watch() -> None:
    """Wait for the ready stamp (restarting a background compilation that ended without one
    once), then switch."""
    restarted = False
    while True:
        time.sleep(POLL)
        try:
            if verified():
                _switch()
                return
            if running():
                continue
            time.sleep(POLL)  # it may have just written the stamp
            if verified():
                _switch()
                return
            if restarted:
                lock = lock_path()
                STATE.reason = f"the background compilation failed (see {lock.with_suffix('.log')})"
                return
            restarted = start_background()
        except Exception as exc:  # noqa: BLE001 - stay on the reference, say why
            STATE.reason = f"the background compilation failed: {exc}"
            return


def start() -> None:
    """Decide this process's mode, once (the first kernel call or entry point)."""
    if STATE.compiled is not None:
        return
    with STATE.lock:
        if STATE.compiled is not None:
            return
        m = mode()
        ready = m != "reference" and verified(strict=m == "auto")  # damaged files deleted
        if m != "reference":
            atexit.register(_at_exit)
        if m == "compile" or ready:
            STATE.compiled = True
            for k in STATE.kernels:
                k.fn = k.dispatcher
            return
        STATE.compiled = False  # each kernel's first call takes its reference (Kernel._first)
        if m == "reference":
            STATE.reason = "ANTHROARM_JIT=reference"
            return
        STATE.reason = "compiling in the background"
        try:
            started = start_background()
        except OSError as exc:
            started, STATE.reason = False, f"cannot start the background compilation: {exc}"
        if started:
            STATE.watcher = threading.Thread(target=_watch, name="anthroarm-jit", daemon=True)
            STATE.watcher.start()
        elif not STATE.reason.startswith("cannot"):
            STATE.reason = "no cache folder for the compiled kernels"
        if not started:
            warnings.warn(
                f"anthroarm runs its kernels uncompiled ({STATE.reason}): slower",
                RuntimeWarning,
                stacklevel=3,
            )


def compiled() -> bool:
    """True if this process runs compiled kernels now (deciding its mode first)."""
    start()
    return bool(STATE.compiled)


def status() -> str:
    """``compiled``, ``reference (<why>)`` or ``not started``: what this process runs."""
    if STATE.compiled is None:
        return "not started"
    return "compiled" if STATE.compiled else f"reference ({STATE.reason})"


def wait(timeout: float | None = None) -> bool:
    """Wait until this process runs compiled code (or ``timeout`` seconds); True if it does."""
    start()
    end = None if timeout is None else time.monotonic() + timeout
    while not STATE.compiled:
        w = STATE.watcher
        if w is None or not w.is_alive():
            return bool(STATE.compiled)
        w.join(POLL if end is None else max(0.0, min(POLL, end - time.monotonic())))
        if end is not None and time.monotonic() >= end:
            break
    return bool(STATE.compiled)


__all__ = [
    "CACHE_SUBFOLDER",
    "MATH",
    "MODES",
    "OPTIONS",
    "OWN_FOLDER",
    "STATE",
    "Entry",
    "Kernel",
    "borrow",
    "callees",
    "compiled",
    "entry_point",
    "kernel",
    "kernel_files",
    "kernel_sources_digest",
    "local",
    "local2",
    "local_flags",
    "local_ints2",
    "mode",
    "part",
    "part2",
    "numba_folder",
    "ready_name",
    "reference",
    "running",
    "switch",
    "start_background",
    "lock_path",
    "start",
    "status",
    "verified",
    "view2",
    "view3",
    "wait",
    "write_stamp",
]
