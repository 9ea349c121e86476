"""The one disk cache: everything anthroarm writes to disk to reuse later lives here.

Today that is the generated Lagrange code (``lagrange/*.py``, :mod:`anthroarm.dynamics.lagrange`)
and the compiled C libraries (``lagrange/*.so``, :mod:`anthroarm.dynamics.ccode`;
compiled scalar kernels (``numba/``, Numba's own cache of :mod:`anthroarm.jit` kernels: keyed by
source file, signature, CPU and Numba version, see there).

**Where.**  ``$ANTHROARM_CACHE`` if set; else ``$XDG_CACHE_HOME/anthroarm`` if set; else the
platform's user cache folder: ``~/.cache/anthroarm`` (Linux and other Unix),
``~/Library/Caches/anthroarm`` (macOS), ``%LOCALAPPDATA%\\anthroarm\\Cache`` (Windows).
One subfolder per producer (``lagrange``, ``ik``).

**Keys.**  A file's name carries a hash of what determines its content: the generator's inputs
and version for generated Python, and for a shared library the C source, the compiler (its path
and ``--version``) and the flags (:func:`key`).

**Integrity.**  Every entry ``NAME`` has a sidecar ``NAME.sha256`` with the SHA-256 and size
of its bytes, written after it.  :func:`read` returns the bytes only if they match; a
generated module is executed from exactly those verified bytes, or from its bytecode entry
(keyed by the verified source's hash, itself verified; :func:`python_module`), and a
shared library is loaded only after its file has been verified (:func:`shared_library`).  A
truncated, edited or half-copied entry is deleted and rebuilt, never run.  Both files are
written atomically (temp file + ``os.replace``, :func:`anthroarm._io.atomic_write_text`), so
concurrent processes see a whole file or none.

**Trust.**  The digest catches *accidents* (a crash mid-write, a full disk, a half-copied
folder, a truncated file), not an adversary: whoever can write the folder can restamp a
sidecar.  Other users are kept out by the folder itself, checked every time it is used
(:func:`root`), as ssh checks its keys: it must be a real folder (a symbolic link is refused,
not resolved: a link to ``/usr/lib`` passes an owner check when running as root), owned by
this process's effective user and not writable by group or others.  A missing folder is
created with mode 0700 whatever the umask.  A folder that fails the check is not used at all
(an :class:`~anthroarm.errors.UnsafeCacheWarning` says why and how to fix it): this process
runs without the cache, from a private temporary folder removed at exit; ``anthroarm cache
clear`` refuses it with :class:`~anthroarm.errors.UnsafeCacheError`.  Inside the folder no
symbolic link is followed: an entry is read only if it is a regular file (``O_NOFOLLOW``, no
blocking on a FIFO), a link in place of an entry is replaced, not written through, a
subfolder that is a link is not used; ``clear`` deletes only regular files of the forms the
cache writes, through folder descriptors that never cross a link.  A shared library is
returned only if its bytes verify, its size on disk is theirs, and, for ELF, its headers stay
inside it (a truncated library with a restamped sidecar would otherwise be mapped and kill
the process with SIGBUS): else it is compiled again.  See ``SECURITY.md``.

**No cache folder.**  If the folder cannot be created or written (read-only, under a regular
file, full disk) or is refused, everything still works: generated code is executed from
memory (or from the private temporary folder) and a library is compiled into a private
temporary folder removed when the process exits; :func:`status` says why.
``anthroarm cache info`` / ``anthroarm cache clear`` show and empty it.

Thread-safe: no shared mutable state but a memo of compiler versions and the last fallback
reason and the refused folders (plain strings, under a lock).
"""

from __future__ import annotations

import atexit
import hashlib
import marshal
import os
import re
import shutil
import stat
import struct
import subprocess
import sys
import tempfile
import threading
import types
import warnings
from pathlib import Path

from ._io import atomic_write_text
from .errors import ParameterError, UnsafeCacheError, UnsafeCacheWarning

