"""Writing files safely: the one atomic write every module uses (URDF export, HTML export,
benchmark tables, the disk cache of :mod:`anthroarm.cache`)."""

from __future__ import annotations

import os
import secrets
import threading
from pathlib import Path


def atomic_write_text(path, text: str | bytes) -> None:
    """Write ``text`` (str as UTF-8, or bytes) to ``path`` atomically: a temp file in the same
    folder, flushed to disk, then ``os.replace``, so a reader sees the old file or the new one,
    never a partial one; the temp file is removed on failure.  The folder must exist
    (``FileNotFoundError``)."""
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"folder {path.parent} does not exist (cannot write {path.name})")
    data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.{secrets.token_hex(4)}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)   # the umask applies, as for open()
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
