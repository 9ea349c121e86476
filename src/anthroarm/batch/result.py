"""Batch results: numpy arrays with named axes and metadata, saved atomically as ``.npz``.

Why not xarray: the results are a handful of dense arrays on regular grids (voxels, people,
targets); a small container that names each array's dimensions and carries the coordinates
and the job's parameters covers what the jobs and plots need, loads with plain numpy anywhere
(``np.load``: one array per variable, coordinates as ``coord:<dim>``, metadata as JSON in
``__meta__``), and keeps xarray, a NetCDF engine and their import time off every worker.
:meth:`BatchResult.to_xarray` converts for those who have xarray installed.
"""

from __future__ import annotations

import io
import json
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import atomic_write_text, json_depth, read_bounded
from .errors import BatchParameterError, BatchResultError

FORMAT = "anthroarm.batch/1"


@dataclass
class BatchResult:
    """``variables``: name → (dims tuple, array); ``coords``: dim → 1-D coordinate array
    (units in ``attrs["units"]``); ``attrs``: the job's parameters (JSON-serialisable)."""

    job: str
    variables: dict = field(default_factory=dict)
    coords: dict = field(default_factory=dict)
    attrs: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.variables[name][1]

    def dims(self, name: str) -> tuple:
        return self.variables[name][0]

    def __repr__(self) -> str:
        v = ", ".join(f"{k}{tuple(d)}:{a.shape}" for k, (d, a) in self.variables.items())
        return f"BatchResult({self.job!r}: {v})"

    def equals(self, other: "BatchResult") -> bool:
        """Bitwise equality of every variable and coordinate (NaN equal to NaN)."""
        if (
            self.job != other.job
            or set(self.variables) != set(other.variables)
            or set(self.coords) != set(other.coords)
        ):
            return False
        for k, (d, a) in self.variables.items():
            d2, b = other.variables[k]
            if tuple(d) != tuple(d2) or not np.array_equal(a, b, equal_nan=a.dtype.kind == "f"):
                return False
        return all(np.array_equal(v, other.coords[k]) for k, v in self.coords.items())

    def problem(self) -> str:
        """What makes this result inconsistent ('' when nothing): a variable whose array has
        not one axis per dimension, a coordinate that is not 1-D, or a dimension whose length
        differs between arrays or from its coordinate."""
        size = {}
        for k, v in self.coords.items():
            if np.ndim(v) != 1:
                return f"coordinate {k!r} must be 1-D, got shape {np.shape(v)}"
            size[k] = (len(v), f"coordinate {k!r}")
        for name, (dims, a) in self.variables.items():
            if np.ndim(a) != len(dims):
                return (
                    f"variable {name!r} has shape {np.shape(a)} but {len(dims)} dimensions "
                    f"{tuple(dims)}"
                )
            for d, m in zip(dims, np.shape(a)):
                if d in size and size[d][0] != m:
                    return (
                        f"dimension {d!r} of variable {name!r} has length {m}, but "
                        f"{size[d][1]} has length {size[d][0]}"
                    )
                size.setdefault(d, (m, f"variable {name!r}"))
        return ""

    # ------------------------------------------------------------------ files
    def to_bytes(self) -> bytes:
        arrays = {k: a for k, (_, a) in self.variables.items()}
        arrays.update({f"coord:{k}": np.asarray(v) for k, v in self.coords.items()})
        meta = {
            "format": FORMAT,
            "job": self.job,
            "dims": {k: list(d) for k, (d, _) in self.variables.items()},
            "attrs": self.attrs,
        }
        arrays["__meta__"] = np.frombuffer(json.dumps(meta, default=_json).encode(), dtype=np.uint8)
        buf = io.BytesIO()
        np.savez_compressed(buf, **arrays)
        return buf.getvalue()

    def save(self, path) -> Path:
        """Write ``path`` (``.npz``) atomically: a reader sees the old file or the whole new one.
        A path not ending in ``.npz`` and an inconsistent result (:meth:`problem`) raise
        :class:`~anthroarm.batch.errors.BatchParameterError` before anything is written."""
        path = check_suffix(path)
        problem = self.problem()
        if problem:
            raise BatchParameterError(f"{path}: not saved, the result is inconsistent: {problem}")
        atomic_write_text(path, self.to_bytes())
        return path

    def to_xarray(self):
        """An ``xarray.Dataset`` (needs xarray, which anthroarm does not depend on)."""
        import xarray as xr

        return xr.Dataset(
            {k: (d, a) for k, (d, a) in self.variables.items()},
            coords=self.coords,
            attrs={k: json.dumps(v, default=_json) for k, v in self.attrs.items()},
        )


def _json(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"not JSON-serialisable: {type(x).__name__}")


