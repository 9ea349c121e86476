"""``anthroarm size``: the run (the parser and the command's description: :mod:`.size`), and
the joint-trajectory files ``--activities`` reads."""

from __future__ import annotations

import difflib
import inspect
import json
import sys
import zipfile
from pathlib import Path

import numpy as np

from .. import models
from .._io import check_regular_file, read_bounded
from ..errors import ActivityError
from ..motion import activities as adl
from ..prosthesis import catalogue, report, study
from ..prosthesis.residual import ResidualMuscles
from ..viewer.pages import activities_html
from .common import UserError
from .person import check_person
from .runtime import input_file, load_model, progress, resolve_model

#: the largest trajectory file read (bytes): 10**6 samples of a 7-joint arm as CSV are ~150 MB
MAX_TRAJECTORY_BYTES = 256 * 2**20


def read_trajectory(path: Path, robot) -> dict:
    def bad(problem):
        return ActivityError(f"{path}: {problem}")

    # a regular file within the bound: /dev/zero, a folder or a FIFO is refused unread
    check_regular_file(path, MAX_TRAJECTORY_BYTES, error=bad, what="trajectory file")
    if path.suffix.lower() == ".npz":
        not_npz = ActivityError(
            f"{path}: not a NumPy .npz archive of numeric arrays (np.savez(path, t=..., q=...))"
        )
        try:
            z = np.load(path, allow_pickle=False)
        except (OSError, ValueError, EOFError, zipfile.BadZipFile):
            raise not_npz from None
        if not isinstance(z, np.lib.npyio.NpzFile):  # a single .npy array under an .npz name
            raise not_npz
        with z:
            if "t" not in z.files or "q" not in z.files:
                raise ActivityError(
                    f"{path}: an .npz trajectory needs arrays 't' (N,) and 'q' (N, {robot.nq}); "
                    f"it has {sorted(z.files)}"
                )
            try:
                t, q = z["t"], z["q"]
            except (OSError, ValueError, EOFError, zipfile.BadZipFile):
                raise not_npz from None
        try:
            return dict(name=path.stem, t=np.asarray(t, float), q=np.asarray(q, float))
        except (TypeError, ValueError):
            raise ActivityError(
                f"{path}: 't' and 'q' must be numbers (s, rad), got {t.dtype} and {q.dtype}"
            ) from None
    if path.suffix.lower() == ".csv":
        text = read_bounded(
            path, MAX_TRAJECTORY_BYTES, error=bad, what="trajectory file", encoding="utf-8-sig"
        )
        lines = [
            (k + 1, ln)
            for k, ln in enumerate(text.splitlines())
            if ln.strip() and not ln.startswith("#")
        ]
        if not lines:
            raise ActivityError(f"{path}: empty trajectory file")
        header = [h.strip() for h in lines[0][1].split(",")]
        need = ["t", *robot.joint_names]
        missing = [c for c in need if c not in header]
        if missing:
            raise ActivityError(f"{path}: missing column(s) {missing}; need {need}")
        rows = []
        for lineno, ln in lines[1:]:
            fields = ln.split(",")
            if len(fields) != len(header):
                raise ActivityError(
                    f"{path}, line {lineno}: {len(fields)} values, the header has {len(header)}"
                )
            try:
                rows.append([float(x) for x in fields])
            except ValueError:
                raise ActivityError(
                    f"{path}, line {lineno}: a value is not a number: {ln.strip()!r}"
                ) from None
        if not rows:
            raise ActivityError(f"{path}: a header but no samples")
        data = np.array(rows, dtype=float)
        cols = [header.index(c) for c in need]
        return dict(name=path.stem, t=data[:, cols[0]], q=data[:, cols[1:]])
    raise ActivityError(f"{path}: a trajectory file is .npz or .csv, got {path.suffix!r}")


def activities_from(spec: str, robot, payload: float) -> list[dict]:
    """The activity dicts of :func:`anthroarm.prosthesis.study.run` for ``--activities``
    (:mod:`.size`)."""
    if spec.strip().lower() == "adl":
        return study.adl_activities(robot, payload)
    known = adl.names()
    out, items = [], [p.strip() for p in spec.split(",") if p.strip()]
    if not items:
        raise UserError("--activities is empty: give 'adl', activity names or trajectory files")
    for item in items:
        if item in known:
            out += study.adl_activities(robot, payload, [item])
        elif Path(item).exists() or Path(item).suffix.lower() in (".npz", ".csv"):
            out.append(read_trajectory(Path(item), robot))
        else:
            close = difflib.get_close_matches(item, ["adl", *known], n=3, cutoff=0.6)
            hint = f"did you mean {' or '.join(map(repr, close))}? " if close else ""
            raise UserError(
                f"--activities {item!r} is neither 'adl', an activity of the library nor a "
                f"trajectory file (.npz, .csv): {hint}activities: {', '.join(known)}"
            )
    return out


