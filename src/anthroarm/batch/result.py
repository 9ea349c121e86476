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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import atomic_write_text

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
        """Write ``path`` (``.npz``) atomically: a reader sees the old file or the whole new one."""
        path = Path(path)
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


def load(path) -> BatchResult:
    """Read a file written by :meth:`BatchResult.save`."""
    with np.load(Path(path), allow_pickle=False) as z:
        if "__meta__" not in z.files:
            raise ValueError(f"{path}: not an anthroarm batch result (no __meta__ entry)")
        meta = json.loads(bytes(z["__meta__"]).decode())
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path}: format {meta.get('format')!r}, expected {FORMAT!r}")
        variables = {k: (tuple(d), z[k]) for k, d in meta["dims"].items()}
        coords = {f[6:]: z[f] for f in z.files if f.startswith("coord:")}
    return BatchResult(meta["job"], variables, coords, meta["attrs"])
