"""C3D marker files (the biomechanics standard, https://www.c3d.org) through ``ezc3d``.

:func:`read_c3d` returns :class:`~anthroarm.motion.trial.MarkerTrajectories` in metres: the
file's ``POINT:UNITS`` (mm, cm, m) is read and converted; the labels come from ``POINT:LABELS``
(and ``LABELS2``, ``LABELS3`` ... for files with more than 255 points), the rate from
``POINT:RATE``.  A sample is missing when its residual is negative (the C3D convention for an
invalid point; ezc3d reads its coordinates as NaN), when a coordinate is not finite, or, with
``zero_is_missing`` (default), when it is exactly (0, 0, 0), which several capture systems write
for gaps.

Frame counts are checked on the file's bytes, not taken from ezc3d: the frames the header and
``POINT:FRAMES`` announce must be in the file (ezc3d returns the frames it finds, silently, and
reads the zero padding of the last 512-byte block as frames when ``POINT:FRAMES`` says so).
A file whose bytes end before the last announced frame, or whose header and ``POINT:FRAMES``
disagree, holds fewer frames than it announces: a :class:`~anthroarm.errors.C3DError` naming both
counts, or, with ``partial=True``, the frames it holds with ``meta["status"] == "truncated"``.
In such a file the trailing frames of zero bytes in the last 512 bytes are the block padding,
not frames, and are not counted.  (A file whose header and ``POINT:FRAMES`` agree on frames that
its padding holds cannot be told from one that ends with frames of zeros: those frames are
read, as missing samples with ``zero_is_missing``.)  Only regular files
of at most :data:`MAX_C3D_BYTES` are read (:func:`anthroarm._io.check_regular_file`).

:func:`write_c3d` writes a trial (in mm by default) to a temporary file in the target's folder
and renames it into place, so a reader never sees half a file.
"""

from __future__ import annotations

import os
import secrets
import struct
from pathlib import Path

import numpy as np

from .._io import check_regular_file
from ..errors import C3DError
from .trial import MarkerTrajectories

#: the largest C3D file :func:`read_c3d` reads, bytes (1 GiB: ezc3d holds the whole file in
#: memory, several times over as Python objects); a larger file is a C3DError naming the bound
MAX_C3D_BYTES = 1 << 30

#: metres per unit of the C3D POINT:UNITS values anthroarm understands
UNITS = {
    "mm": 1e-3,
    "millimeter": 1e-3,
    "millimeters": 1e-3,
    "millimetre": 1e-3,
    "millimetres": 1e-3,
    "cm": 1e-2,
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
}


def _param(c, group: str, name: str, default=None):
    try:
        return c["parameters"][group][name]["value"]
    except (KeyError, TypeError):
        return default


