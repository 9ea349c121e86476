"""Guards of :mod:`anthroarm.control.teach`: the bounds on stored programs (size, JSON nesting),
the call-graph check (cycles, depth), and the playback's item budget.  Public names are
re-exported by :mod:`anthroarm.control.teach`."""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError, PlaybackError

#: the largest stored program :meth:`Program.load` / :meth:`Program.from_json` read, bytes
MAX_PROGRAM_BYTES = 64 * 2**20
#: the deepest nesting of JSON arrays/objects in a stored program (a program needs 5)
MAX_JSON_DEPTH = 32
#: the deepest chain of subroutine calls a playback accepts (main → a → b → …)
MAX_CALL_DEPTH = 100
#: a playback stops (status ``"step limit"``) after this many items (steps, jumps and calls)
#: per allowed step: a program of calls and jumps that plays no step cannot run for ever
ITEMS_PER_STEP = 4


def name(x, what: str) -> str:
    if not isinstance(x, str):
        raise ControlError(f"{what} must be a string, got {type(x).__name__} {_check.short(x)}")
    return x


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')


def json_depth(text: str) -> int:
    """The deepest nesting of arrays/objects in JSON ``text``, brackets inside strings not
    counted (one vectorised pass; an unterminated string only overestimates)."""
    b = np.frombuffer(_JSON_STRING.sub('""', text).encode("utf-8"), dtype=np.uint8)
    step = (b == ord("[")).astype(np.int64) + (b == ord("{"))
    step -= (b == ord("]")).astype(np.int64) + (b == ord("}"))
    return int(np.cumsum(step).max(initial=0))


def parse_program_json(text):
    if isinstance(text, (bytes, bytearray)):
        try:
            text = bytes(text).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ControlError(f"a stored program must be UTF-8 text ({exc})") from None
    if not isinstance(text, str):
        raise ControlError(f"a stored program is JSON text, got {type(text).__name__}")
    if len(text) > MAX_PROGRAM_BYTES:
        raise ControlError(
            f"the program text has {len(text)} characters, more than the bound of "
            f"{MAX_PROGRAM_BYTES} (MAX_PROGRAM_BYTES)"
        )
    depth = json_depth(text)
    if depth > MAX_JSON_DEPTH:
        raise ControlError(
            f"not a stored program: JSON nested {depth} levels deep, more than the bound of "
            f"{MAX_JSON_DEPTH} (a program needs 5)"
        )
    try:
        return json.loads(text)
    except RecursionError:  # only if the bound were above the parser's limit
        raise ControlError("not a stored program: JSON nested too deeply") from None
    except ValueError as exc:  # JSONDecodeError, and ints beyond Python's digit limit
        raise ControlError(f"not a stored program: {exc}") from None


def check_call_graph(program, library: Mapping, calls_of: Callable) -> None:
    """Refuse a call cycle reachable from ``program`` (``calls_of(prog)`` lists the names a
    program calls) (a subroutine that calls itself, directly
    or through others: it would never return) and call chains deeper than
    :data:`MAX_CALL_DEPTH`; each message names the chain.  One iterative depth-first search."""
    # the main program is its library entry when it is one; else a node of its own (the main of
    # play_subroutines may share a name with a subroutine)
    root = program.name if library.get(program.name) is program else object()

    def calls(node):
        return list(dict.fromkeys(calls_of(program if node == root else library[node])))

    def label(node):
        return program.name if node == root else node

    depth: dict = {}  # finished node -> longest chain below it (in calls)
    on_path: dict = {root: 0}
    path = [root]
    todo = [iter(calls(root))]
    while todo:
        nxt = next(todo[-1], None)
        if nxt is None:  # all callees done
            node = path.pop()
            todo.pop()
            del on_path[node]
            depth[node] = 1 + max((depth[c] for c in calls(node)), default=-1)
            if depth[node] > MAX_CALL_DEPTH:
                chain = [label(n) for n in path] + [label(node)]
                raise PlaybackError(
                    f"subroutine calls nested deeper than {MAX_CALL_DEPTH} "
                    f"(MAX_CALL_DEPTH): {depth[node]} levels below "
                    f"{' -> '.join(chain[-3:])}"
                )
            continue
        if nxt in on_path:
            cycle = [label(n) for n in path[on_path[nxt] :]] + [nxt]
            raise PlaybackError(
                "subroutines call each other in a cycle and would never return: "
                + " -> ".join(cycle)
            )
        if nxt in depth:
            continue
        on_path[nxt] = len(path)
        path.append(nxt)
        todo.append(iter(calls(nxt)))


def hashable(x) -> bool:
    try:
        hash(x)
    except TypeError:
        return False
    return True


class History(Sequence):
    """A read-only view of the first ``n`` addresses of a growing list (tuple-like)."""

    __slots__ = ("_list", "_n")

    def __init__(self, lst: list, n: int):
        self._list, self._n = lst, n

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, k):
        if isinstance(k, slice):
            return tuple(self._list[: self._n][k])
        if not -self._n <= k < self._n:
            raise IndexError("history index out of range")
        return self._list[k % self._n]

    def __eq__(self, other) -> bool:
        if isinstance(other, (tuple, list, History)):
            return tuple(self) == tuple(other)
        return NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return repr(tuple(self))


def sensor_signal(sensors, name: str, cycle: int) -> bool:
    if callable(sensors) and not isinstance(sensors, Mapping):
        return bool(sensors(name, cycle))
    if sensors is None or name not in sensors:
        known = [] if sensors is None else sorted(sensors)
        raise PlaybackError(f"sensor {name!r} has no signal; sensors: {known}")
    v = sensors[name]
    if callable(v):
        return bool(v(cycle))
    if isinstance(v, (list, tuple, np.ndarray)):
        if len(v) == 0:
            raise PlaybackError(f"sensor {name!r} has an empty list of signals (one per cycle)")
        return bool(v[cycle % len(v)])
    return bool(v)


def library_of(library, program_type) -> dict:
    if library is None:
        return {}
    if not isinstance(library, Mapping):
        raise ControlError(f"the subroutines must be a mapping name -> Program, got {library!r}")
    for k, v in library.items():
        if not isinstance(v, program_type):
            raise ControlError(f"subroutine {k!r} is not a Program: {_check.short(v)}")
    return dict(library)


def check_calls(program, library: Mapping, call_type) -> None:
    """Every call of ``program`` names a subroutine of ``library``."""
    for k, it in enumerate(program.items):
        if isinstance(it, call_type) and it.name not in library:
            raise PlaybackError(
                f"program {program.name!r}: item {k} calls subroutine {it.name!r}, which does not "
                f"exist; subroutines: {sorted(library)}"
            )
