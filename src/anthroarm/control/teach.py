"""Teach, store and play back a playback robot's program (§9-1 一, lines 6798–7036; Fig. 9-9).

The book's playback robot (重复型机器人) is taught (示教), stores (存贮) and plays back (再现)
three kinds of information: **sequence** (顺序), **position** (位置) and **time** (时间).  A
:class:`Program` holds them as separate channels (:meth:`Program.channels`, the book's separated
storage 分离存贮) or together, step by step (its centralised storage 集中存贮).

Playback modes (§9-1 一.3):

* **fixed sequence** (固定顺序) — :func:`play_fixed`: the steps in taught order, cycle after cycle;
* **program select** (程序选择, Fig. 9-9 (a)) — :func:`play_select`: several taught programs,
  a sensor picks one;
* **program jump** (程序跳越, Fig. 9-9 (b)) — :func:`play_jump`: a :class:`Jump` inside the
  program skips to a label when its sensor signal is on;
* **subroutine** (子程序, Fig. 9-9 (c)) — :func:`play_subroutines`: a stored order of named
  subroutines (a :class:`Call` inside a program works too);
* **random access** (随机存取) — :func:`play_random_access`: every unit motion has an address
  and the next address is chosen from the sensor signals (a computer's job in the book); moves
  between points use straight-line or circular-arc interpolation
  (:mod:`~anthroarm.control.interpolation`).

The book describes these with flow charts only (Fig. 9-9, lost); the data model here (steps,
labels, jumps, calls, a call stack, a step limit) is this module's choice.  A :class:`Playback`
lists the executed steps and turns them into a timed path with :meth:`Playback.trajectory`:
between consecutive points the motion of the *arriving* step (``"joint"``: linear in the stored
coordinates; ``"line"``: straight line in Cartesian space; ``"arc"``: circular arc through the
step's ``via`` point) at constant speed over the step's ``time``, then its ``dwell``.

Positions are joint vectors (rad, m) or Cartesian points (m, shape (3,)) or poses (4×4) in the
base frame; one program uses one kind.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import input_checks as _check
from .._io import atomic_write_text, read_bounded
from ..errors import ControlError, PlaybackError
from ..ik import solve
from ._teach_guard import (
    ITEMS_PER_STEP,
    MAX_CALL_DEPTH,
    MAX_JSON_DEPTH,
    MAX_PROGRAM_BYTES,
    History,
    check_call_graph,
    check_calls,
    hashable,
    library_of,
    parse_program_json,
    sensor_signal,
)
from ._teach_guard import name as _name
from .interpolation import _lerp, arc_poses, circle_through, line_poses

__all__ = [
    "ITEMS_PER_STEP",
    "MAX_CALL_DEPTH",
    "MAX_JSON_DEPTH",
    "MAX_PROGRAM_BYTES",
    "Call",
    "ExecutedStep",
    "Jump",
    "Playback",
    "Program",
    "Step",
    "play_fixed",
    "play_jump",
    "play_random_access",
    "play_select",
    "play_subroutines",
    "record",
]

MOTIONS = ("joint", "line", "arc")


@dataclass(frozen=True)
class Step:
    """One taught point: position channel, time channel, and the step's place in the sequence.

    Parameters
    ----------
    position : array_like
        Joint vector, Cartesian point (3,) or pose (4, 4).
    time : float
        Time to move to this point from the previous one, s (≥ 0; the time channel).
    label : str, optional
        A label that jumps and random access can name.
    dwell : float
        Time to stay at the point after arriving, s (≥ 0).
    motion : str
        ``"joint"``, ``"line"`` or ``"arc"`` (how to reach this point).
    via : array_like, optional
        For ``"arc"``: the intermediate point of the arc (m, shape (3,)).
    grip : float, optional
        A gripper command to issue on arrival (e.g. a grip force, N), carried through.
    """

    position: np.ndarray
    time: float
    label: str | None = None
    dwell: float = 0.0
    motion: str = "joint"
    via: np.ndarray | None = None
    grip: float | None = None

    def __post_init__(self):
        s = object.__setattr__
        pos = _check.array(self.position, "position")
        if pos.ndim == 0 or pos.ndim > 2 or (pos.ndim == 2 and pos.shape != (4, 4)):
            raise ControlError(f"position must be a vector or a 4x4 pose, got shape {pos.shape}")
        s(self, "position", pos)
        s(self, "time", _check.nonnegative(self.time, "time (s)"))
        s(self, "dwell", _check.nonnegative(self.dwell, "dwell (s)"))
        if self.motion not in MOTIONS:
            raise ControlError(f"motion must be one of {MOTIONS}, got {self.motion!r}")
        if self.motion in ("line", "arc") and pos.shape not in ((3,), (4, 4)):
            raise ControlError(
                f"{self.motion!r} motion needs a Cartesian point (3,) or pose (4, 4), got "
                f"{pos.shape}"
            )
        if self.motion == "joint" and pos.shape == (4, 4):
            raise ControlError(
                "a 4x4 pose cannot be interpolated entry by entry: give motion='line' or 'arc'"
            )
        if self.motion == "arc":
            if self.via is None:
                raise ControlError("an 'arc' step needs its via point (via=...)")
            v = _check.array(self.via, "via")
            if v.shape != (3,):
                raise ControlError(f"via must be a point of shape (3,), got {v.shape}")
            s(self, "via", v)
        elif self.via is not None:
            raise ControlError("via is only for motion='arc'")
        if self.grip is not None:
            s(self, "grip", _check.scalar(self.grip, "grip"))
        if self.label is not None and not isinstance(self.label, str):
            raise ControlError(f"label must be a string, got {self.label!r}")

    def to_dict(self) -> dict:
        """A JSON-ready dictionary (see :meth:`Program.to_json`)."""
        d = {
            "kind": "step",
            "position": self.position.tolist(),
            "time": self.time,
            "dwell": self.dwell,
            "motion": self.motion,
        }
        if self.label is not None:
            d["label"] = self.label
        if self.via is not None:
            d["via"] = self.via.tolist()
        if self.grip is not None:
            d["grip"] = self.grip
        return d


@dataclass(frozen=True)
class Jump:
    """Program jump (程序跳越): go to ``label`` when the sensor ``sensor`` is on (always when
    ``sensor`` is None)."""

    label: str
    sensor: str | None = None

    def __post_init__(self):
        _name(self.label, "a jump's label")
        if self.sensor is not None:
            _name(self.sensor, "a jump's sensor")

    def to_dict(self) -> dict:
        return {"kind": "jump", "label": self.label, "sensor": self.sensor}


@dataclass(frozen=True)
class Call:
    """Run the subroutine ``name`` (a program of the library) and come back (子程序)."""

    name: str

    def __post_init__(self):
        _name(self.name, "a call's subroutine name")

    def to_dict(self) -> dict:
        return {"kind": "call", "name": self.name}


Item = Step | Jump | Call


@dataclass(frozen=True)
class Program:
    """A taught program: a named sequence of :class:`Step`, :class:`Jump` and :class:`Call`.

    Raises
    ------
    anthroarm.errors.PlaybackError
        A duplicate label or a :class:`Jump` to a label the program does not have (the message
        lists the labels).
    anthroarm.errors.ControlError
        Steps whose positions are of different kinds.
    """

    name: str
    items: tuple = field(default_factory=tuple)

    def __post_init__(self):
        _name(self.name, "a program's name")
        if isinstance(self.items, (str, bytes, Mapping)) or not isinstance(
            self.items, (Sequence, tuple, list)
        ):
            raise ControlError(
                f"program {self.name!r}: items must be a sequence of Step, Jump and Call, got "
                f"{type(self.items).__name__}"
            )
        items = tuple(self.items)
        object.__setattr__(self, "items", items)
        labels: dict[str, int] = {}
        shape = None
        for k, it in enumerate(items):
            if not isinstance(it, (Step, Jump, Call)):
                raise ControlError(
                    f"program {self.name!r} item {k} is not a Step, Jump or Call: {it!r}"
                )
            if isinstance(it, Step):
                if it.label is not None:
                    if it.label in labels:
                        raise PlaybackError(
                            f"program {self.name!r}: label {it.label!r} is used twice "
                            f"(items {labels[it.label]} and {k})"
                        )
                    labels[it.label] = k
                if shape is None:
                    shape = it.position.shape
                elif it.position.shape != shape:
                    raise ControlError(
                        f"program {self.name!r}: step {k} has a position of shape "
                        f"{it.position.shape}, the program's are {shape}"
                    )
        for k, it in enumerate(items):
            if isinstance(it, Jump) and it.label not in labels:
                raise PlaybackError(
                    f"program {self.name!r}: item {k} jumps to label {it.label!r}, which does not "
                    f"exist; labels: {sorted(labels)}"
                )
        object.__setattr__(self, "_labels", labels)

    @property
    def labels(self) -> dict[str, int]:
        """Label → item index."""
        return dict(self._labels)

    @property
    def steps(self) -> tuple[Step, ...]:
        """The program's steps (no jumps or calls)."""
        return tuple(it for it in self.items if isinstance(it, Step))

    def channels(self) -> dict[str, object]:
        """The separated storage of the steps: ``"sequence"`` (the labels, or the step number
        where a step has none), ``"position"`` (array (n, ...) of positions) and ``"time"``
        (array (n,) of move times, s), plus ``"dwell"`` (s)."""
        st = self.steps
        return {
            "sequence": [s.label if s.label is not None else f"#{k}" for k, s in enumerate(st)],
            "position": np.array([s.position for s in st]),
            "time": np.array([s.time for s in st]),
            "dwell": np.array([s.dwell for s in st]),
        }

    @classmethod
    def from_channels(
        cls, name: str, sequence, position, time, dwell=None, **step_kwargs
    ) -> Program:
        """A program from separately stored channels (the book's 分离存贮): the inverse of
        :meth:`channels` for a program of steps.

        Parameters
        ----------
        name : str
            Program name.
        sequence : sequence of str
            A label per step (``"#k"`` entries, as :meth:`channels` writes for unlabelled
            steps, give no label).
        position : array_like, shape (n, ...)
            The positions.
        time : array_like, shape (n,)
            Move times, s.
        dwell : array_like, shape (n,), optional
            Dwell times, s.
        **step_kwargs
            Passed to every :class:`Step` (e.g. ``motion="line"``).

        Returns
        -------
        Program
        """
        if isinstance(sequence, (str, bytes)) or not isinstance(sequence, Sequence):
            raise ControlError(
                f"sequence must be a list of labels (one per step), got {type(sequence).__name__}"
            )
        for lb in sequence:
            if lb is not None:
                _name(lb, "a label of the sequence")
        pos = _check.array(position, "position")
        n = len(sequence)
        t = _check.array(time, "time")
        d = np.zeros(n) if dwell is None else _check.array(dwell, "dwell")
        if pos.ndim == 0 or pos.shape[:1] != (n,) or t.shape != (n,) or d.shape != (n,):
            raise ControlError(
                f"channels of different lengths: sequence {n}, position {pos.shape}, time "
                f"{t.shape}, dwell {d.shape}"
            )
        labels = [None if (isinstance(s, str) and s.startswith("#")) else s for s in sequence]
        return cls(
            name,
            tuple(
                Step(p, float(tk), label=lb, dwell=float(dk), **step_kwargs)
                for p, tk, lb, dk in zip(pos, t, labels, d)
            ),
        )

    # ------------------------------------------------------------------ store
    def to_json(self) -> str:
        """The program as JSON text (round trip with :meth:`from_json`)."""
        return json.dumps(
            {"name": self.name, "items": [it.to_dict() for it in self.items]}, indent=1
        )

    @classmethod
    def from_json(cls, text: str) -> Program:
        """Read a program written by :meth:`to_json`.

        The text is bounded before it is parsed: at most :data:`MAX_PROGRAM_BYTES` characters
        and :data:`MAX_JSON_DEPTH` nested arrays/objects (a deeper document would exhaust the
        parser's recursion).

        Raises
        ------
        anthroarm.errors.ControlError
            Text that is not such a program (the message says what is wrong).
        """
        return cls._from_dict(parse_program_json(text))

    @classmethod
    def _from_dict(cls, d) -> Program:
        if not isinstance(d, dict):
            raise ControlError(f"not a stored program: a JSON {type(d).__name__}, not an object")
        try:
            items = d["items"]
            name = d["name"]
        except KeyError as exc:
            raise ControlError(f"not a stored program: no {exc.args[0]!r} entry") from None
        if not isinstance(items, list):
            raise ControlError(f"not a stored program: 'items' is a {type(items).__name__}")
        out = []
        for k, it in enumerate(items):
            if not isinstance(it, dict):
                raise ControlError(
                    f"stored program item {k} is a {type(it).__name__}, not an object"
                )
            kind = it.get("kind")
            try:
                if kind == "step":
                    out.append(
                        Step(
                            position=it["position"],
                            time=it["time"],
                            label=it.get("label"),
                            dwell=it.get("dwell", 0.0),
                            motion=it.get("motion", "joint"),
                            via=it.get("via"),
                            grip=it.get("grip"),
                        )
                    )
                elif kind == "jump":
                    out.append(Jump(it["label"], it.get("sensor")))
                elif kind == "call":
                    out.append(Call(it["name"]))
                else:
                    raise ControlError(
                        f"unknown item kind {_check.short(kind)} (step, jump or call)"
                    )
            except KeyError as exc:
                raise ControlError(
                    f"stored program item {k} ({kind}) has no {exc.args[0]!r} entry"
                ) from None
            except ControlError as exc:
                raise type(exc)(f"stored program item {k}: {exc}") from None
        return cls(_name(name, "a stored program's name"), tuple(out))

    def save(self, path) -> None:
        """Store the program as JSON, atomically (a reader sees the old file or the new one)."""
        atomic_write_text(path, self.to_json())

    @classmethod
    def load(cls, path) -> Program:
        """Read a program stored by :meth:`save`.

        Only a regular file of at most :data:`MAX_PROGRAM_BYTES` bytes is read (a folder, a
        FIFO or a device is refused without being read), in UTF-8, nested at most
        :data:`MAX_JSON_DEPTH` deep.

        Raises
        ------
        anthroarm.errors.ControlError
            The file is missing, not a regular file, too large, not UTF-8 or not a program; the
            message names the file.
        """

        def error(problem):
            return ControlError(f"{path}: {problem}")

        text = read_bounded(path, MAX_PROGRAM_BYTES, error=error, what="teach program")
        try:
            return cls.from_json(text)
        except ControlError as exc:
            raise type(exc)(f"{path}: {exc}") from None


