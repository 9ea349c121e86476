"""Writing files safely: the one atomic write every module uses (URDF export, HTML export,
benchmark tables, the disk cache of :mod:`anthroarm.cache`).

**Guarantees** (tested in ``tests/adversarial/test_file_faults.py``): a reader of the target sees
its old content or the complete new content, never a part, whatever happens to the writer (an
exception, a full disk, a read-only file system, ``SIGKILL`` mid-write); a target that is a
folder, a device, a FIFO or a socket is never replaced; on any error the target is untouched
and the exception (an :class:`OSError` naming the path) propagates.

**Temp files.**  The new content is written to ``.NAME.PID.THREAD.RANDOM.tmp`` in the target's
folder.  An exception removes it.  A writer killed with ``SIGKILL`` cannot, so its temp file may
stay: it is hidden, no reader opens it (the cache counts and serves only its own entries), and
the next :func:`atomic_write_text` to the same target deletes the temp files of writers whose
process no longer exists.
"""

from __future__ import annotations

import errno
import glob
import os
import secrets
import stat
import threading
from pathlib import Path


def atomic_write_text(path, text: str | bytes) -> None:
    """Write ``text`` (str as UTF-8, or bytes) to ``path`` atomically: a temp file in the same
    folder, flushed to disk, then ``os.replace``, so a reader sees the old file or the new one,
    never a partial one; the temp file is removed on failure.  The folder must exist
    (``FileNotFoundError``; ``NotADirectoryError`` when a part of it is a file); a ``path`` that
    is a folder raises ``IsADirectoryError``, one that is a device, FIFO or socket
    ``OSError(EINVAL)``: neither is replaced.  Both messages name the path and say what to
    give instead.  A ``path`` that is not a path, or ``text`` that is neither str nor bytes,
    raises :class:`~anthroarm.errors.ParameterError`."""
    from .errors import ParameterError

    if not isinstance(path, (str, os.PathLike)) or (isinstance(path, str) and not path):
        raise ParameterError(
            f"atomic_write_text: path must be a file path (str or os.PathLike), "
            f"got {type(path).__name__} {path!r}"
        )
    if not isinstance(text, (str, bytes, bytearray, memoryview)):
        # bytes(5) would silently write five NUL bytes
        raise ParameterError(
            f"atomic_write_text: text must be str or bytes, got {type(text).__name__} "
            f"(writing {os.fspath(path)!r})"
        )
    path = Path(path)
    data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
    parent = path.parent
    if not parent.is_dir():
        if parent.exists() or any(p.is_file() for p in parent.parents):
            raise NotADirectoryError(
                errno.ENOTDIR, f"{parent} is not a folder (cannot write {path.name})", str(path)
            )
        raise FileNotFoundError(f"folder {parent} does not exist (cannot write {path.name})")
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    if mode is not None and stat.S_ISDIR(mode):
        raise IsADirectoryError(
            errno.EISDIR,
            f"is a folder, not a file (left unchanged); give a file name, e.g. {path / 'NAME'}",
            str(path),
        )
    if mode is not None and not stat.S_ISREG(mode):
        raise OSError(
            errno.EINVAL,
            "is not a regular file (a device, FIFO or socket; left unchanged); "
            "give the path of a regular file",
            str(path),
        )
    _remove_stale_temps(path)
    tmp = path.with_name(
        f".{path.name}.{os.getpid()}.{threading.get_ident()}.{secrets.token_hex(4)}.tmp"
    )
    try:
        fd = os.open(
            tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666
        )  # the umask applies, as for open()
    except OSError as exc:
        raise _naming(exc, path) from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        raise _naming(exc, path) from None
    finally:
        if os.path.lexists(tmp):
            os.unlink(tmp)


def _naming(exc: OSError, path: Path) -> OSError:
    """The same error (same errno, so the same OSError subclass) naming the target, not the
    temp file."""
    return OSError(exc.errno, exc.strerror or str(exc), str(path)) if exc.errno else exc


def _remove_stale_temps(path: Path) -> None:
    """Delete ``.NAME.PID.*.tmp`` temp files of ``path`` left by writers that were killed
    (their process no longer exists); best effort, never raises."""
    pattern = str(path.with_name(glob.escape(f".{path.name}.") + "*.tmp"))
    for t in glob.glob(pattern):
        rest = os.path.basename(t)[len(path.name) + 2 :].split(".")
        if len(rest) != 4 or not rest[0].isdigit():
            continue
        pid = int(rest[0])
        if pid == os.getpid():
            continue
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            try:
                os.unlink(t)
            except OSError:
                pass
        except (PermissionError, OverflowError, OSError):
            pass  # alive (another user's) or not a pid: leave it