ENV = "ANTHROARM_CACHE"
#: subfolders this module manages (``cache clear`` empties only these; ``ik`` holds the C
#: attempt kernels of releases before the LM attempt became a numba kernel: cleared, not written)
SUBFOLDERS = ("lagrange", "ik", "urdf", "numba", "kernels")
_SIDECAR = ".sha256"
_LOCK = threading.Lock()
_CC_IDS: dict[str, str] = {}
# fallback: the last write failure; refused: {configured folder: why it is not used}
_STATE = {"fallback": None, "tmp": None, "refused": {}}
_O_READ = (
    os.O_RDONLY
    | getattr(os, "O_NOFOLLOW", 0)
    | getattr(os, "O_NONBLOCK", 0)
    | getattr(os, "O_CLOEXEC", 0)
    | getattr(os, "O_BINARY", 0)
)
_O_DIR = (
    os.O_RDONLY
    | getattr(os, "O_DIRECTORY", 0)
    | getattr(os, "O_NOFOLLOW", 0)
    | getattr(os, "O_CLOEXEC", 0)
)


# ---------------------------------------------------------------------------- where
def configured() -> Path:
    """The cache folder the environment asks for (see the module docstring); neither created
    nor checked (:func:`root` does both)."""
    env = os.environ.get(ENV)
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg:
        return Path(xdg).expanduser() / "anthroarm"
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "anthroarm"
    if os.name == "nt":
        base = os.environ.get("LOCALAPPDATA")
        return (Path(base) if base else Path.home() / "AppData" / "Local") / "anthroarm" / "Cache"
    return Path.home() / ".cache" / "anthroarm"


def root() -> Path:
    """The cache folder in use: :func:`configured`, created with mode 0700 if missing, if it
    passes the check (a real folder, not a symbolic link; owned by this process's effective
    user; not writable by group or others).  Otherwise a private temporary folder of this
    process (0700, removed at exit), and nothing is read from or written to the configured one:
    an :class:`~anthroarm.errors.UnsafeCacheWarning` (once per folder and reason) says why
    when the folder is unsafe, :func:`status` also when it merely cannot be created."""
    p = configured()
    key = str(p)
    problem, unsafe = _prepare(p)
    if problem is None:
        if key in _STATE["refused"]:
            with _LOCK:
                _STATE["refused"].pop(key, None)
        return p
    _refuse(key, problem, warn=unsafe)
    return _private_dir()


def _prepare(p: Path) -> tuple[str | None, bool]:
    """(why ``p`` cannot be the cache folder or None, whether that is a safety problem);
    creates ``p`` (0700) if it does not exist."""
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        try:
            p.parent.mkdir(parents=True, exist_ok=True)
            os.mkdir(p, 0o700)  # the mode is masked by the umask, which keeps 0700 as it is
        except FileExistsError:
            pass  # made by another process meanwhile: checked below like any folder
        except OSError as exc:
            return f"cannot create it ({exc.strerror or exc})", False
        try:
            st = os.lstat(p)
        except OSError as exc:
            return f"cannot create it ({exc.strerror or exc})", False
    except OSError as exc:
        return f"cannot use it ({exc.strerror or exc})", False
    problem = _unsafe(p, st)
    return problem, problem is not None


def _unsafe(p: Path, st: os.stat_result) -> str | None:
    """Why the folder ``p`` (its ``lstat``) must not be trusted, or None."""
    if stat.S_ISLNK(st.st_mode):
        return (
            f"it is a symbolic link (to {os.path.realpath(p)}), which is not followed; "
            f"set ${ENV} to the folder itself if it is yours"
        )
    if not stat.S_ISDIR(st.st_mode):
        return "it is not a folder"
    if os.name != "posix":  # Windows: the user's profile folder is private by its ACL
        return None
    euid = os.geteuid()
    if st.st_uid != euid:
        return (
            f"it is owned by uid {st.st_uid}, not by you (uid {euid}); "
            f"set ${ENV} to a folder of your own"
        )
    if st.st_mode & 0o022:
        who = " and ".join(
            w for w, bit in (("group", 0o020), ("others", 0o002)) if st.st_mode & bit
        )
        return (
            f"it is writable by {who} (mode {stat.S_IMODE(st.st_mode):04o}), who could plant "
            f"code that anthroarm runs; make it private with: chmod 700 {p}, "
            "then empty it with: anthroarm cache clear"
        )
    return None


def _check(p: Path) -> str | None:
    """Why the existing folder ``p`` must not be trusted; None if it passes or is absent."""
    try:
        st = os.lstat(p)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        return f"cannot use it ({exc.strerror or exc})"
    return _unsafe(p, st)


def _refusal(key: str, problem: str) -> str:
    return (
        f"cache folder {key} not used: {problem}; this process keeps generated code in a "
        "private temporary folder removed at exit"
    )


