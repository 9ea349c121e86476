"""OpenSim's storage files (``.mot`` motions, ``.sto`` storages), read and written.

A storage file is a header that ends with a line ``endheader``, a line of column labels (the
first is ``time``) and rows of numbers (OpenSim's ``Storage`` class and its ``STOFileAdapter``,
opensim-core ``OpenSim/Common/Storage.cpp``, ``STOFileAdapter.cpp``)::

    Coordinates
    version=1
    nRows=73
    nColumns=24
    inDegrees=yes
    endheader
    time    pelvis_tilt    pelvis_list ...
    0.40    5.186          -1.887 ...

Header lines of the form ``key=value`` are kept (``nRows`` and ``nColumns`` are checked against
the data when present, ``inDegrees`` must be ``yes`` or ``no``); other header lines are a
description (the first is the table's name in older files).  Labels and cells are separated by
tabs, or by spaces in files without tabs.  ``nan`` (and an empty cell of a tab-separated file)
is a gap.  Angles are in degrees when ``inDegrees=yes``: which columns are angles the file does
not say (``pelvis_tx`` is in m either way), so :meth:`StorageTable.to_q` converts by the joint
kinds of a robot and :meth:`StorageTable.si` by a list of angle columns.

Bad input is a :class:`~anthroarm.errors.MotionDataError` naming the file and the line: no
``endheader``, a label line that does not start with ``time``, duplicate labels, ``inDegrees``
other than yes/no, ``nColumns`` or ``nRows`` that disagree with the data (``partial=True`` reads
a file with fewer or more rows than ``nRows``: ``status`` says which), a ragged row, a cell that
is not a number, an infinite value, time that decreases.  Only a regular file of at most
:data:`MAX_STORAGE_BYTES` is read.

:func:`write_mot` writes a motion that OpenSim reads back (``opensim.Storage``,
``opensim.TimeSeriesTable``): joint values from an array or a marker-IK result, angles in
degrees (``inDegrees=yes``, OpenSim's convention for ``.mot``) or radians.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import atomic_write_text, read_bounded
from ..errors import MotionDataError
from .osim_ik import rotational_coordinates

#: the largest storage file :func:`read_storage` reads, bytes (256 MiB)
MAX_STORAGE_BYTES = 256 << 20
#: header lines read before ``endheader`` must have appeared
MAX_HEADER_LINES = 10_000

_KEY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.*?)\s*$")


@dataclass
class StorageTable:
    """The columns of a storage file (``.mot`` / ``.sto``).

    Attributes
    ----------
    labels : tuple of str
        Column labels after ``time``.
    time : (N,) array
        s.
    values : (N, C) array
        As written in the file (degrees for angle columns when ``in_degrees``); NaN for gaps.
    in_degrees : bool or None
        The header's ``inDegrees`` (None when the file does not say).
    name : str
        The table's name (the first header line of a ``.mot``), or ``""``.
    header : dict
        ``key=value`` header lines, as text.
    description : tuple of str
        The other header lines.
    source : str
    status : str
        ``"complete"``, or ``"truncated"`` / ``"extra_rows"`` for a partial read.
    """

    labels: tuple
    time: np.ndarray
    values: np.ndarray
    in_degrees: bool | None = None
    name: str = ""
    header: dict = field(default_factory=dict)
    description: tuple = ()
    source: str = "<array>"
    status: str = "complete"

    def __len__(self) -> int:
        return self.time.shape[0]

    def __repr__(self) -> str:
        return (
            f"StorageTable({self.name!r}, {len(self)} rows, {len(self.labels)} columns, "
            f"in_degrees={self.in_degrees}, source={self.source!r})"
        )

    def _path(self):
        return None if self.source == "<array>" else self.source

    def column(self, label: str) -> np.ndarray:
        """(N,) values of one column, as in the file."""
        if label not in self.labels:
            raise MotionDataError(
                f"no column {label!r}; columns: {', '.join(self.labels)}", self._path()
            )
        return self.values[:, self.labels.index(label)]

    def si(self, angles=()) -> np.ndarray:
        """(N, C) values with the columns named in ``angles`` in radians (converted from degrees
        when ``in_degrees``); the other columns as in the file."""
        angles = set(angles)
        unknown = sorted(angles - set(self.labels))
        if unknown:
            raise MotionDataError(f"no columns {unknown} in the table", self._path())
        out = self.values.copy()
        if self.in_degrees:
            cols = [i for i, lab in enumerate(self.labels) if lab in angles]
            out[:, cols] = np.deg2rad(out[:, cols])
        return out

    def to_q(self, robot, *, default=None) -> np.ndarray:
        """(N, nq) configurations of ``robot``: each coordinate's value from the column named
        after it (rad or m; an angle column is converted from degrees when ``in_degrees``;
        the angles are :func:`~anthroarm.motion.osim_ik.rotational_coordinates`).  A coordinate
        without a column takes ``default`` (a (nq,) configuration) when given; otherwise its
        absence is a :class:`~anthroarm.errors.MotionDataError` listing the coordinates.
        Continuous joints (cos, sin in q) are set from their angle."""
        q = np.tile(robot.neutral() if default is None else robot.check_q(default), (len(self), 1))
        absent = []
        for name, i, angle, continuous in coordinate_columns(robot):
            if name not in self.labels:
                absent.append(name)
                continue
            v = self.column(name).astype(float)
            if self.in_degrees and angle:
                v = np.deg2rad(v)
            if continuous:
                q[:, i], q[:, i + 1] = np.cos(v), np.sin(v)
            else:
                q[:, i] = v
        if absent and default is None:
            raise MotionDataError(
                f"no columns for coordinates {absent} of {robot.name} (columns: "
                f"{', '.join(self.labels)}); pass default= a configuration for them",
                self._path(),
            )
        return q


def coordinate_columns(robot) -> list[tuple[str, int, bool, bool]]:
    """(name, index in q, is an angle, is continuous) of each coordinate of ``robot``: the
    independent coordinates of a model with a coupling map (``robot.coupling``), otherwise
    the joints of ``robot.chain`` with one degree of freedom."""
    angles = set(rotational_coordinates(robot))
    if getattr(robot, "coupling", None) is not None:
        return [(n, i, n in angles, False) for i, n in enumerate(robot.joint_names)]
    return [
        (j.name, j.idx_q, j.name in angles, j.nq == 2)
        for j in robot.chain.joints
        if not j.is_mimic and j.nv == 1
    ]


def _split(line: str, tabs: bool) -> list[str]:
    line = line.rstrip("\r\n")
    if tabs:
        cells = [c.strip() for c in line.split("\t")]
        while cells and cells[-1] == "":
            cells.pop()
        return cells
    return line.split()


def read_storage(path, *, partial: bool = False) -> StorageTable:
    """The table of an OpenSim ``.mot`` or ``.sto`` file.

    Parameters
    ----------
    path : str or os.PathLike
    partial : bool
        Read a file whose row count differs from its ``nRows`` instead of refusing it.

    Returns
    -------
    StorageTable

    Raises
    ------
    MotionDataError
        As listed in the module docstring, naming the file and the line.

    References
    ----------
    OpenSim ``Storage`` and ``STOFileAdapter`` (opensim-core, ``OpenSim/Common/Storage.cpp``,
    ``STOFileAdapter.cpp``): the header up to ``endheader``, ``inDegrees``, the labels line.
    """
    if not isinstance(path, (str, os.PathLike)) or path == "":
        raise MotionDataError(f"read_storage: path must be a file path, got {type(path).__name__}")
    p = Path(path)
    text = read_bounded(
        p, MAX_STORAGE_BYTES, what="storage file", error=lambda problem: MotionDataError(problem, p)
    )
    lines = text.split("\n")
    end = next(
        (i for i, ln in enumerate(lines[:MAX_HEADER_LINES]) if ln.strip().lower() == "endheader"),
        None,
    )
    if end is None:
        raise MotionDataError(
            "no 'endheader' line: not an OpenSim storage file (.mot/.sto: a header ending with "
            "'endheader', then the column labels)",
            p,
        )
    header, description, key_line = {}, [], {}
    for i, ln in enumerate(lines[:end]):
        m = _KEY.match(ln)
        if m:
            header[m.group(1)] = m.group(2)
            key_line[m.group(1)] = i + 1
        elif ln.strip():
            description.append(ln.strip())
    in_degrees = None
    if "inDegrees" in header:
        v = header["inDegrees"].strip().lower()
        if v not in ("yes", "no"):
            raise MotionDataError(
                f"line {key_line['inDegrees']}: inDegrees is {header['inDegrees']!r}: "
                "'yes' or 'no'",
                p,
            )
        in_degrees = v == "yes"
    k = end + 1
    while k < len(lines) and not lines[k].strip():
        k += 1
    if k >= len(lines):
        raise MotionDataError(f"no column labels after 'endheader' (line {end + 1})", p)
    tabs = "\t" in lines[k]
    labels = _split(lines[k], tabs)
    label_line = k + 1
    if not labels or labels[0].lower() != "time":
        raise MotionDataError(
            f"line {label_line}: the first column should be 'time', got "
            f"{labels[0] if labels else ''!r}",
            p,
        )
    dup = sorted({s for s in labels if labels.count(s) > 1})
    if dup or "" in labels:
        raise MotionDataError(
            f"line {label_line}: column labels {dup or ['(empty)']} "
            f"{'appear twice' if dup else 'must not be empty'}",
            p,
        )
    if "nColumns" in header:
        try:
            nc = int(header["nColumns"])
        except ValueError:
            nc = None
        if nc != len(labels):
            raise MotionDataError(
                f"line {key_line['nColumns']}: nColumns is {header['nColumns']!r}, line "
                f"{label_line} has {len(labels)} labels (time included)",
                p,
            )
    width = len(labels)
    rows, linenos = [], []
    for i in range(label_line, len(lines)):
        ln = lines[i]
        if not ln.strip():
            continue
        cells = _split(ln, tabs)
        if len(cells) != width:
            raise MotionDataError(
                f"line {i + 1}: {len(cells)} cells, expected {width} (one per label of line "
                f"{label_line}): a ragged row",
                p,
            )
        row = np.empty(width)
        for c, cell in enumerate(cells):
            if cell == "":
                row[c] = np.nan
                continue
            try:
                row[c] = float(cell)
            except ValueError:
                raise MotionDataError(
                    f"line {i + 1}: column {labels[c]!r} is {cell!r}, not a number", p
                ) from None
            if np.isinf(row[c]):
                raise MotionDataError(
                    f"line {i + 1}: column {labels[c]!r} is {cell!r}: values must be finite "
                    "(nan for a gap)",
                    p,
                )
        if not np.isfinite(row[0]):
            raise MotionDataError(f"line {i + 1}: time is {cells[0]!r}, not a number", p)
        if rows and row[0] < rows[-1][0]:
            raise MotionDataError(
                f"line {i + 1}: time {row[0]:g} s decreases (line {linenos[-1]}: "
                f"{rows[-1][0]:g} s)",
                p,
            )
        rows.append(row)
        linenos.append(i + 1)
    status = "complete"
    if "nRows" in header:
        try:
            nr = int(header["nRows"])
        except ValueError:
            raise MotionDataError(
                f"line {key_line['nRows']}: nRows is {header['nRows']!r}, not a whole number", p
            ) from None
        if nr != len(rows):
            if not partial:
                raise MotionDataError(
                    f"line {key_line['nRows']}: nRows is {nr}, the file holds {len(rows)} rows; "
                    "read_storage(..., partial=True) reads the rows it holds",
                    p,
                )
            status = "truncated" if len(rows) < nr else "extra_rows"
    data = np.array(rows).reshape(len(rows), width)
    name = description[0] if description and not lines[0].strip().count("=") else ""
    return StorageTable(
        labels=tuple(labels[1:]),
        time=data[:, 0].copy(),
        values=data[:, 1:].copy(),
        in_degrees=in_degrees,
        name=name,
        header=header,
        description=tuple(description),
        source=str(p),
        status=status,
    )


def _fmt(v: float) -> str:
    return "nan" if not np.isfinite(v) else repr(float(v))


def write_mot(
    path,
    time,
    values=None,
    labels=None,
    *,
    robot=None,
    in_degrees: bool = True,
    angles=None,
    name: str = "Coordinates",
) -> Path:
    """Write joint values as an OpenSim motion (``.mot``) that OpenSim reads back.

    ``write_mot(path, result, robot=robot)`` writes a marker-IK result
    (:class:`~anthroarm.motion.marker_ik.MarkerIKResult`: its ``time``, and its ``q`` with one
    column per joint of ``robot`` named after the joint, as OpenSim names coordinates);
    ``write_mot(path, time, values, labels, angles=[...])`` writes columns given in SI units
    (rad, m).  With ``in_degrees`` (default, OpenSim's convention for ``.mot``) the angle
    columns — the revolute joints of ``robot``, or the labels in ``angles`` — are written in
    degrees and the header says ``inDegrees=yes``.  Every value must be finite: OpenSim's
    ``Storage`` (its GUI's motion loader) stops reading at a row with ``nan``.
    Atomic (:func:`anthroarm._io.atomic_write_text`).

    Raises
    ------
    MotionDataError
        Shapes that disagree, time not finite or decreasing, a value that is not finite, labels that are
        empty, repeated or contain whitespace, an ``angles`` label that is not a column.
    """
    if values is None:
        res = time
        if robot is None:
            raise MotionDataError("write_mot(path, result) needs robot= to name the joints", path)
        cols = coordinate_columns(robot)
        q = np.asarray(res.q, dtype=float)
        time = res.time
        labels = [c[0] for c in cols]
        values = np.column_stack(
            [np.arctan2(q[:, i + 1], q[:, i]) if cont else q[:, i] for _, i, _, cont in cols]
        )
        angles = [c[0] for c in cols if c[2]]
    t = np.asarray(time, dtype=float)
    V = np.asarray(values, dtype=float)
    labels = [str(s) for s in (labels or ())]
    if V.ndim != 2 or t.shape != (V.shape[0],) or len(labels) != V.shape[1]:
        raise MotionDataError(
            f"write_mot: time (N,), values (N, C) and C labels, got {t.shape}, {V.shape}, "
            f"{len(labels)}",
            path,
        )
    if not np.isfinite(t).all() or np.any(np.diff(t) < 0):
        raise MotionDataError("write_mot: time must be finite and not decrease", path)
    if not np.isfinite(V).all():
        bad_row = int(np.flatnonzero(~np.isfinite(V).all(axis=1))[0])
        raise MotionDataError(
            f"write_mot: values must be finite (row {bad_row} is not): OpenSim's Storage, "
            "which its GUI and tools load motions with, stops reading a .mot at a row with nan",
            path,
        )
    bad = [s for s in labels if not s or any(c.isspace() for c in s)]
    dup = sorted({s for s in labels if labels.count(s) > 1})
    if bad or dup or "time" in labels:
        raise MotionDataError(
            f"write_mot: labels must be unique, non-empty, without whitespace and not 'time': "
            f"{bad or dup or ['time']}",
            path,
        )
    angles = set(angles or ())
    unknown = sorted(angles - set(labels))
    if unknown:
        raise MotionDataError(f"write_mot: angles {unknown} are not columns", path)
    if in_degrees:
        cols = [i for i, s in enumerate(labels) if s in angles]
        V = V.copy()
        V[:, cols] = np.rad2deg(V[:, cols])
    head = [
        str(name).replace("\n", " ") or "Coordinates",
        "version=1",
        f"nRows={len(t)}",
        f"nColumns={len(labels) + 1}",
        f"inDegrees={'yes' if in_degrees else 'no'}",
        "",
        "Units are S.I. units (second, meters, Newtons, ...)",
        "Angles are in degrees." if in_degrees else "Angles are in radians.",
        "",
        "endheader",
        "\t".join(["time", *labels]),
    ]
    rows = np.column_stack([t, V]).tolist()
    body = ["\t".join(map(_fmt, r)) for r in rows]
    p = Path(path)
    atomic_write_text(p, "\n".join(head + body) + "\n")
    return p
