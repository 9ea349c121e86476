"""Safe reading of an OpenSim ``.osim`` file into lxml elements, and the small readers of its
values (numbers, vectors, booleans) that name the element and its line when a value is bad.

The file is read bounded (a regular file of at most :data:`MAX_OSIM_BYTES`), refused if it
declares a DTD or an entity (entity expansion, external entities: the attacks
:func:`anthroarm.urdf_io.parse_urdf_bytes` refuses in a URDF), and parsed by lxml without
entity resolution, network or DTD loading.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .._io import parse_xml, read_bounded
from ..errors import OsimError, OsimSecurityError, OsimUnsupportedError

#: the largest file accepted (the largest model of opensim-models is ~2.5 MB)
MAX_OSIM_BYTES = 64 * 2**20

_SCOPED = re.compile(rb"(</?[A-Za-z_][\w.-]*)::")


def parse(path) -> tuple:
    """(the ``<Model>`` element, the document's version number) of the file ``path``.

    Raises :class:`~anthroarm.errors.OsimError` for a missing file, malformed XML or a root that
    is not an ``<OpenSimDocument>`` holding a ``<Model>``,
    :class:`~anthroarm.errors.OsimSecurityError` for a DTD / entity declaration or an oversized
    file."""
    path = Path(path)

    def error(problem: str) -> Exception:
        if "more than the bound" in problem or "grew beyond" in problem:
            return OsimSecurityError(path, problem)
        return OsimError(path, problem)

    raw = read_bounded(path, MAX_OSIM_BYTES, error=error, what="OpenSim model", encoding=None)
    return parse_bytes(raw, path)


def parse_bytes(raw: bytes, path) -> tuple:
    """:func:`parse` of text already in memory (``path`` names it in messages)."""

    def error(problem: str, line) -> Exception:
        if problem.startswith("DTD"):
            return OsimSecurityError(path, problem, "<!DOCTYPE>/<!ENTITY>", line)
        return OsimError(path, problem, None, line or None)

    # OpenSim writes element names with C++ scopes (<HuntCrossleyForce::ContactParametersSet>),
    # which its own parser reads and XML namespaces refuse: rename them (same lines)
    root = parse_xml(_SCOPED.sub(rb"\1__", raw), error, "a model")
    if root.tag != "OpenSimDocument":
        raise OsimError(
            path,
            "root element is not <OpenSimDocument>: not an OpenSim model",
            f"<{root.tag}>",
            root.sourceline,
        )
    try:
        version = int(root.get("Version", "0"))
    except ValueError:
        raise OsimError(
            path, f"Version={root.get('Version')!r} is not a number", "<OpenSimDocument>", 1
        ) from None
    model = root.find("Model")
    if model is None:
        raise OsimError(path, "no <Model> in the document", "<OpenSimDocument>", root.sourceline)
    if version < 30000:
        raise OsimUnsupportedError(
            path, f"OpenSim document version {version} is not a 3.x or 4.x model"
        )
    return model, version


class Values:
    """Readers of an element's child values that raise :class:`~anthroarm.errors.OsimError`
    naming ``what`` (the component) and the line."""

    def __init__(self, path):
        self.path = path

    def error(self, el, what: str, problem: str, cls=OsimError) -> Exception:
        line = el.sourceline if el is not None else None
        return cls(self.path, problem, what, line)

    def text(self, el, tag: str, default: str | None = None) -> str | None:
        c = el.find(tag)
        if c is None or c.text is None:
            return default
        return c.text.strip()

    def floats(self, el, tag: str, what: str, n: int | None = None, default=None) -> np.ndarray:
        c = el.find(tag)
        if c is None or c.text is None or not c.text.strip():
            if default is not None:
                return np.array(default, dtype=float)
            if c is None:
                raise self.error(el, what, f"<{tag}> is missing")
            raise self.error(c, what, f"<{tag}> is empty")
        try:
            v = np.array([float(t) for t in c.text.split()], dtype=float)
        except ValueError:
            raise self.error(c, what, f"<{tag}> is not numbers: {c.text.strip()[:60]!r}") from None
        if n is not None and v.size != n:
            raise self.error(c, what, f"<{tag}> has {v.size} numbers, expected {n}")
        if not np.all(np.isfinite(v)):
            raise self.error(c, what, f"<{tag}> holds a non-finite number: {c.text.strip()!r}")
        return v

    def scalar(self, el, tag: str, what: str, default: float | None = None) -> float:
        return float(self.floats(el, tag, what, 1, None if default is None else [default])[0])

    def boolean(self, el, tag: str, what: str, default: bool = False) -> bool:
        t = self.text(el, tag)
        if t is None or t == "":
            return default
        t = t.lower()
        if t in ("true", "1"):
            return True
        if t in ("false", "0"):
            return False
        raise self.error(el.find(tag), what, f"<{tag}> is {t!r}, expected true or false")
