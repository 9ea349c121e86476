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

**No cache folder.**  If the folder cannot be created or written (read-only, under a regular
file, full disk), everything still works: generated code is executed from memory and a
library is compiled into a private temporary folder removed when the process exits;
:func:`status` says why.  ``anthroarm cache info`` / ``anthroarm cache clear`` show and empty it.

Thread-safe: no shared mutable state but a memo of compiler versions and the last fallback
reason (both plain strings, under a lock).
"""

from __future__ import annotations

import atexit
import hashlib
import marshal
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import types
from pathlib import Path

from ._io import atomic_write_text

ENV = "ANTHROARM_CACHE"
#: subfolders this module manages (``cache clear`` empties only these)
SUBFOLDERS = ("lagrange", "ik", "urdf", "numba")
_SIDECAR = ".sha256"
_LOCK = threading.Lock()
_CC_IDS: dict[str, str] = {}
_STATE = {"fallback": None, "tmp": None}


# ---------------------------------------------------------------------------- where
def root() -> Path:
    """The cache folder (see the module docstring); not created here."""
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


def folder(sub: str) -> Path | None:
    """``root()/sub``, created if needed; None (and :func:`status` says why) if it cannot be."""
    if sub not in SUBFOLDERS:
        raise ValueError(f"unknown cache subfolder {sub!r}; choose from {', '.join(SUBFOLDERS)}")
    p = root() / sub
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        _fallback(f"cannot create {p}: {exc.strerror or exc}")
        return None
    return p


def _fallback(reason: str) -> None:
    with _LOCK:
        _STATE["fallback"] = (
            f"{reason}; generated code is kept in memory (set ${ENV} to a writable folder)"
        )


def status() -> str:
    """Where the cache is and whether the last write or folder creation failed."""
    return _STATE["fallback"] or f"{root()} (writable as far as known)"


# ---------------------------------------------------------------------------- keys
def compiler() -> str | None:
    """Path of the C compiler (``$CC``, default ``cc``), or None."""
    return shutil.which(os.environ.get("CC", "cc"))


class CompiledOnce:
    """One family of compiled kernels, each built on first use and kept on its owner.

    :meth:`get` builds ``owner.<attr>`` once (``False`` after a failed build, so it is not
    retried) and keeps the last failure for :meth:`status`; the environment variable ``switch``
    set to 0/false/no/off disables the family, and callers then use ``fallback`` (named in the
    status)."""

    def __init__(self, switch: str, fallback: str, available: str):
        self.switch, self.fallback, self.available = switch, fallback, available
        self.reason: str | None = None

    def enabled(self) -> bool:
        return os.environ.get(self.switch, "1").strip().lower() not in ("0", "false", "no", "off")

    def status(self) -> str:
        """Why the compiled kernels are (not) in use (the last build failure, if any)."""
        if not self.enabled():
            return f"disabled by {self.switch}=0"
        if compiler() is None:
            return f"no C compiler ($CC or cc) found: {self.fallback}"
        return self.reason or self.available

    def get(self, owner, attr: str, build, what: str):
        """``owner.<attr>``, built by ``build(owner)`` the first time; None where the family is
        disabled or the build failed (``what`` names the kernel in the status)."""
        if not self.enabled():
            return None
        k = getattr(owner, attr)
        if k is None:
            try:
                k = build(owner)
                self.reason = None
            except (RuntimeError, OSError) as exc:
                self.reason = f"compiled {what} unavailable ({exc}); {self.fallback}"
                k = False
            setattr(owner, attr, k)
        return k or None


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
    for p in (path, _sidecar(path)):
        try:
            p.unlink()
        except FileNotFoundError:
            pass
        except OSError:  # read-only folder: the entry stays invalid and is rebuilt in memory
            pass


def read(sub: str, name: str) -> bytes | None:
    """The bytes of entry ``name`` if it exists and matches its recorded SHA-256 and size;
    None otherwise (a damaged entry is deleted)."""
    d = folder(sub)
    if d is None:
        return None
    path = d / name
    try:
        data = path.read_bytes()
        stamp = _sidecar(path).read_text(encoding="ascii")
    except (FileNotFoundError, UnicodeDecodeError):
        if path.exists():
            _remove(path)  # an entry without a valid sidecar cannot be trusted
        return None
    except OSError:
        return None
    if stamp != _stamp(data):
        _remove(path)
        return None
    return data


def write(sub: str, name: str, data: bytes) -> Path | None:
    """Store ``data`` as entry ``name`` (the file, then its sidecar, each atomically); the
    path, or None if the cache folder is not writable (then nothing is stored)."""
    d = folder(sub)
    if d is None:
        return None
    path = d / name
    try:
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


def shared_library(sub: str, stem: str, source: str, flags: list[str]) -> tuple[Path, str]:
    """Path of a shared library compiled from C ``source`` with ``flags``: the cached
    ``<stem>_<key>.so`` if its bytes verify, else compiled now and stored.  The key hashes the
    source, the compiler (:func:`compiler_id`) and the flags.  Without a writable cache folder
    the library is compiled into a private temporary folder.  Returns ``(path, origin)`` with
    origin "cache" or "compiled"; raises :class:`CompileError`."""
    cc = compiler()
    if cc is None:
        raise CompileError("no C compiler ($CC or cc)")
    name = f"{stem}_{key(source, compiler_id(cc), ' '.join(flags))}.so"
    d = folder(sub)
    if d is not None and read(sub, name) is not None:
        return d / name, "cache"
    so = _compile(cc, source, flags)
    path = write(sub, name, so)
    if path is None:
        path = _private_dir() / name
        atomic_write_text(path, so)
    return path, "compiled"


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
def info() -> dict:
    """{"folder", "entries", "bytes", "by_folder": {sub: (entries, bytes)}, "status"}; an
    entry is a cached file (its sidecar counted in its size)."""
    base = root()
    by = {}
    for sub in SUBFOLDERS:
        d = base / sub
        n = size = 0
        if d.is_dir():
            for p in d.rglob("*"):  # numba: one folder per source file
                if p.is_file():
                    size += p.stat().st_size
                    if not p.name.endswith(_SIDECAR) and not p.name.startswith("."):
                        n += 1
        by[sub] = (n, size)
    return {
        "folder": str(base),
        "entries": sum(v[0] for v in by.values()),
        "bytes": sum(v[1] for v in by.values()),
        "by_folder": by,
        "status": status(),
    }


def clear() -> int:
    """Delete every file in the cache's subfolders (nothing else under the folder); returns
    the number of entries removed.  Libraries already loaded stay usable in running processes."""
    base = root()
    removed = 0
    for sub in SUBFOLDERS:
        d = base / sub
        if not d.is_dir():
            continue
        for p in sorted(d.rglob("*"), reverse=True):
            if p.is_file():
                if not p.name.endswith(_SIDECAR) and not p.name.startswith("."):
                    removed += 1
                p.unlink()
            elif p.is_dir():
                p.rmdir()
    with _LOCK:
        _STATE["fallback"] = None
    return removed