def _person_params(a) -> dict:
    """height, mass and sex for a catalog model whose builder scales a person; anything else
    cannot be sized for a person: a one-line error naming the person models."""
    builder = models.BOOK_MODELS.get(a.model)
    person = [
        n
        for n, b in models.BOOK_MODELS.items()
        if {"height", "mass", "sex"} <= set(inspect.signature(b).parameters)
    ]
    if builder is None or a.model not in person:
        raise UserError(
            f"model {a.model}: anthroarm size scales a person's arm to --height/--mass/--sex; "
            f"person models: {', '.join(sorted(person))}"
        )
    return check_person(a)


def residual_muscles(a, robot):
    """The person's residual muscles of ``--muscles`` (None without it)."""
    given = [o for o in ("muscle_joints", "remaining") if getattr(a, o) is not None]
    if a.muscles is None:
        if given or a.strength != 1.0:
            opts = [f"--{o.replace('_', '-')}" for o in given] or ["--strength"]
            raise UserError(f"{', '.join(opts)} need --muscles MODEL.osim (the person's muscles)")
        return None
    if not a.muscle_joints:
        raise UserError(
            "--muscles needs --muscle-joints JOINT=COORD[,...]: which coordinate of the model "
            f"each joint of the arm is (joints: {', '.join(robot.joint_names)})"
        )
    remaining = None if a.remaining is None else a.remaining.split(",")
    res = ResidualMuscles.from_osim(input_file(a.muscles), a.muscle_joints, remaining, a.strength)
    res.check_arm(robot.joint_names)
    return res


def run(a) -> int:
    resolve_model(a)
    out = Path(a.out)
    if out.suffix.lower() not in (".html", ".htm"):
        raise UserError(f"--out {a.out}: the report is an HTML file (.html)")
    if out.is_dir():
        raise UserError(
            f"--out {a.out} is a folder; give a file name such as {out / 'report.html'}"
        )
    if not out.parent.is_dir():
        raise UserError(f"--out {a.out}: folder {out.parent} does not exist")
    for what, v, lo, hi in (
        ("payload", 0.0 if a.payload is None else a.payload, 0.0, 50.0),
        ("margin", a.margin, 0.0, 10.0),
    ):
        if not (np.isfinite(v) and lo <= v <= hi):
            unit = "kg" if what == "payload" else "a fraction, 0.2 = 20 %"
            raise UserError(f"--{what} {v:g} is outside {lo:g}–{hi:g} ({unit})")
    check_person(a)  # before any work: a height in cm is refused with the remedy
    cat = catalogue.load(a.motors, a.gearboxes)
    robot = load_model(a.model, _person_params(a))
    muscles = residual_muscles(a, robot)
    acts = activities_from(a.activities, robot, a.payload)
    bar = progress(len(acts) + robot.nv, "size", not a.no_progress)

    def tick(stage, name):
        bar.set_postfix_str(f"{stage} {name}")
        bar.update(1)

    try:
        st = study.run(
            robot,
            acts,
            payload=a.payload or 0.0,
            catalogue=cat,
            margin=a.margin,
            person=dict(height=a.height, mass=a.mass, sex=a.sex),
            progress=tick,
            residual=muscles,
        )
        bar.set_postfix_str("report")
        inputs = dict(
            model=a.model,
            **_person_params(a),
            activities=a.activities
            if a.activities.strip().lower() == "adl"
            else ", ".join(Path(p.strip()).name for p in a.activities.split(",") if p.strip()),
            payload_kg=a.payload,
            margin=a.margin,
        )
        if muscles is not None:
            inputs.update(
                muscles=Path(a.muscles).name,
                remaining=", ".join(muscles.muscles.names),
                strength=a.strength,
                muscle_joints=a.muscle_joints,
            )
        page = None if a.no_viewer else activities_html(st)
        report.write(st, out, viewer=page, inputs=inputs)
    finally:
        bar.close()
    summary = dict(out=str(out), **st.summary())  # the report's own verdicts (one source)
    print(json.dumps(summary), file=sys.stdout)
    return 0