def record(name: str, positions, times, labels=None, **step_kwargs) -> Program:
    """Teach a program point by point: one :class:`Step` per position with its move time.

    Parameters
    ----------
    name : str
        Program name.
    positions : sequence of array_like
        The taught positions.
    times : float or sequence of float
        Move time to each position, s (one value for all).
    labels : sequence of str or None, optional
        A label per position.
    **step_kwargs
        Passed to every :class:`Step` (e.g. ``motion="line"``).

    Returns
    -------
    Program
    """
    positions = list(positions)
    t = _check.array(times, "times (s)")
    if t.ndim == 0:
        t = np.full(len(positions), float(t))
    elif t.shape != (len(positions),):
        raise ControlError(
            f"times must be one value or one per position ({len(positions)}), got shape {t.shape}"
        )
    labels = [None] * len(positions) if labels is None else list(labels)
    if len(labels) != len(positions):
        raise ControlError(f"{len(labels)} labels for {len(positions)} positions")
    return Program(
        name,
        tuple(
            Step(p, float(tk), label=lb, **step_kwargs) for p, tk, lb in zip(positions, t, labels)
        ),
    )


# ---------------------------------------------------------------------------- playback
@dataclass(frozen=True)
class ExecutedStep:
    """One step as played back: which program and item, which cycle, and the step itself."""

    program: str
    index: int
    cycle: int
    step: Step


