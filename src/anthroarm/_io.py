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

Reading files safely: :func:`read_bounded`, :func:`load_json_bounded` and
:func:`check_regular_file` (for a path handed to a library that opens it itself) are the readers'
side (C3D, joint CSV and marker-set JSON of :mod:`anthroarm.motion`; meant for every reader of a
user's file: teach programs, catalogues, batch results).  They read **regular files only** (a
folder, ``/dev/zero``, a FIFO or a socket is refused without being read: a FIFO is opened
non-blocking, so a reader never waits for a writer), at most ``max_bytes`` (checked on the size
before reading, and again on the bytes read, in case the file grows), and, for JSON, at most
``max_depth`` nested arrays/objects, checked on the text before :func:`json.loads` runs (a deep
document would otherwise raise :class:`RecursionError`). Each takes ``error``, a callable
``error(problem) -> Exception`` that builds the caller's typed error (e.g. ``lambda problem:
MotionDataError(problem, path)``): the problems it is given say what is wrong and name the bound,
the caller's error names the file.

XML (URDF, ``.osim``, OpenSim setups, COLLADA meshes): :func:`parse_xml` is the one parser every
reader uses — a DTD or entity declaration refused before parsing, no entity resolution, no
network, no DTD loading, no huge trees.
"""

from __future__ import annotations

import errno
import glob
import json
import os
import re
import secrets
import stat
import threading
from collections.abc import Callable
from pathlib import Path

from lxml import etree

from .errors import ParameterError

#: the default nesting bound of :func:`load_json_bounded` (arrays and objects, counted together)
MAX_JSON_DEPTH = 64


def atomic_write_text(path, text: str | bytes) -> None:
    """Write ``text`` (str as UTF-8, or bytes) to ``path`` atomically: a temp file in the same
    folder, flushed to disk, then ``os.replace``, so a reader sees the old file or the new one,
    never a partial one; the temp file is removed on failure.  The folder must exist
    (``FileNotFoundError``; ``NotADirectoryError`` when a part of it is a file); a ``path`` that
    is a folder raises ``IsADirectoryError``, one that is a device, FIFO or socket
    ``OSError(EINVAL)``: neither is replaced.  Both messages name the path and say what to
    give instead.  A ``path`` that is not a path, or ``text`` that is neither str nor bytes,
    raises :class:`~anthroarm.errors.ParameterError`."""
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


def read_bounded(
    path,
    max_bytes: int,
    *,
    error: Callable[[str], Exception],
    what: str = "file",
    encoding: str | None = "utf-8",
) -> str | bytes:
    """The content of the regular file ``path``: text decoded with ``encoding`` (bytes when
    ``encoding`` is None).  Raises ``error(problem)`` when the file does not exist, is not a
    regular file (a folder, a device such as ``/dev/zero``, a FIFO, a socket; a symlink is
    followed), is larger than ``max_bytes``, cannot be read (the OS error's text) or decoded.
    A FIFO is opened with ``O_NONBLOCK`` and refused without waiting for a writer.  ``what``
    names the kind of file in the problems (``"C3D file"``: "C3D file not found")."""
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise error(f"{what} not found") from None
    except IsADirectoryError:
        raise error("is a folder, not a file") from None
    except OSError as exc:
        raise error(f"cannot open the file ({exc.strerror or exc})") from None
    try:
        st = os.fstat(fd)
        _check_regular(st, max_bytes, error, what)
        chunks, left = [], max_bytes + 1
        while left > 0:
            b = os.read(fd, min(left, 1 << 20))
            if not b:
                break
            chunks.append(b)
            left -= len(b)
    except OSError as exc:
        raise error(f"cannot read the file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > max_bytes:
        raise error(f"the file grew beyond {max_bytes} bytes while being read (the bound)")
    if encoding is None:
        return data
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise error(f"not {encoding} text ({exc})") from None


def check_regular_file(
    path, max_bytes: int, *, error: Callable[[str], Exception], what: str = "file"
) -> int:
    """The size of the regular file ``path`` (bytes), for a reader that hands the path to a
    library (ezc3d): ``error(problem)`` as :func:`read_bounded` for a missing file, a file that
    is not a regular file, or one larger than ``max_bytes``.  Nothing is opened."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise error(f"{what} not found") from None
    except OSError as exc:
        raise error(f"cannot read the file ({exc.strerror or exc})") from None
    _check_regular(st, max_bytes, error, what)
    return st.st_size


def _check_regular(st: os.stat_result, max_bytes: int, error, what: str) -> None:
    if stat.S_ISDIR(st.st_mode):
        raise error("is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        kind = (
            "a device"
            if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
            else "a FIFO"
            if stat.S_ISFIFO(st.st_mode)
            else "a socket"
            if stat.S_ISSOCK(st.st_mode)
            else "not a regular file"
        )
        raise error(f"is {kind}, not a regular file: give the path of a {what}")
    if st.st_size > max_bytes:
        raise error(f"the file has {st.st_size} bytes, more than the bound of {max_bytes} bytes")


def json_depth(text: str) -> int:
    """The deepest nesting of arrays and objects in the JSON ``text`` (brackets inside strings
    are not counted), by one linear scan, without parsing."""
    depth = deepest = 0
    in_str = esc = False
    for ch in text:
        if in_str:
            if esc:
                esc = False
            elif ch == "\\":
                esc = True
            elif ch == '"':
                in_str = False
        elif ch == '"':
            in_str = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


def load_json_bounded(
    path,
    max_bytes: int,
    *,
    error: Callable[[str], Exception],
    what: str = "file",
    max_depth: int = MAX_JSON_DEPTH,
):
    """The JSON document in the regular file ``path`` (UTF-8): :func:`read_bounded`, then the
    nesting depth checked against ``max_depth`` (:func:`json_depth`) before :func:`json.loads`.
    ``error(problem)`` also for a document nested deeper than ``max_depth`` and for text that is
    not JSON (the decoder's message, with the line and column)."""
    text = read_bounded(path, max_bytes, error=error, what=what)
    opening = text.count("[") + text.count("{")  # no deeper than the brackets it has
    d = json_depth(text) if opening > max_depth else opening
    if d > max_depth:
        raise error(
            f"JSON nested {d} levels deep, more than the bound of {max_depth} "
            "(arrays and objects inside each other)"
        )
    try:
        return json.loads(text)
    except ValueError as exc:  # JSONDecodeError, and ints beyond Python's digit limit
        raise error(f"not a JSON {what} ({exc})") from None


#: a DTD or entity declaration (``<!DOCTYPE``, ``<!ENTITY``): refused before any parsing
DTD_OR_ENTITY = re.compile(rb"<!(?:DOCTYPE|ENTITY)", re.IGNORECASE)


def parse_xml(raw: bytes, error, what: str = "file", keep_comments: bool = False):
    """The root element of the XML text ``raw``, parsed safely.

    A DTD or entity declaration anywhere in the text (entity expansion — the "billion laughs" —
    and external entities) is refused before parsing, with ``error(problem, line)``; so is
    malformed XML (lxml's message and line).  The parser resolves no entity, loads no DTD, opens
    no network resource and refuses huge trees; comments are dropped unless ``keep_comments``.
    ``error(problem, line)`` builds the caller's typed error (``line`` may be None); ``what``
    names the document in the problem ("a URDF", "a model")."""
    m = DTD_OR_ENTITY.search(raw)
    if m:
        raise error(
            f"DTD/entity declarations are not allowed in {what} (entity expansion or external "
            "entity)",
            raw[: m.start()].count(b"\n") + 1,
        )
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=not keep_comments,
    )
    try:
        return etree.fromstring(raw, parser)
    except etree.XMLSyntaxError as exc:
        raise error(f"malformed XML: {exc.msg}", getattr(exc, "lineno", None)) from None
