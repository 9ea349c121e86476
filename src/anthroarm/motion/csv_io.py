"""Joint-angle trajectories as CSV.

Format (what :func:`write_joint_csv` writes and ``anthroarm size --activities FILE.csv`` reads):
``#`` lines are comments (units, source, the legend of the status codes); the header is ``t``
(s) and one column per joint named as the joint (rad, or m for a prismatic joint); a marker-IK
result adds ``rms_m``, ``max_error_m`` (m; ``nan`` for a skipped frame), ``n_markers`` and
``status`` (a code: 0 ok, 1 too_few_markers, 2 not_converged, 3 skipped, 4 large_error).  Every
value is a number, so any CSV reader takes it.

:func:`read_joint_csv` also accepts ``time`` / ``time_s`` for the time column and joint columns
with a unit suffix (``_rad``, ``_deg``; degrees are converted), so spreadsheets from other tools
load too.  An empty or ``nan`` cell is a gap; ``inf`` or a magnitude beyond 1e6 is an error, so
is a column named twice (``a`` and ``a_deg`` name the same joint).  Only a regular file of at
most :data:`MAX_CSV_BYTES` is read (:func:`anthroarm._io.read_bounded`).
A row whose joint values are not finite is a gap: it is marked invalid and holds the
previous valid row (the next one before the first), never NaN.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._io import atomic_write_text, read_bounded
from ..errors import MotionDataError
from .marker_ik import STATUSES, MarkerIKResult

TIME_COLUMNS = ("t", "time", "time_s")
_EXTRAS = ("rms_m", "max_error_m", "n_markers", "status")  # the marker-IK columns
#: the largest magnitude :func:`read_joint_csv` takes in a cell (inf and beyond are errors)
MAX_VALUE = 1e6
#: the largest joint-trajectory CSV :func:`read_joint_csv` reads, bytes (64 MiB: about 500 000
#: rows of 7 joints, 80 min at 100 Hz); a larger file is a MotionDataError naming the bound
MAX_CSV_BYTES = 64 << 20


@dataclass
class JointTrajectory:
    """Joint trajectory read from CSV: ``t`` (N,) s, ``q`` (N, n) rad (or m), the joint
    ``names`` of the columns, and ``valid`` (N,) False for rows that had a missing value."""

    t: np.ndarray
    q: np.ndarray
    names: tuple
    valid: np.ndarray
    source: str = ""


def write_joint_csv(path, t, q=None, names=None, *, comment: str = "") -> Path:
    """Write a joint trajectory: ``write_joint_csv(path, result)`` for a
    :class:`~anthroarm.motion.marker_ik.MarkerIKResult` (with its per-frame errors and status),
    an object with ``t``/``time``, ``q`` and ``joint_names`` (an activity trajectory), or
    ``write_joint_csv(path, t, q, names)``.  Atomic (:func:`anthroarm._io.atomic_write_text`)."""
    extra = None
    if q is None:
        res = t
        t = getattr(res, "time", None) if getattr(res, "t", None) is None else res.t
        q, names = res.q, res.joint_names
        if isinstance(res, MarkerIKResult):
            code = np.array([STATUSES.index(s) for s in res.status])
            extra = (
                ("rms_m", "max_error_m", "n_markers", "status"),
                np.column_stack([res.rms, res.max_error, res.n_markers, code]),
            )
    t = np.asarray(t, float)
    q = np.asarray(q, float)
    names = tuple(names or ())
    if q.ndim != 2 or t.shape != (q.shape[0],) or len(names) != q.shape[1]:
        raise MotionDataError(
            f"write_joint_csv: t (N,), q (N, n) and n names, got {t.shape}, {q.shape}, {len(names)}"
        )
    if not (np.isfinite(t).all() and np.isfinite(q).all()):
        raise MotionDataError("write_joint_csv: t and q must be finite", path)
    bad = [
        n
        for n in names
        if not str(n).strip()
        or any(c in str(n) for c in ',\n\r"')
        or str(n).lstrip().startswith("#")
    ]
    if bad:
        raise MotionDataError(
            f"write_joint_csv: joint names {bad} cannot be CSV column names (empty, a comma, a "
            "quote, a line break or a leading #)",
            path,
        )
    buf = io.StringIO()
    buf.write("# anthroarm joint trajectory: t in s, joint angles in rad (prismatic joints in m)\n")
    if extra is not None:
        buf.write(
            "# rms_m, max_error_m: marker errors in m (nan: skipped frame); status: "
            + ", ".join(f"{i} {s}" for i, s in enumerate(STATUSES))
            + "\n"
        )
    for line in comment.splitlines():
        buf.write(f"# {line}\n")
    header = ["t", *names] + (list(extra[0]) if extra is not None else [])
    buf.write(",".join(header) + "\n")
    cols = [t[:, None], q] + ([extra[1]] if extra is not None else [])
    data = np.hstack(cols)
    nint = 2 if extra is not None else 0
    for row in data:
        vals = [repr(float(x)) for x in row[: len(row) - nint]]
        vals += [str(int(x)) for x in row[len(row) - nint :]]
        buf.write(",".join(vals) + "\n")
    p = Path(path)
    atomic_write_text(p, buf.getvalue())
    return p


def read_joint_csv(path, robot=None) -> JointTrajectory:
    """Read a joint trajectory (see the module docstring).  With ``robot``, every joint of
    ``robot.chain.q_names`` must have a column (returned in the robot's order); without, every
    column except the time and the marker-IK extras is a joint.

    Raises :class:`~anthroarm.errors.MotionDataError` naming the file and the line: no such
    file, not a regular file (a folder, a device, a FIFO), larger than :data:`MAX_CSV_BYTES`,
    not UTF-8 text, no header, no time column, a column named twice, a missing joint, a value
    that is not a number or is infinite or beyond :data:`MAX_VALUE`, a row of the wrong length,
    times that do not increase, no valid row."""
    if not isinstance(path, (str, os.PathLike)) or path == "":
        raise MotionDataError(
            f"read_joint_csv: path must be a file path, got {type(path).__name__} {path!r}"
        )
    p = Path(path)
    text = read_bounded(
        p,
        MAX_CSV_BYTES,
        what="joint-trajectory CSV",
        encoding="utf-8-sig",  # a byte-order mark (spreadsheets write one) is not in the header
        error=lambda problem: MotionDataError(problem, p),
    )
    rows = [
        (i + 1, ln)
        for i, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not rows:
        raise MotionDataError("no header line", p)
    hline, hrow = rows[0]
    header = [h.strip() for h in hrow.split(",")]
    times = [h for h in header if h in TIME_COLUMNS]
    if not times:
        raise MotionDataError(f"no time column (one of {list(TIME_COLUMNS)}); header: {header}", p)
    if len(times) > 1:
        raise MotionDataError(
            f"line {hline}: time columns {times[0]!r} and {times[1]!r}: keep one", p
        )
    tcol = header.index(times[0])
    joints, seen = {}, {}
    for i, h in enumerate(header):
        if i == tcol:
            continue
        key, scale = h, 1.0
        if h.endswith("_deg"):
            key, scale = h[:-4], np.pi / 180.0
        elif h.endswith("_rad"):
            key = h[:-4]
        if key in seen:
            same = f"column {h!r} twice" if seen[key] == h else f"columns {seen[key]!r} and {h!r}"
            raise MotionDataError(
                f"line {hline}: {same} (the same {'joint' if key not in _EXTRAS else 'value'} "
                f"{key!r}); keep one",
                p,
            )
        seen[key] = h
        if h not in _EXTRAS:
            joints[key] = (i, scale)
    names = tuple(joints) if robot is None else tuple(robot.chain.q_names)
    missing = [n for n in names if n not in joints]
    if missing:
        raise MotionDataError(f"missing joint column(s) {missing}; header: {header}", p)
    if not names:
        raise MotionDataError("no joint columns", p)
    vals = np.empty((len(rows) - 1, len(header)))
    for r, (lineno, ln) in enumerate(rows[1:]):
        cells = ln.split(",")
        if len(cells) != len(header):
            raise MotionDataError(
                f"line {lineno}: {len(cells)} values, the header has {len(header)}", p
            )
        for c, cell in enumerate(cells):
            s = cell.strip()
            try:
                x = float(s) if s else np.nan
            except ValueError:
                raise MotionDataError(
                    f"line {lineno}, column {header[c]!r}: {s!r} is not a number", p
                ) from None
            if abs(x) > MAX_VALUE:  # inf, or no angle (rad), length (m) or time (s)
                raise MotionDataError(
                    f"line {lineno}, column {header[c]!r}: {s!r} is beyond {MAX_VALUE:g} (not a "
                    "joint value in rad or m, nor a time in s); leave a gap empty or write nan",
                    p,
                )
            vals[r, c] = x
    t = vals[:, tcol]
    if not np.isfinite(t).all():
        bad = rows[1 + int(np.flatnonzero(~np.isfinite(t))[0])][0]
        raise MotionDataError(f"line {bad}: the time is missing or not finite", p)
    if np.any(np.diff(t) <= 0):
        bad = rows[2 + int(np.flatnonzero(np.diff(t) <= 0)[0])][0]
        raise MotionDataError(f"line {bad}: times must increase", p)
    q = (
        np.column_stack([vals[:, joints[n][0]] * joints[n][1] for n in names])
        if len(t)
        else np.zeros((0, len(names)))
    )
    valid = np.isfinite(q).all(axis=1)
    if not valid.any():
        raise MotionDataError("no row with every joint value", p)
    first = int(np.argmax(valid))
    q[:first] = q[first]
    for n in range(first + 1, len(q)):
        if not valid[n]:
            q[n] = q[n - 1]
    return JointTrajectory(t, q, names, valid, str(p))
