"""OpenSim's marker files (``.trc``, "track row column"), read and written.

The format is the one OpenSim's ``TRCFileAdapter`` reads and writes (opensim-core,
``OpenSim/Common/TRCFileAdapter.cpp``; Delp et al. 2007, IEEE TBME 54(11), 1940–1950):
tab-separated text, five header lines and the rows::

    PathFileType  4  (X/Y/Z)  walk.trc
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
    60.00     60.00       151        41          mm     60.00         1                   151
    Frame#  Time  R.ASIS        L.ASIS ...
                  X1  Y1  Z1    X2  Y2  Z2 ...
    (a blank line)
    1  0.000  617.2  1055.3  170.8  639.6 ...

:func:`read_trc` returns :class:`~anthroarm.motion.trial.MarkerTrajectories` in metres, like
:func:`~anthroarm.motion.c3d.read_c3d`: the ``Units`` of the header (``mm``, ``cm``, ``m``) is
converted, the markers keep their labels, the rate is ``DataRate``.  The file's own ``Time``
column (which need not start at 0) is ``meta["time"]`` (s).  A marker with an empty or ``NaN``
cell in a row is missing there (NaN in all three coordinates, as OpenSim reads it), so are
gaps.

Bad input is a :class:`~anthroarm.errors.MotionDataError` naming the file and the line (1-based)
and saying what is wrong: not a TRC file, a header key missing, unknown units, a rate that is
not a positive number, a marker count that disagrees with ``NumMarkers``, ``X1 Y1 Z1`` labels out
of order, a ragged row (more or fewer cells than ``Frame#``, ``Time`` and three per marker), a
cell that is not a number, an infinite coordinate, time that does not increase, a blank line
inside the data, fewer or more rows than ``NumFrames`` (``partial=True`` reads them, with
``meta["status"]`` ``"truncated"`` or ``"extra_frames"``), and a ``Units`` header that the numbers
contradict (the median distance of the markers from the lab origin beyond 100 m, or below 1 cm:
a file in mm labelled ``m``, or the other way round; ``units=`` overrides the header).  Only a
regular file of at most :data:`MAX_TRC_BYTES` is read (:func:`anthroarm._io.read_bounded`).

:func:`write_trc` writes the same format (atomically), missing samples as empty cells, so
OpenSim's ``TRCFileAdapter`` and :func:`read_trc` read it back.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._io import atomic_write_text, read_bounded
from ..errors import MotionDataError
from .c3d import UNITS
from .trial import MarkerTrajectories

#: the largest TRC file :func:`read_trc` reads, bytes (256 MiB: about an hour of 60 markers at
#: 100 Hz); a larger file is a MotionDataError naming the bound
MAX_TRC_BYTES = 256 << 20

#: the header keys :func:`read_trc` needs (OpenSim's adapter requires all eight of
#: :data:`HEADER_KEYS`, in that order; the others are kept in ``meta["header"]`` when present)
REQUIRED_KEYS = ("DataRate", "NumFrames", "NumMarkers", "Units")
HEADER_KEYS = (
    "DataRate",
    "CameraRate",
    "NumFrames",
    "NumMarkers",
    "Units",
    "OrigDataRate",
    "OrigDataStartFrame",
    "OrigNumFrames",
)
#: plausible median distance of the markers from the lab origin, m: outside it the numbers
#: contradict the ``Units`` header
PLAUSIBLE_M = (0.01, 100.0)


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.rstrip("\r\n").split("\t")]


def _number(p, lineno: int, text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise MotionDataError(f"line {lineno}: {what} is {text!r}, not a number", p) from None
    return v


def read_trc(path, *, units: str | None = None, partial: bool = False) -> MarkerTrajectories:
    """Marker trajectories of an OpenSim ``.trc`` file, in metres.

    Parameters
    ----------
    path : str or os.PathLike
    units : str, optional
        Overrides the header's ``Units`` (one of the keys of :data:`anthroarm.motion.c3d.UNITS`),
        for a file whose header is wrong.
    partial : bool
        Read a file whose row count differs from ``NumFrames`` instead of refusing it.

    Returns
    -------
    MarkerTrajectories
        ``meta`` holds ``units``, ``status`` (``"complete"``, ``"truncated"``,
        ``"extra_frames"``), ``time`` ((N,) s, the file's ``Time`` column), ``frames_announced``,
        ``frames_read``, ``header`` (the header keys and values as text), ``partial_samples``
        (samples with one or two empty coordinates, read as missing) and ``first_data_line``.

    Raises
    ------
    MotionDataError
        As listed in the module docstring, naming the file and the line.

    References
    ----------
    OpenSim ``TRCFileAdapter`` (opensim-core, ``OpenSim/Common/TRCFileAdapter.cpp``), whose
    layout and missing-value convention this reader follows.
    """
    if not isinstance(path, (str, os.PathLike)) or path == "":
        raise MotionDataError(f"read_trc: path must be a file path, got {type(path).__name__}")
    p = Path(path)
    text = read_bounded(
        p, MAX_TRC_BYTES, what="TRC file", error=lambda problem: MotionDataError(problem, p)
    )
    lines = text.split("\n")
    if len(lines) < 5:
        raise MotionDataError(
            f"{len(lines)} line(s): a TRC file has 5 header lines and the rows", p
        )
    first = lines[0].replace("\t", " ").split()
    if not first or first[0] != "PathFileType":
        raise MotionDataError(
            f"line 1: not a TRC file (it should start with 'PathFileType', got {lines[0][:40]!r})",
            p,
        )
    keys = [c for c in _cells(lines[1]) if c]
    values = [c for c in _cells(lines[2]) if c]
    missing = [k for k in REQUIRED_KEYS if k not in keys]
    if missing:
        raise MotionDataError(
            f"line 2: header keys {missing} missing (found {keys}; OpenSim writes "
            f"{' '.join(HEADER_KEYS)})",
            p,
        )
    if len(values) != len(keys):
        raise MotionDataError(
            f"line 3: {len(values)} header values for the {len(keys)} keys of line 2", p
        )
    header = dict(zip(keys, values))
    rate = _number(p, 3, header["DataRate"], "DataRate")
    if not (np.isfinite(rate) and rate > 0):
        raise MotionDataError(f"line 3: DataRate is {header['DataRate']!r}: give Hz > 0", p)
    counts = {}
    for k in ("NumFrames", "NumMarkers"):
        v = _number(p, 3, header[k], k)
        if not (np.isfinite(v) and v >= 0 and v == int(v)):
            raise MotionDataError(f"line 3: {k} is {header[k]!r}, not a whole number >= 0", p)
        counts[k] = int(v)
    unit_text = header["Units"] if units is None else units
    unit = str(unit_text).strip().lower()
    if unit not in UNITS:
        where = "line 3: Units" if units is None else "units="
        raise MotionDataError(
            f"{where} is {unit_text!r}; known units: {', '.join(sorted(set(UNITS)))}", p
        )
    labels = [c for c in _cells(lines[3]) if c]
    if labels[:2] != ["Frame#", "Time"]:
        raise MotionDataError(
            f"line 4: the columns should start with 'Frame#' and 'Time', got {labels[:2]}", p
        )
    names = labels[2:]
    n_markers = counts["NumMarkers"]
    if len(names) != n_markers:
        raise MotionDataError(
            f"line 4 names {len(names)} markers, line 3 says NumMarkers {n_markers}", p
        )
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise MotionDataError(f"line 4: marker labels {dup} appear twice", p)
    xyz = [c for c in _cells(lines[4]) if c]
    for i in range(n_markers):
        for j, letter in enumerate("XYZ"):
            want = f"{letter}{i + 1}"
            got = xyz[3 * i + j] if 3 * i + j < len(xyz) else None
            if got != want:
                raise MotionDataError(
                    f"line 5: column {3 * i + j + 3} of marker {names[i]!r} should be labelled "
                    f"{want!r}, got {got!r}",
                    p,
                )
    width = 2 + 3 * n_markers
    rows, times, linenos = [], [], []
    partial_samples = 0
    k = 5
    while k < len(lines) and not lines[k].strip():
        k += 1
    first_data = k + 1
    blank_at = None
    for k in range(k, len(lines)):
        line = lines[k]
        lineno = k + 1
        if not line.strip():
            blank_at = blank_at or lineno
            continue
        if blank_at is not None:
            raise MotionDataError(
                f"line {lineno}: data after the blank line {blank_at} (a blank line ends the "
                "data in OpenSim's reader: remove it)",
                p,
            )
        cells = _cells(line)
        while len(cells) > width and cells[-1] == "":
            cells.pop()  # the trailing tab most writers put at the end of a row
        if len(cells) != width:
            raise MotionDataError(
                f"line {lineno}: {len(cells)} cells, expected {width} (Frame#, Time and X, Y, Z "
                f"of {n_markers} markers): a ragged row",
                p,
            )
        _number(p, lineno, cells[0], "Frame#")
        t = _number(p, lineno, cells[1], "Time")
        if not np.isfinite(t):
            raise MotionDataError(f"line {lineno}: Time is {cells[1]!r}, not a finite number", p)
        if times and t <= times[-1]:
            raise MotionDataError(
                f"line {lineno}: Time {t:g} s does not increase (previous row {times[-1]:g} s)", p
            )
        row = np.full(3 * n_markers, np.nan)
        for m in range(n_markers):
            trip = cells[2 + 3 * m : 5 + 3 * m]
            if any(c == "" for c in trip):
                partial_samples += any(c != "" for c in trip)
                continue  # OpenSim: a marker with an empty coordinate is missing (NaN)
            for j, c in enumerate(trip):
                v = _number(p, lineno, c, f"{'XYZ'[j]} of marker {names[m]!r}")
                if np.isinf(v):
                    raise MotionDataError(
                        f"line {lineno}: {'XYZ'[j]} of marker {names[m]!r} is {c!r}: a "
                        "coordinate must be finite (leave the cell empty for a gap)",
                        p,
                    )
                row[3 * m + j] = v
        rows.append(row)
        times.append(t)
        linenos.append(lineno)
    announced = counts["NumFrames"]
    status = "complete"
    if len(rows) != announced:
        if not partial:
            raise MotionDataError(
                f"line 3 announces NumFrames {announced}, the file holds {len(rows)} rows "
                f"(lines {first_data}..{linenos[-1] if linenos else first_data}); "
                "read_trc(..., partial=True) reads the rows it holds",
                p,
            )
        status = "truncated" if len(rows) < announced else "extra_frames"
    if not rows:
        raise MotionDataError("no data rows after the header", p)
    P = np.array(rows).reshape(len(rows), n_markers, 3) * UNITS[unit]
    seen = np.isfinite(P).all(axis=2)
    if seen.any():
        med = float(np.median(np.linalg.norm(P[seen], axis=1)))
        lo, hi = PLAUSIBLE_M
        if not (lo <= med <= hi):
            raise MotionDataError(
                f"line 3: Units {unit_text!r} makes the markers' median distance from the lab "
                f"origin {med:.4g} m, outside [{lo:g}, {hi:g}] m: the numbers are in other units "
                "(pass read_trc(..., units='mm') or 'm' to override the header)",
                p,
            )
    meta = {
        "units": unit,
        "status": status,
        "time": np.array(times),
        "frames_announced": announced,
        "frames_read": len(rows),
        "header": header,
        "partial_samples": int(partial_samples),
        "first_data_line": first_data,
    }
    return MarkerTrajectories(tuple(names), P, rate=rate, source=str(p), meta=meta)


def _num(v: float) -> str:
    return "" if not np.isfinite(v) else repr(float(v))


def write_trc(path, trial: MarkerTrajectories, *, units: str = "mm", time=None) -> Path:
    """Write ``trial`` as an OpenSim ``.trc`` file in ``units`` (``"mm"`` or ``"m"``), missing
    samples as empty cells, numbers at full precision.  ``time`` ((N,) s) is the ``Time``
    column; by default ``trial.meta["time"]`` when present (a trial read by :func:`read_trc`),
    else ``trial.time``.  Atomic (:func:`anthroarm._io.atomic_write_text`).

    Raises
    ------
    MotionDataError
        Not a :class:`~anthroarm.motion.trial.MarkerTrajectories`, unknown ``units``, a label
        with a tab or a line break, ``time`` of the wrong length, not finite or not increasing.
    """
    if not isinstance(trial, MarkerTrajectories):
        raise MotionDataError(f"write_trc takes MarkerTrajectories, got {type(trial).__name__}")
    if units not in ("mm", "m"):
        raise MotionDataError(f"units must be 'mm' or 'm', got {units!r}", path)
    bad = [n for n in trial.names if any(c in n for c in "\t\r\n") or not n.strip()]
    if bad:
        raise MotionDataError(f"marker labels {bad!r} cannot be written to a TRC file", path)
    N, M, _ = trial.positions.shape
    t = trial.meta.get("time", trial.time) if time is None else time
    t = np.asarray(t, dtype=float)
    if t.shape != (N,) or not np.isfinite(t).all() or np.any(np.diff(t) <= 0):
        raise MotionDataError(f"time must be {N} finite increasing numbers (s)", path)
    p = Path(path)
    rate = repr(float(trial.rate))
    out = [
        f"PathFileType\t4\t(X/Y/Z)\t{p.name}",
        "\t".join(HEADER_KEYS),
        "\t".join([rate, rate, str(N), str(M), units, rate, "1", str(N)]),
        "\t".join(["Frame#", "Time", *(f"{n}\t\t" for n in trial.names)]),
        "\t\t" + "\t".join(f"X{i + 1}\tY{i + 1}\tZ{i + 1}" for i in range(M)),
        "",
    ]
    X = (trial.positions / UNITS[units]).reshape(N, 3 * M).tolist()
    for n in range(N):
        out.append("\t".join([str(n + 1), repr(float(t[n])), *map(_num, X[n])]))
    atomic_write_text(p, "\n".join(out) + "\n")
    return p