def _check_structure(p: Path) -> dict:
    """Walk the header and the parameter section of a C3D file (https://www.c3d.org, "The C3D
    File Format User Guide", ch. 2-3: 512-byte blocks; parameter records ``name length, group id,
    name, offset to the next record, [type, dimensions, data], description``) and raise
    :class:`~anthroarm.errors.C3DError` where it is inconsistent, before ezc3d reads it: ezc3d
    (1.7) crashes the interpreter (SIGSEGV) or never returns on some damaged parameter sections.
    Returns the layout the frame count is checked on (:func:`_frames_held`): ``size``, the
    ``data_start`` byte, ``frame_bytes``, the frames the header announces (``header_frames``,
    None when it cannot say: 65535 or more) and ``POINT:FRAMES`` (``point_frames``, None if
    absent)."""
    size = p.stat().st_size
    with open(p, "rb") as fh:
        head = fh.read(512)
        if len(head) < 512 or head[1] != 0x50:
            raise C3DError("not a C3D file (no C3D header: the second byte is not 0x50)", p)
        start = (head[0] - 1) * 512
        if head[0] < 2 or start + 4 > size:
            raise C3DError(
                f"damaged C3D header: parameter section at block {head[0]} is outside the file", p
            )
        fh.seek(start)
        sec = fh.read(4)
        n_blocks, proc = sec[2], sec[3]
        if proc not in (84, 85, 86):
            raise C3DError(
                f"damaged C3D parameter section: processor type {proc} (84 Intel, 85 DEC, 86 MIPS)",
                p,
            )
        if n_blocks < 1 or start + 512 * n_blocks > size:
            raise C3DError(
                f"damaged or truncated C3D file: the parameter section ({n_blocks} blocks) does "
                f"not fit in the file ({size} bytes)",
                p,
            )
        fh.seek(start)
        sec = fh.read(512 * n_blocks)
    i16 = ">h" if proc == 86 else "<h"
    u16 = ">H" if proc == 86 else "<H"
    groups, params = set(), set()
    group_ids, scalars = {}, {}  # group name -> id; (group id, NAME) -> (type, data bytes)
    i = 4
    while i + 2 <= len(sec):
        nchar, gid = struct.unpack("bb", sec[i : i + 2])
        if nchar == 0:
            break
        off_at = i + 2 + abs(nchar)
        if gid == 0 or off_at + 3 > len(sec):
            raise C3DError(f"damaged C3D parameter section at byte {start + i}: group id {gid}", p)
        nxt = struct.unpack(i16, sec[off_at : off_at + 2])[0]
        j = off_at + 2
        if gid < 0:
            if -gid in groups:
                raise C3DError(f"damaged C3D parameter section: group id {-gid} appears twice", p)
            groups.add(-gid)
            group_ids[sec[i + 2 : i + 2 + abs(nchar)].decode("latin-1").upper()] = -gid
        else:
            params.add(gid)
            typ, ndim = struct.unpack("bB", sec[j : j + 2])
            dims = sec[j + 2 : j + 2 + ndim]
            if typ not in (-1, 1, 2, 4) or ndim > 7 or len(dims) < ndim:
                raise C3DError(
                    f"damaged C3D parameter section at byte {start + i}: data type {typ}, {ndim} "
                    "dimensions",
                    p,
                )
            if ndim == 0 and typ in (2, 4):
                raw = sec[j + 2 : j + 2 + typ]
                scalars[(gid, sec[i + 2 : i + 2 + abs(nchar)].decode("latin-1").upper())] = (
                    typ,
                    raw,
                )
            j += 2 + ndim + abs(typ) * int(np.prod([int(d) for d in dims]))
        if j >= len(sec):
            raise C3DError(
                f"damaged C3D parameter section at byte {start + i}: a record runs past the "
                "section",
                p,
            )
        j += 1 + sec[j]  # the description
        if j > len(sec) or (nxt != 0 and (nxt < 2 or j > off_at + nxt)):
            raise C3DError(
                f"damaged C3D parameter section at byte {start + i}: a record overlaps the next "
                "one",
                p,
            )
        if nxt == 0:
            break
        i = off_at + nxt
    if params - groups:
        raise C3DError(
            "damaged C3D parameter section: parameters of undeclared groups "
            f"{sorted(params - groups)}",
            p,
        )
    first, last = (struct.unpack(u16, head[k : k + 2])[0] for k in (6, 8))
    n_points, n_analog, data_block = (struct.unpack(u16, head[k : k + 2])[0] for k in (2, 4, 16))
    sign_byte = {84: 15, 85: 13, 86: 12}[proc]  # the sign bit of POINT's scale (IEEE LE, DEC, BE)
    word = 4 if head[sign_byte] & 0x80 else 2  # a negative scale: float data
    point = group_ids.get("POINT")

    def scalar(name):
        """POINT:name as a number (an int16 read unsigned), None if absent or not a scalar."""
        rec = scalars.get((point, name))
        if rec is None or len(rec[1]) != rec[0]:
            return None
        typ, raw = rec
        if typ == 2:
            return struct.unpack(u16, raw)[0]  # unsigned: files of 32768+ frames
        if proc == 85:  # DEC F-float: swap the 16-bit words, IEEE, divide by 4
            raw = raw[2:4] + raw[0:2]
        v = struct.unpack(">f" if proc == 86 else "<f", raw)[0] / (4.0 if proc == 85 else 1.0)
        return int(v) if np.isfinite(v) and 0 <= v < 2**31 else None

    point_frames = scalar("FRAMES")
    used, param_start = scalar("USED"), scalar("DATA_START")
    if used is not None and used != n_points:
        raise C3DError(
            f"damaged C3D file: the header says {n_points} points a frame, POINT:USED {used}", p
        )
    if data_block == 0 and param_start:
        data_block = param_start
    elif param_start is not None and param_start != data_block:
        raise C3DError(
            f"damaged C3D file: the header puts the data at block {data_block}, "
            f"POINT:DATA_START at block {param_start}",
            p,
        )
    return {
        "size": size,
        "data_start": (data_block - 1) * 512 if data_block >= 1 else None,
        "frame_bytes": (4 * n_points + n_analog) * word,
        "header_frames": last - first + 1 if 0 < first <= last < 65535 else None,
        "point_frames": point_frames,
    }


