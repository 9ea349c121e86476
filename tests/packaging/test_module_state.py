"""State on the Robot, not in modules (issues 28 item 5, 29 item 5): a module-level container
that functions change at run time exists only where this file says why.  Per-robot derived data
(plans, solvers, workspaces) lives on the robot (:meth:`anthroarm.robot.Robot.derived`), so it
goes with the robot and is remade when its chain or tool change."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src" / "anthroarm"

#: (file, name) -> why a process-wide container is the design
ALLOWED = {
    ("cache.py", "_CC_IDS"): "the disk cache: compiler identities, probed once per process",
    ("cache.py", "_STATE"): "the disk cache: its fallback folder and refusals, per process",
    ("threads.py", "_POOL"): "the one thread pool of the process (grown with $ANTHROARM_THREADS)",
    ("dynamics/ccode.py", "_LIBS"): "compiled libraries by source digest (no robot in them)",
    ("dynamics/lagrange.py", "_MEMO"): "generated modules by model digest (no robot in them)",
    ("ik/qp/_qpgen2.py", "_SELFTESTED"): "a per-size self-test of a C routine, once per process",
    ("viewer/meshes.py", "_PACKED"): "mesh files packed for the browser, by path and mtime",
    ("batch/describe.py", "_cache"): "job descriptions by value (bounded LRU, CACHE_SIZE)",
    ("batch/engine.py", "_trim_relaxed"): "whether glibc's malloc trim was relaxed in a worker",
}

#: still keyed by Robot in a module: to move onto the robot (Robot.derived)
KNOWN: set[tuple[str, str]] = set()

MUTATORS = {"append", "extend", "update", "pop", "popitem", "setdefault", "clear", "add"}
MUTATORS |= {"discard", "remove", "insert", "move_to_end"}
CONTAINERS = ("dict", "list", "set", "WeakKeyDictionary", "WeakValueDictionary", "defaultdict")
CONTAINERS += ("OrderedDict", "deque")


def _module_containers(tree) -> set[str]:
    out = set()
    for n in tree.body:
        if isinstance(n, ast.Assign) and len(n.targets) == 1:
            target, value = n.targets[0], n.value
        elif isinstance(n, ast.AnnAssign) and n.value is not None:
            target, value = n.target, n.value
        else:
            continue
        if not isinstance(target, ast.Name):
            continue
        if isinstance(value, (ast.Dict, ast.List, ast.Set)) or (
            isinstance(value, ast.Call) and ast.unparse(value.func).split(".")[-1] in CONTAINERS
        ):
            out.add(target.id)
    return out


def changed_at_run_time(tree) -> set[str]:
    names = _module_containers(tree)
    changed = set()
    for f in ast.walk(tree):
        if not isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for n in ast.walk(f):
            if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute):
                base = n.func.value
                if isinstance(base, ast.Name) and base.id in names and n.func.attr in MUTATORS:
                    changed.add(base.id)
            targets = n.targets if isinstance(n, (ast.Assign, ast.Delete)) else []
            targets = [n.target] if isinstance(n, ast.AugAssign) else targets
            for t in targets:
                if isinstance(t, ast.Subscript) and isinstance(t.value, ast.Name):
                    if t.value.id in names:
                        changed.add(t.value.id)
    return changed


def scan() -> set[tuple[str, str]]:
    found = set()
    for p in sorted(SRC.rglob("*.py")):
        rel = p.relative_to(SRC).as_posix()
        found |= {(rel, name) for name in changed_at_run_time(ast.parse(p.read_text()))}
    return found


def test_module_state_only_where_it_is_the_design():
    found = scan()
    unexplained = sorted(found - set(ALLOWED) - KNOWN)
    assert not unexplained, f"module-level state changed at run time, say why: {unexplained}"
    stale = sorted((set(ALLOWED) | KNOWN) - found)
    assert not stale, f"no longer there, delete from the lists: {stale}"


def test_the_scan_sees_a_module_table():
    tree = ast.parse(
        "_T = {}\n\ndef f(robot):\n    _T[id(robot)] = 1\n\n_L = []\ndef g():\n    _L.append(1)\n"
    )
    assert changed_at_run_time(tree) == {"_T", "_L"}
