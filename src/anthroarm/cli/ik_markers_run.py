"""``anthroarm ik-markers``: the run (the parser and the command's description:
:mod:`.ik_markers`)."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from ..motion import MarkerSet, marker_ik, read_c3d, scale_from_static
from ..motion.csv_io import write_joint_csv
from .common import UserError
from .ik_markers_osim import is_osim
from .ik_markers_osim import run as run_osim
from .person import check_person
from .runtime import load_model, progress, resolve_model


def run(a) -> int:
    resolve_model(a)
    rename = {}
    for item in a.rename:
        if "=" not in item:
            raise UserError(f"--rename expects LABEL=MARKER, got {item!r}")
        k, v = item.split("=", 1)
        rename[k.strip()] = v.strip()

    out = Path(a.out)
    if out.is_dir() or not out.parent.is_dir():
        raise UserError(f"--out {a.out}: give a file name in an existing folder")
    if out.exists() and not out.is_file():
        raise UserError(
            f"--out {a.out}: not a regular file (a device, FIFO or socket); give a file name"
        )
    for flag, given in (("the trial", a.trial), ("--static", a.static), ("--markers", a.markers)):
        if given is not None and _same_file(out, Path(given)):
            raise UserError(
                f"--out {a.out} is an input ({flag} {given}): it would be overwritten; "
                "give another output file"
            )
    if is_osim(a):  # an .osim model, a .trc trial or a Setup_IK.xml: marker IK in coordinates
        return run_osim(a)
    person = check_person(a)
    trial = read_c3d(a.trial)
    robot = load_model(a.model, person)
    markers = MarkerSet.read_json(a.markers) if a.markers else None
    info = {}
    if a.static:
        sc = scale_from_static(robot, read_c3d(a.static), markers, rename=rename, subject=a.subject)
        if sc.status != "ok":
            raise UserError(
                f"--static {a.static}: the static trial does not fit {a.model} ({sc.status}: RMS marker "
                f"error {sc.rms * 1e3:.1f} mm, scale factors "
                f"{ {k: round(v, 2) for k, v in sc.scales.items()} }); check the markers' labels (--rename) "
                "and that it is a static trial of this person"
            )
        robot = load_model(a.model, sc.load_kwargs(robot))
        markers = sc.marker_set
        info["segment_lengths_m"] = {k: round(v, 4) for k, v in sc.segment_lengths.items()}
        info["static_rms_m"] = sc.rms
    bar = progress(trial.n_frames, "marker IK", not a.no_progress)
    try:
        res = marker_ik(
            robot,
            trial,
            markers,
            rename=rename,
            subject=a.subject,
            solver=a.solver,
            progress=lambda n, N: bar.update(n - bar.n),
        )
    finally:
        bar.close()
    write_joint_csv(
        a.out,
        res,
        comment=f"source: {trial.source} ({trial.n_frames} frames at {trial.rate:g} Hz); "
        f"model {robot.name}; marker set {res.info['marker_set']}",
    )
    summary = {"out": a.out, **res.summary(), **info}
    print(json.dumps(summary))
    if res.counts()["ok"] == 0:
        print("anthroarm ik-markers: no frame solved with status ok", file=sys.stderr)
        return 1
    return 0


def _same_file(a, b) -> bool:
    """``a`` and ``b`` name the same file: the same inode (a hard link, a symlink, the same path
    written differently) or, when one does not exist yet, the same resolved path."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