def _frames_held(p: Path, layout: dict, announced: int) -> tuple[int, int]:
    """(frames held, of them block padding): the complete frames of ``announced`` that the
    file's bytes hold after the data start, less the trailing frames of zero bytes that lie in
    the last 512 bytes of the file (the padding of its last block, which ezc3d reads as frames
    when the file announces them)."""
    ds, fb, size = layout["data_start"], layout["frame_bytes"], layout["size"]
    if ds is None or fb <= 0 or ds > size:
        return 0, 0
    held = min(announced, (size - ds) // fb)
    if held == 0:
        return 0, 0
    i0 = max(0, -(-(size - 511 - ds) // fb))  # the first frame starting in the last 511 bytes
    if i0 >= held:
        return held, 0
    lo = ds + i0 * fb
    with open(p, "rb") as fh:
        fh.seek(lo)
        tail = fh.read(ds + held * fb - lo)
    k = held
    while k > i0 and not any(tail[(k - 1 - i0) * fb : (k - i0) * fb]):
        k -= 1
    return k, held - k


def read_c3d(path, *, zero_is_missing: bool = True, partial: bool = False) -> MarkerTrajectories:
    """Marker trajectories of a C3D file, in metres (world = the lab frame of the file).

    ``meta`` of the result holds ``units``, ``status`` (``"complete"``, or ``"truncated"`` for a
    partial read), ``frames_announced`` and ``frames_read``.  With ``partial=True`` a file that
    holds fewer frames than it announces is read up to its last complete frame instead of
    refused (block padding is never read as frames).

    Raises
    ------
    C3DError
        No such file, not a regular file (a folder, a device, a FIFO), larger than
        :data:`MAX_C3D_BYTES`, not a C3D file ezc3d can read (a damaged header or parameter
        section is found before ezc3d reads it), fewer frames than the header or
        ``POINT:FRAMES`` announces (unless ``partial``: the message names both counts), no
        POINT data, unknown ``POINT:UNITS`` (the message lists the known ones), a non-positive
        rate, duplicate labels.
    """
    if not isinstance(path, (str, os.PathLike)) or path == "":
        raise C3DError(f"read_c3d: path must be a file path, got {type(path).__name__} {path!r}")
    p = Path(path)
    check_regular_file(
        p, MAX_C3D_BYTES, what="C3D file", error=lambda problem: C3DError(problem, p)
    )
    try:
        layout = _check_structure(p)
    except OSError as exc:
        raise C3DError(f"cannot read the file ({exc.strerror or exc})", p) from None
    try:
        import ezc3d

        c = ezc3d.c3d(str(p))
    except Exception as exc:  # ezc3d raises RuntimeError/IOError from C++
        raise C3DError(f"ezc3d cannot read this file as C3D ({exc})", p) from None
    pts = np.asarray(c["data"]["points"], dtype=float)
    if pts.ndim != 3 or pts.shape[0] < 3:
        raise C3DError(f"no POINT data (points array of shape {pts.shape})", p)
    n_read = pts.shape[2]
    claims = {k: layout[k] for k in ("header_frames", "point_frames") if layout[k] is not None}
    announced = max([n_read, *claims.values()])
    consistent = n_read == announced and all(v == announced for v in claims.values())
    ds, fb = layout["data_start"], layout["frame_bytes"]
    if fb <= 0:  # nothing per frame to count on
        held, padding = n_read, 0
    elif consistent and ds is not None and ds + announced * fb <= layout["size"]:
        held, padding = announced, 0  # frames of zeros at the end of such a file are kept
    else:
        try:
            held, padding = _frames_held(p, layout, announced)
        except OSError as exc:
            raise C3DError(f"cannot read the file ({exc.strerror or exc})", p) from None
    status = "complete"
    if held < announced or not consistent:
        said = ", ".join(
            f"{'the header' if k == 'header_frames' else 'POINT:FRAMES'} {v}"
            for k, v in claims.items()
        )
        pad = (
            f" (the {padding} frame(s) of zero bytes after them are the padding of the last "
            "512-byte block, not frames)"
            if padding
            else ""
        )
        if not partial:
            raise C3DError(
                f"truncated or damaged file: its header announces {announced} frames ({said}), "
                f"the file holds {min(held, n_read)}{pad} (ezc3d reads {n_read}); "
                f"read_c3d(..., partial=True) reads the frames it holds",
                p,
            )
        status = "truncated"
        pts = pts[:, :, : min(held, n_read)]
    labels = list(_param(c, "POINT", "LABELS", []) or [])
    k = 2
    while len(labels) < pts.shape[1] and _param(c, "POINT", f"LABELS{k}") is not None:
        labels += list(_param(c, "POINT", f"LABELS{k}"))
        k += 1
    labels = [str(s).strip() for s in labels[: pts.shape[1]]]
    if len(labels) < pts.shape[1]:
        labels += [f"point{i + 1}" for i in range(len(labels), pts.shape[1])]
    units = _param(c, "POINT", "UNITS", ["mm"])
    unit = str(units[0] if len(units) else "mm").strip().lower()
    if unit not in UNITS:
        raise C3DError(f"POINT:UNITS is {unit!r}; known units: {', '.join(sorted(set(UNITS)))}", p)
    rate = _param(c, "POINT", "RATE", [0.0])
    rate = float(np.asarray(rate, dtype=float).ravel()[0]) if np.size(rate) else 0.0
    if not (np.isfinite(rate) and rate > 0):
        raise C3DError(f"POINT:RATE is {rate!r}: the frame rate must be positive (Hz)", p)
    P = np.moveaxis(pts[:3], 0, -1).transpose(1, 0, 2) * UNITS[unit]  # (N, M, 3)
    missing = ~np.isfinite(P).all(axis=2)
    if zero_is_missing:
        missing |= np.all(P == 0.0, axis=2)
    P[missing] = np.nan
    dup = sorted({s for s in labels if labels.count(s) > 1})
    if dup:
        raise C3DError(f"duplicate marker labels {dup}: rename them in the capture software", p)
    meta = {
        "units": unit,
        "status": status,
        "frames_announced": int(announced),
        "frames_read": int(P.shape[0]),
    }
    return MarkerTrajectories(tuple(labels), P, rate=rate, source=str(p), meta=meta)


def write_c3d(path, trial: MarkerTrajectories, *, units: str = "mm") -> Path:
    """Write ``trial`` to ``path`` as a C3D file with ``POINT:UNITS = units`` (``"mm"`` or
    ``"m"``); missing samples are written as NaN with residual −1.  Atomic: a temporary
    file in the same folder, then ``os.replace``."""
    if units not in ("mm", "m"):
        raise C3DError(f"units must be 'mm' or 'm', got {units!r}", path)
    if not isinstance(trial, MarkerTrajectories):
        raise C3DError(f"write_c3d takes MarkerTrajectories, got {type(trial).__name__}", path)
    import ezc3d

    p = Path(path)
    if p.is_dir():
        raise C3DError("is a folder: give a file name", p)
    if not p.parent.is_dir():
        raise C3DError(f"folder {p.parent} does not exist", p)
    long = [n for n in trial.names if len(n.encode("utf-8")) > 255]
    if long:
        raise C3DError(
            "marker labels longer than 255 bytes cannot be stored in POINT:LABELS: "
            f"{long[0][:40]!r}...",
            p,
        )
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [trial.rate]
    c["parameters"]["POINT"]["LABELS"]["value"] = list(trial.names)
    c["parameters"]["POINT"]["UNITS"]["value"] = [units]
    N, M, _ = trial.positions.shape
    pts = np.ones((4, M, N))
    pts[:3] = trial.positions.transpose(2, 1, 0) / UNITS[units]
    missing = ~trial.visible.T  # (M, N)
    pts[:3, missing] = np.nan
    c["data"]["points"] = pts
    res = np.zeros((1, M, N))
    res[0, missing] = -1.0
    c["data"]["meta_points"] = {"residuals": res, "camera_masks": np.zeros((7, M, N), dtype=bool)}
    tmp = p.with_name(f".{p.stem}.{os.getpid()}.{secrets.token_hex(4)}.tmp.c3d")
    try:
        c.write(str(tmp))
        os.replace(tmp, p)
    except Exception as exc:
        tmp.unlink(missing_ok=True)
        what = (
            f"cannot write the file ({exc.strerror})"
            if isinstance(exc, OSError) and exc.strerror
            else f"ezc3d cannot write the file ({exc})"
        )
        raise C3DError(what, p) from None
    return p