#: the largest result file :func:`load` reads, and the most bytes its arrays may take once
#: decompressed (bytes; the jobs' outputs are bounded by the same 4 GiB,
#: :data:`anthroarm.batch.limits.MEMORY_BUDGET`)
MAX_FILE_BYTES = 4 * 2**30
#: the deepest nesting of the ``__meta__`` JSON accepted
MAX_META_DEPTH = 32
#: the suffix of a result file
SUFFIX = ".npz"


def check_suffix(path, what: str = "result file") -> Path:
    """``path`` as a Path; :class:`~anthroarm.batch.errors.BatchParameterError` unless it ends
    in ``.npz`` (a result is a zip of numpy arrays: ``r.txt`` would hold a zip under a text
    name)."""
    p = Path(path)
    if p.suffix.lower() != SUFFIX:
        raise BatchParameterError(
            f"{p}: a batch {what} is a .npz file (a zip of numpy arrays), not "
            f"{p.suffix or 'a name without a suffix'}: give {p.with_suffix(SUFFIX).name}"
        )
    return p


def load(path, max_bytes: int = MAX_FILE_BYTES) -> BatchResult:
    """Read a file written by :meth:`BatchResult.save`.

    Only a regular file of at most ``max_bytes`` is read (a folder, ``/dev/zero`` or a FIFO is
    refused unread); object arrays are never unpickled.  Anything that is not a whole, valid
    result (not a zip, a damaged or truncated entry, metadata that is not the format's JSON,
    a variable without its array, an array whose shape does not match its dimensions or its
    coordinates) raises :class:`~anthroarm.batch.errors.BatchResultError` naming the file and
    what is wrong."""

    def bad(problem):
        return BatchResultError(problem, path)

    data = read_bounded(path, max_bytes, error=bad, what="batch result file", encoding=None)
    try:
        zf = zipfile.ZipFile(io.BytesIO(data))
        infos = zf.infolist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError) as exc:
        raise bad(f"not a batch result (.npz is a zip file; {exc})") from None
    total = sum(i.file_size for i in infos)
    if total > max_bytes:
        raise bad(f"its arrays would take {total} bytes decompressed, more than {max_bytes}")
    if data[:4] not in (b"PK\x03\x04", b"PK\x05\x06"):
        raise bad("not a batch result (a zip with data before its first entry)")
    with np.load(io.BytesIO(data), allow_pickle=False) as z:
        entry = _entry_reader(z, bad)
        if "__meta__" not in z.files:
            raise bad("not an anthroarm batch result (no __meta__ entry)")
        meta = _meta(entry("__meta__"), bad)
        variables = {}
        for k, d in meta["dims"].items():
            if k not in z.files:
                raise bad(f"variable {k!r} is named in the metadata but has no array")
            variables[k] = (tuple(d), entry(k))
        coords = {f[6:]: entry(f) for f in z.files if f.startswith("coord:")}
    result = BatchResult(meta["job"], variables, coords, meta["attrs"])
    problem = result.problem()
    if problem:
        raise bad(problem)
    return result


def _entry_reader(z, bad):
    def entry(name):
        try:
            return z[name]
        except ValueError as exc:
            if "allow_pickle" in str(exc):
                raise bad(f"entry {name!r} holds Python objects (never unpickled)") from None
            raise bad(f"entry {name!r} is not a numpy array ({exc})") from None
        except (zipfile.BadZipFile, OSError, EOFError, zlib.error, KeyError) as exc:
            raise bad(f"entry {name!r} is damaged ({type(exc).__name__}: {exc})") from None

    return entry


def _meta(raw, bad) -> dict:
    """The ``__meta__`` entry as the format's dict, else ``bad(problem)``."""
    if raw.dtype != np.uint8 or raw.ndim != 1:
        raise bad(f"__meta__ must be UTF-8 JSON bytes, got {raw.dtype} of shape {raw.shape}")
    try:
        text = bytes(raw).decode()
    except UnicodeDecodeError as exc:
        raise bad(f"__meta__ is not UTF-8 ({exc})") from None
    if json_depth(text) > MAX_META_DEPTH:
        raise bad(f"__meta__ JSON is nested more than {MAX_META_DEPTH} levels deep")
    try:
        meta = json.loads(text)
    except ValueError as exc:
        raise bad(f"__meta__ is not JSON ({exc})") from None
    if not isinstance(meta, dict):
        raise bad(f"__meta__ must be a JSON object, got {type(meta).__name__}")
    if meta.get("format") != FORMAT:
        raise bad(f"format {meta.get('format')!r}, expected {FORMAT!r}")
    job, dims, attrs = meta.get("job"), meta.get("dims"), meta.get("attrs")
    if not isinstance(job, str):
        raise bad(f"__meta__ 'job' must be a name, got {job!r}")
    if not isinstance(attrs, dict):
        raise bad(f"__meta__ 'attrs' must be an object, got {type(attrs).__name__}")
    if not isinstance(dims, dict) or not all(
        isinstance(d, list) and all(isinstance(x, str) for x in d) for d in dims.values()
    ):
        raise bad("__meta__ 'dims' must map each variable to a list of dimension names")
    return meta