def _refuse(key: str, problem: str, warn: bool) -> None:
    msg = _refusal(key, problem)
    with _LOCK:
        new = _STATE["refused"].get(key) != msg
        _STATE["refused"][key] = msg
    if new and warn:
        warnings.warn(msg, UnsafeCacheWarning, stacklevel=4)


def folder(sub: str) -> Path | None:
    """``root()/sub``, created (0700) if needed; None (and :func:`status` says why) if it cannot
    be, or if it is a symbolic link or not a folder (never followed)."""
    if sub not in SUBFOLDERS:
        raise ValueError(f"unknown cache subfolder {sub!r}; choose from {', '.join(SUBFOLDERS)}")
    p = root() / sub
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        try:
            os.mkdir(p, 0o700)
        except FileExistsError:
            pass
        except OSError as exc:
            _fallback(f"cannot create {p}: {exc.strerror or exc}")
            return None
        try:
            st = os.lstat(p)
        except OSError as exc:
            _fallback(f"cannot create {p}: {exc.strerror or exc}")
            return None
    except OSError as exc:
        _fallback(f"cannot use {p}: {exc.strerror or exc}")
        return None
    if stat.S_ISLNK(st.st_mode):
        _fallback(f"{p} is a symbolic link, which is not followed (remove it)")
        return None
    if not stat.S_ISDIR(st.st_mode):
        _fallback(f"{p} is not a folder")
        return None
    return p


def _fallback(reason: str) -> None:
    with _LOCK:
        _STATE["fallback"] = (
            f"{reason}; generated code is kept in memory (set ${ENV} to a writable folder)"
        )


def status() -> str:
    """Where the cache is, or why it is not used; whether the last write or folder creation
    failed."""
    p = configured()
    problem = _check(p)
    if problem is not None:
        return _refusal(str(p), problem)
    with _LOCK:
        why = _STATE["refused"].get(str(p)) or _STATE["fallback"]
    return why or f"{p} (writable as far as known)"


# ---------------------------------------------------------------------------- keys
def compiler() -> str | None:
    """Path of the C compiler (``$CC``, default ``cc``), or None."""
    return shutil.which(os.environ.get("CC", "cc"))


#: ``$ANTHROARM_JIT``: who compiles (:mod:`anthroarm.jit`): ``auto`` in the background,
#: ``compile`` on first use in the calling thread, ``reference`` never
BUILD_MODES = ("auto", "compile", "reference")


def build_mode() -> str:
    """``$ANTHROARM_JIT`` (:data:`BUILD_MODES`; ``auto`` if unset).  An unknown value raises
    :class:`~anthroarm.errors.ParameterError`."""
    m = os.environ.get("ANTHROARM_JIT", "auto").strip().lower() or "auto"
    if m not in BUILD_MODES:
        raise ParameterError(f"ANTHROARM_JIT={m!r}: give one of {', '.join(BUILD_MODES)}")
    return m


def compiler_id(cc: str) -> str:
    """The compiler's path and the first line of its ``--version`` (memoised per path)."""
    with _LOCK:
        got = _CC_IDS.get(cc)
    if got is None:
        try:
            r = subprocess.run([cc, "--version"], capture_output=True, text=True, timeout=30)
            first = (r.stdout or r.stderr).strip().splitlines()
            got = f"{cc} {first[0] if first else ''}"
        except (OSError, subprocess.SubprocessError):
            got = cc
        with _LOCK:
            _CC_IDS[cc] = got
    return got