@dataclass(frozen=True)
class Playback:
    """The result of a playback: the executed steps in order.

    Attributes
    ----------
    mode : str
        ``"fixed"``, ``"select"``, ``"jump"``, ``"subroutine"`` or ``"random access"``.
    executed : tuple of ExecutedStep
        The steps in the order played.
    status : str
        ``"done"``, or ``"step limit"`` when ``max_steps`` stopped an endless loop.
    """

    mode: str
    executed: tuple
    status: str

    @property
    def labels(self) -> list:
        """The played steps' labels (None where a step has none)."""
        return [e.step.label for e in self.executed]

    @property
    def positions(self) -> np.ndarray:
        """The played positions, stacked."""
        return np.array([e.step.position for e in self.executed])

    @property
    def duration(self) -> float:
        """Total time: moves (except the first step's, which is the start) and dwells, s."""
        ex = self.executed
        return float(sum(e.step.time for e in ex[1:]) + sum(e.step.dwell for e in ex))

    def trajectory(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Sample the played path every ``dt`` seconds, starting at the first step's position
        (module docstring for the motions).

        Returns
        -------
        t : numpy.ndarray, shape (N,)
            Times, s.
        positions : numpy.ndarray, shape (N, ...)
            The positions at those times (joint vectors, points or 4×4 poses).
        """
        dt = _check.positive(dt, "dt (s)")
        ex = [e.step for e in self.executed]
        if not ex:
            raise ControlError("nothing was played back")
        durations = [st.time for st in ex[1:] if st.time > 0] + [
            st.dwell for st in ex if st.dwell > 0
        ]
        total = 1.0 + sum(_check.n_per(d, dt) for d in durations)
        _check.samples(
            total,
            ex[0].position.size,
            f"trajectory(dt={dt:g} s) over {self.duration:g} s",
            "give a larger dt (s)",
        )
        ts, ps = [np.array([0.0])], [ex[0].position[None]]
        t0 = 0.0

        def segment(duration, positions_at):
            nonlocal t0
            n = int(_check.n_per(duration, dt))
            s = np.arange(1, n + 1) / n
            ts.append(t0 + duration * s)
            ps.append(positions_at(s))
            t0 += duration

        prev = None
        for st in ex:
            if prev is not None and st.time > 0:
                segment(st.time, lambda s, a=prev, b=st: _move(a, b, s))
            if st.dwell > 0:
                segment(st.dwell, lambda s, b=st: np.repeat(b.position[None], s.size, axis=0))
            prev = st
        return np.concatenate(ts), np.concatenate(ps)

    def joint_path(
        self, robot, dt: float, q0=None, frame=None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Play a program of 4×4 poses on an arm: :meth:`trajectory` sampled every ``dt``
        seconds, each pose solved by :func:`~anthroarm.ik.solve.api.solve` warm-started from the
        previous sample's joints (continuity along the path).

        Parameters
        ----------
        robot : anthroarm.Robot
            The arm; poses are of its tool frame (or ``frame``) in its base frame.
        dt : float
            Sample time, s.
        q0 : array_like, optional
            Joints to start the first solve from (default the robot's neutral configuration).
        frame : str, optional
            The frame the poses are of (default the robot's tool).

        Returns
        -------
        t : numpy.ndarray, shape (N,)
            Times, s.
        q : numpy.ndarray, shape (N, nq)
            Joint values (rad, m); a sample whose solve failed repeats the last good joints.
        ok : numpy.ndarray of bool, shape (N,)
            Whether each solve met the IK tolerances.
        """
        t, P = self.trajectory(dt)
        if P.shape[1:] != (4, 4):
            raise ControlError(
                f"joint_path needs a program of 4x4 poses, this one stores positions of shape "
                f"{P.shape[1:]}"
            )
        q = robot.neutral() if q0 is None else _check.array(q0, "q0")
        qs, ok = [], []
        for T in P:
            r = solve(robot, T, q0=q, frame=frame)
            if r.success:
                q = r.q
            qs.append(np.array(q, dtype=float))
            ok.append(bool(r.success))
        return t, np.array(qs), np.array(ok)


def _move(a: Step, b: Step, s: np.ndarray) -> np.ndarray:
    """Positions from ``a`` to ``b`` at the fractions ``s`` with ``b``'s motion."""
    p, q = a.position, b.position
    if b.motion == "joint" or (b.motion == "line" and p.shape == (3,)):
        return _lerp(p, q, s)
    if p.shape == (3,):
        return circle_through(p, b.via, q).points(s)
    if b.motion == "line":
        return line_poses(p, q, s)
    return arc_poses(p, b.via, q, s)


def _run(
    program: Program,
    mode: str,
    *,
    library=None,
    sensors=None,
    cycles: int = 1,
    max_steps: int = 100_000,
) -> Playback:
    """Execute items with a call stack; jumps test sensors; stop after ``max_steps`` steps or
    ``ITEMS_PER_STEP * max_steps`` items (steps, jumps, calls)."""
    if not isinstance(program, Program):
        raise ControlError(f"program must be a Program, got {_check.short(program)}")
    library = library_of(library, Program)
    cycles = _check.count(cycles, "cycles", 1)
    max_steps = _check.count(max_steps, "max_steps", 1)
    for prog in [program, *library.values()]:
        check_calls(prog, library, Call)
    check_call_graph(
        program, library, lambda prog: [it.name for it in prog.items if isinstance(it, Call)]
    )
    out: list[ExecutedStep] = []
    items_left = ITEMS_PER_STEP * max_steps
    for cycle in range(int(cycles)):
        stack: list[tuple[Program, int]] = [(program, 0)]
        while stack:
            prog, k = stack.pop()
            if k >= len(prog.items):
                continue
            items_left -= 1
            if items_left < 0:
                return Playback(mode, tuple(out), "step limit")
            it = prog.items[k]
            if isinstance(it, Step):
                out.append(ExecutedStep(prog.name, k, cycle, it))
                if len(out) >= max_steps:
                    return Playback(mode, tuple(out), "step limit")
                stack.append((prog, k + 1))
            elif isinstance(it, Jump):
                on = True if it.sensor is None else sensor_signal(sensors, it.sensor, cycle)
                stack.append((prog, prog._labels[it.label] if on else k + 1))
            else:
                stack.append((prog, k + 1))
                stack.append((library[it.name], 0))
    return Playback(mode, tuple(out), "done")


def play_fixed(program: Program, cycles: int = 1) -> Playback:
    """Fixed-sequence playback (固定顺序再现): every step in taught order, ``cycles`` times.

    Raises
    ------
    anthroarm.errors.PlaybackError
        The program has jumps or calls (use :func:`play_jump` / :func:`play_subroutines`).
    """
    if any(not isinstance(it, Step) for it in program.items):
        raise PlaybackError(
            f"program {program.name!r} has jumps or calls; a fixed sequence has only steps "
            "(use play_jump or play_subroutines)"
        )
    return _run(program, "fixed", cycles=cycles)


def play_select(
    programs: Mapping[str, Program] | Sequence[Program], selector, sensors=None, cycles: int = 1
) -> Playback:
    """Program select (程序选择, Fig. 9-9 (a)): play the program that ``selector`` picks.

    Parameters
    ----------
    programs : mapping name → Program, or sequence of Program
        The taught programs.
    selector : str or callable
        A program name, or ``selector(sensors)`` returning one (e.g. from a size/weight sensor
        as in the book's Fig. 9-10: program A or B).
    sensors : mapping or callable, optional
        Sensor signals, passed to ``selector`` and to the program's jumps.
    cycles : int
        Number of cycles.

    Raises
    ------
    anthroarm.errors.PlaybackError
        The selected name is not a program (the message lists them).
    """
    if isinstance(programs, Mapping):
        lib = library_of(programs, Program)
    else:
        progs = list(programs)
        for p in progs:
            if not isinstance(p, Program):
                raise ControlError(f"programs must be Programs, got {_check.short(p)}")
        lib = {p.name: p for p in progs}
    name = selector(sensors) if callable(selector) else selector
    if not isinstance(name, str):
        raise PlaybackError(
            f"the selector must give a program name (a string), got {_check.short(name)}; "
            f"programs: {sorted(lib)}"
        )
    if name not in lib:
        raise PlaybackError(
            f"program {name!r} was selected but does not exist; programs: {sorted(lib)}"
        )
    return _run(lib[name], "select", library=lib, sensors=sensors, cycles=cycles)


def play_jump(program: Program, sensors, cycles: int = 1, max_steps: int = 100_000) -> Playback:
    """Program jump (程序跳越, Fig. 9-9 (b)): the taught order, but a :class:`Jump` goes to its
    label when its sensor is on.

    Parameters
    ----------
    program : Program
    sensors : mapping or callable
        ``{name: bool | sequence (one value per cycle, repeating) | callable(cycle)}`` or
        ``sensors(name, cycle) -> bool``.
    cycles : int
        Number of cycles (the book: a packing job changes part of its work every cycle).
    max_steps : int
        Stop (status ``"step limit"``) after this many steps: a jump backwards can loop forever.
    """
    return _run(program, "jump", sensors=sensors, cycles=cycles, max_steps=max_steps)


def play_subroutines(
    subroutines: Mapping[str, Program], order: Sequence[str], cycles: int = 1, sensors=None
) -> Playback:
    """Subroutine playback (子程序方式, Fig. 9-9 (c)): run the stored ``order`` of subroutines.

    Raises
    ------
    anthroarm.errors.PlaybackError
        A name in ``order`` (or a :class:`Call`) that is not a subroutine.
    """
    if isinstance(order, (str, bytes)) or not isinstance(order, Sequence):
        raise ControlError(f"order must be a list of subroutine names, got {_check.short(order)}")
    main = Program("main", tuple(Call(_name(n, "a name of the order")) for n in order))
    return _run(main, "subroutine", library=subroutines, sensors=sensors, cycles=cycles)


def play_random_access(
    points: Mapping[str, Step], start: str, next_address: Callable, max_steps: int = 10_000
) -> Playback:
    """Random access (随机存取): every unit motion has an address; after each one
    ``next_address(address, history)`` returns the next address, or None to stop.

    Parameters
    ----------
    points : mapping address → Step
        The addressed unit motions.
    start : str
        First address.
    next_address : callable
        ``next_address(current_address, history_of_addresses) -> address or None``; the robot's
        decision from its sensors.  The history is a read-only sequence of the addresses so
        far (indexing, slicing, ``len``, iteration and ``==`` with a tuple work as on a tuple;
        it is a view, not a copy, so a long playback stays linear in time).
    max_steps : int
        Stop (status ``"step limit"``) after this many steps.

    Raises
    ------
    anthroarm.errors.PlaybackError
        An address that does not exist (the message lists them).
    """
    pts = dict(points)
    max_steps = _check.count(max_steps, "max_steps", 1)
    prog_name = "random access"
    out: list[ExecutedStep] = []
    hist: list[str] = []
    addr = start
    if not callable(next_address):
        raise ControlError(f"next_address must be callable, got {_check.short(next_address)}")
    while addr is not None:
        if not isinstance(addr, str) and not hashable(addr):
            raise PlaybackError(f"address {_check.short(addr)} is not an address")
        if addr not in pts:
            raise PlaybackError(f"address {addr!r} does not exist; addresses: {sorted(pts)}")
        step = pts[addr]
        if not isinstance(step, Step):
            raise ControlError(f"address {addr!r} does not hold a Step: {step!r}")
        hist.append(addr)
        out.append(ExecutedStep(prog_name, len(out), 0, step))
        if len(out) >= max_steps:
            return Playback("random access", tuple(out), "step limit")
        addr = next_address(addr, History(hist, len(hist)))
    return Playback("random access", tuple(out), "done")