def key(*parts, length: int = 24) -> str:
    """Hex SHA-256 (first ``length`` digits) of the parts (str or bytes), separated."""
    h = hashlib.sha256()
    for p in parts:
        h.update(p if isinstance(p, bytes) else str(p).encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()[:length]


# ---------------------------------------------------------------------------- entries
def _sidecar(path: Path) -> Path:
    return path.with_name(path.name + _SIDECAR)


def _stamp(data: bytes) -> str:
    return f"sha256 {hashlib.sha256(data).hexdigest()} {len(data)}\n"


def _remove(path: Path) -> None:
    """Delete an entry and its sidecar (a symbolic link is removed itself, never its target)."""
    for p in (path, _sidecar(path)):
        try:
            p.unlink()
        except FileNotFoundError:
            pass
        except OSError:  # read-only folder: the entry stays invalid and is rebuilt in memory
            pass


class _NotRegular(Exception):
    """An entry that is a symbolic link, a FIFO, a device or a folder."""


def _read_regular(path: Path) -> bytes:
    """The bytes of ``path`` if it is a regular file: a symbolic link is not followed
    (``O_NOFOLLOW``), a FIFO or device does not block (``O_NONBLOCK``); :class:`_NotRegular`
    otherwise, ``FileNotFoundError`` if it does not exist."""
    if not stat.S_ISREG(os.lstat(path).st_mode):
        raise _NotRegular(path)
    fd = os.open(path, _O_READ)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped since the lstat
            raise _NotRegular(path)
        with os.fdopen(fd, "rb", closefd=False) as f:
            return f.read()
    finally:
        os.close(fd)


def _drop_non_regular(path: Path) -> None:
    """Delete ``path`` if it is a symbolic link, FIFO, socket or device (the link itself, not
    its target), so that a write replaces it instead of going through it."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if not stat.S_ISREG(mode) and not stat.S_ISDIR(mode):
        os.unlink(path)


def read(sub: str, name: str) -> bytes | None:
    """The bytes of entry ``name`` if it is a regular file (no symbolic link is followed) that
    matches its recorded SHA-256 and size; None otherwise (a damaged entry is deleted)."""
    d = folder(sub)
    if d is None:
        return None
    path = d / name
    try:
        data = _read_regular(path)
        stamp = _read_regular(_sidecar(path)).decode("ascii")
    except (FileNotFoundError, UnicodeDecodeError, _NotRegular):
        if os.path.lexists(path):
            _remove(path)  # an entry without a valid sidecar cannot be trusted
        return None
    except OSError:
        return None
    if stamp != _stamp(data):
        _remove(path)
        return None
    return data


def write(sub: str, name: str, data: bytes) -> Path | None:
    """Store ``data`` as entry ``name`` (the file, then its sidecar, each atomically: a temp
    file in the folder, then ``os.replace``; a symbolic link in their place is replaced, not
    written through); the path, or None if the cache folder is not writable (then nothing is
    stored)."""
    d = folder(sub)
    if d is None:
        return None
    path = d / name
    try:
        _drop_non_regular(path)
        _drop_non_regular(_sidecar(path))
        atomic_write_text(path, data)
        atomic_write_text(_sidecar(path), _stamp(data))
    except OSError as exc:
        _fallback(f"cannot write {path}: {exc.strerror or exc}")
        return None
    return path


def python_module(sub: str, name: str, make_source, modname: str):
    """A module from the generated Python entry ``name``: executed from its verified cached
    bytes, else from ``make_source()`` (str), which is then stored.  Returns
    ``(module, origin)`` with origin "cache" or "derived"."""
    data = read(sub, name)
    origin = "cache"
    if data is None:
        data = make_source().encode("utf-8")
        write(sub, name, data)
        origin = "derived"
    mod = types.ModuleType(modname)
    mod.__file__ = str(root() / sub / name)
    # its bytecode is an entry too (compiling a large generated module costs more than deriving
    # it), keyed by the verified source's hash and the interpreter's bytecode tag
    cname = f"{name}.{key(data, length=16)}.{sys.implementation.cache_tag}.code"
    code = read(sub, cname)
    if code is not None:
        code = marshal.loads(code)
    else:
        code = compile(data, mod.__file__, "exec")
        write(sub, cname, marshal.dumps(code))
    exec(code, mod.__dict__)
    return mod, origin


class CompileError(RuntimeError):
    """The C compiler is missing or failed (message: the compiler's first 500 characters)."""


def shared_library(
    sub: str, stem: str, source: str, flags: list[str], compile: bool = True
) -> tuple[Path, str] | None:
    """Path of a shared library compiled from C ``source`` with ``flags``: the cached
    ``<stem>_<key>.so`` if its bytes verify, its size on disk is theirs and it is whole
    (:func:`library_complete`), else compiled now and stored: a library that fails any of these
    is never returned, so never handed to ``dlopen``.  The key hashes the source, the compiler
    (:func:`compiler_id`) and the flags.  Without a writable cache folder
    the library is compiled into a private temporary folder.  Returns ``(path, origin)`` with
    origin "cache" or "compiled" (None with ``compile=False`` and no cached library); raises
    :class:`CompileError`."""
    cc = compiler()
    if cc is None:
        raise CompileError("no C compiler ($CC or cc)")
    name = f"{stem}_{key(source, compiler_id(cc), ' '.join(flags))}.so"
    d = folder(sub)
    if d is not None:
        data = read(sub, name)
        if data is not None:
            try:
                st = os.lstat(d / name)
                same = stat.S_ISREG(st.st_mode) and st.st_size == len(data)
            except OSError:
                same = False
            if same and library_complete(data):
                return d / name, "cache"
            _remove(d / name)  # never handed to dlopen: compiled again
    if not compile:
        return None
    so = _compile(cc, source, flags)
    path = write(sub, name, so)
    if path is None:
        path = _private_dir() / name
        atomic_write_text(path, so)
    return path, "compiled"


def library_complete(data: bytes) -> bool:
    """False if ``data`` cannot be a whole shared library: an ELF file whose program or section
    headers name bytes beyond its end, as a truncated library does (the dynamic loader maps
    its segments as the headers say, and the first touch of a page past the end of the file
    kills the process with SIGBUS), or, on Linux and other ELF platforms, not ELF at all.
    True otherwise; other formats (Mach-O, PE) are left to their loader and the digest."""
    if data[:4] != b"\x7fELF":
        return sys.platform == "darwin" or os.name == "nt"
    if len(data) < 52 or data[4] not in (1, 2) or data[5] not in (1, 2):
        return False
    e = "<" if data[5] == 1 else ">"
    try:
        if data[4] == 2:  # ELF64: e_phoff, e_shoff at 32; e_phentsize... at 54
            phoff, shoff = struct.unpack_from(e + "QQ", data, 32)
            phentsize, phnum, shentsize, shnum = struct.unpack_from(e + "HHHH", data, 54)
            ph, at = e + "IIQQQQ", (2, 5)  # p_type p_flags p_offset p_vaddr p_paddr p_filesz
        else:  # ELF32: e_phoff, e_shoff at 28; e_phentsize... at 42
            phoff, shoff = struct.unpack_from(e + "II", data, 28)
            phentsize, phnum, shentsize, shnum = struct.unpack_from(e + "HHHH", data, 42)
            ph, at = e + "IIIII", (1, 4)  # p_type p_offset p_vaddr p_paddr p_filesz
        n = len(data)
        if phoff + phnum * phentsize > n or shoff + shnum * shentsize > n:
            return False
        if phnum and phentsize < struct.calcsize(ph):
            return False
        for i in range(phnum):
            f = struct.unpack_from(ph, data, phoff + i * phentsize)
            if f[at[0]] + f[at[1]] > n:
                return False
    except struct.error:
        return False
    return True


def _compile(cc: str, source: str, flags: list[str]) -> bytes:
    with tempfile.TemporaryDirectory(prefix="anthroarm_cc_") as tmp:
        cpath, opath = Path(tmp) / "src.c", Path(tmp) / "lib.so"
        cpath.write_text(source)
        try:
            r = subprocess.run(
                [cc, *flags, "-o", str(opath), str(cpath), "-lm"], capture_output=True, text=True
            )
        except OSError as exc:
            raise CompileError(f"cannot run the C compiler {cc}: {exc}") from None
        if r.returncode != 0:
            raise CompileError(f"C compilation failed: {r.stderr[:500]}")
        return opath.read_bytes()


def _private_dir() -> Path:
    with _LOCK:
        if _STATE["tmp"] is None:
            _STATE["tmp"] = tempfile.mkdtemp(prefix="anthroarm_cache_")
            atexit.register(shutil.rmtree, _STATE["tmp"], True)
        return Path(_STATE["tmp"])


# ---------------------------------------------------------------------------- info / clear
#: names of the files the cache writes (``clear`` deletes nothing else): generated entries and
#: their bytecode, sidecars, the temp files of :func:`anthroarm._io.atomic_write_text`, the
#: book URDFs, Numba's index and data files and its temp files
_OWN = {
    "*": re.compile(
        r"[A-Za-z][A-Za-z0-9]*_[0-9a-f]{16,64}\.(py|so)"
        r"|.+\.py\.[0-9a-f]{16}\.[A-Za-z0-9_-]+\.code"
        r"|.+\.sha256"
        r"|\..+\.\d+\.\d+\.[0-9a-f]{8}\.tmp"
    ),
    "urdf": re.compile(r"[A-Za-z0-9_]+\.urdf"),
    "numba": re.compile(r".+\.nb[ic](\.tmp\.[0-9a-f]+)?"),
    "kernels": re.compile(r"ready-[0-9a-f]+\.(json|lock|log)"),
}


def _is_own(sub: str, name: str, names: set) -> bool:
    """Whether ``name`` (in a folder holding ``names``) is a file the cache writes: a name of
    its forms, or an entry with its sidecar next to it."""
    rx = _OWN.get(sub)
    return bool(
        _OWN["*"].fullmatch(name)
        or (rx is not None and rx.fullmatch(name))
        or name + _SIDECAR in names
    )


def _counts(name: str) -> bool:
    """Whether an own file counts as an entry (not a sidecar or a temp file)."""
    return not name.endswith(_SIDECAR) and not name.startswith(".") and ".tmp." not in name


def _own_files(base: Path, sub: str):
    """Yield ``(dir_fd, name, lstat)`` for the cache's own regular files below ``base/sub``,
    and ``(dir_fd, name, None)`` for the real folders below it, bottom-up (each after its
    contents).  No symbolic link is followed or yielded: the walk goes through folder
    descriptors (``os.fwalk``), so a folder swapped for a link meanwhile is not entered.
    Where ``os.fwalk`` does not exist (Windows), ``dir_fd`` is None and ``name`` a full path."""
    if not hasattr(os, "fwalk"):
        top = base / sub
        if not top.is_dir() or top.is_symlink():
            return
        for (
            d,
            dirs,
            files,
        ) in os.walk(top, topdown=False, followlinks=False):
            yield from _classify(sub, None, dirs, files, lambda n, d=d: os.path.join(d, n))
        return
    try:
        bfd = os.open(base, _O_DIR)
    except OSError:  # absent, or not a folder (the caller has refused a link)
        return
    try:
        try:
            if not stat.S_ISDIR(os.stat(sub, dir_fd=bfd, follow_symlinks=False).st_mode):
                return  # a link or a file in place of the subfolder: not ours to walk
        except OSError:
            return
        for _, dirs, files, dfd in os.fwalk(sub, dir_fd=bfd, topdown=False):
            yield from _classify(sub, dfd, dirs, files, lambda n: n)
    finally:
        os.close(bfd)


def _classify(sub, dfd, dirs, files, full):
    names = set(files)
    for n in files:
        try:
            st = os.stat(full(n), dir_fd=dfd, follow_symlinks=False)
        except OSError:
            continue
        if stat.S_ISREG(st.st_mode) and _is_own(sub, n, names):
            yield dfd, full(n), st
    for n in dirs:
        try:
            st = os.stat(full(n), dir_fd=dfd, follow_symlinks=False)
        except OSError:
            continue
        if stat.S_ISDIR(st.st_mode):
            yield dfd, full(n), None


def info() -> dict:
    """{"folder", "entries", "bytes", "by_folder": {sub: (entries, bytes)}, "status"}; an
    entry is a cached file (its sidecar counted in its size); only the cache's own regular
    files count, and a folder that is a symbolic link is not looked into.  An unsafe folder
    warns (:class:`~anthroarm.errors.UnsafeCacheWarning`), as when it is used."""
    base = configured()
    problem = _check(base)
    if problem is not None:
        _refuse(str(base), problem, warn=True)
    by = {}
    for sub in SUBFOLDERS:
        n = size = 0
        if problem is None or "symbolic link" not in problem:
            for _, name, st in _own_files(base, sub):
                if st is not None:
                    size += st.st_size
                    n += _counts(os.path.basename(name))
        by[sub] = (n, size)
    return {
        "folder": str(base),
        "entries": sum(v[0] for v in by.values()),
        "bytes": sum(v[1] for v in by.values()),
        "by_folder": by,
        "status": status(),
    }


def clear() -> int:
    """Delete the cache's own files in its subfolders: regular files of the forms it writes
    (entries, sidecars, temp files, Numba's files) and Numba's emptied folders; nothing else
    under the folder, no file a symbolic link points to, nothing below a linked folder.
    Returns the number of entries removed.  Raises :class:`~anthroarm.errors.UnsafeCacheError`
    (nothing deleted) if the folder is a symbolic link, owned by another user or writable by
    group or others.  Libraries already loaded stay usable in running processes."""
    base = configured()
    problem = _check(base)
    if problem is not None:
        raise UnsafeCacheError(f"cache folder {base} not cleared: {problem}", path=base)
    removed = 0
    for sub in SUBFOLDERS:
        for dfd, name, st in _own_files(base, sub):
            try:
                if st is not None:
                    os.unlink(name, dir_fd=dfd)
                    removed += _counts(os.path.basename(name))
                elif sub == "numba":  # Numba's per-source folders; kept if not empty
                    os.rmdir(name, dir_fd=dfd)
            except OSError:
                pass
    with _LOCK:
        _STATE["fallback"] = None
    return removed
