"""Import circles once closed only by imports inside functions stay broken (issue 29):
``chain`` ↔ ``kinematics.batched`` (the batched :class:`~anthroarm.serial_chain.SerialChain`
moved down into the model layer: ``chain`` and ``kinematics.batched`` both import it from
``serial_chain``, which imports neither), ``dynamics.lagrange`` ↔ ``dynamics.lagrange_sympy``
(the sympy view no longer imports the derivation, even for type checking), ``robot`` ↔
``models`` (``load`` reads the catalog at module level; no catalog module imports ``robot``)
and ``kinematics.book_fk`` ↔ ``kinematics.error_propagation`` (since the printed forms moved to
``models``, neither imports the other).

Standard library only: the import graph is read with :mod:`ast` from ``src/anthroarm`` (every
``import`` statement, at module level, inside a function or under ``TYPE_CHECKING``).  The
contract for the whole package (no circle at all) is ``test_no_import_circle`` of
``tests/packaging/test_layers.py``, over grimp's graph; this file guards these pairs by name."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
PACKAGE = "anthroarm"

#: (higher, lower): the higher module may import the lower one, never the other way round
PAIRS = [
    ("anthroarm.chain", "anthroarm.serial_chain"),
    ("anthroarm.kinematics.batched", "anthroarm.serial_chain"),
    ("anthroarm.dynamics.lagrange", "anthroarm.dynamics.lagrange_sympy"),
    ("anthroarm.robot", "anthroarm.models"),
]
#: modules that share no import at all, in either direction
APART = [
    ("anthroarm.kinematics.error_propagation", "anthroarm.kinematics.book_fk"),
    ("anthroarm.chain", "anthroarm.kinematics.batched"),
]


def _modules(src: Path) -> dict[str, Path]:
    out = {}
    for path in (src / PACKAGE).rglob("*.py"):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def import_graph(src: Path = SRC) -> dict[str, dict[str, bool]]:
    """module -> {imported module: True if imported at module level (run on import)}, inside the
    package only; ``from pkg import name`` counts ``pkg.name`` when that is a module.  As in
    grimp, importing ``a.b.c`` is an edge to ``a.b.c`` only (not to the packages above it,
    which would put every module on a circle through ``anthroarm/__init__``)."""
    mods = _modules(src)
    graph: dict[str, dict[str, bool]] = {}
    for name, path in mods.items():
        is_pkg = path.name == "__init__.py"
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        top = set(map(id, tree.body))
        edges: dict[str, bool] = {}

        def add(target: str, at_top: bool, edges=edges) -> None:
            if target in mods and target != name:
                edges[target] = edges.get(target, False) or at_top

        for node in ast.walk(tree):
            at_top = id(node) in top
            if isinstance(node, ast.Import):
                for a in node.names:
                    add(a.name, at_top)
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_pkg else name.split(".")[:-1]
                    base = base[: len(base) - (node.level - 1)]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                add(mod, at_top)
                for a in node.names:
                    if f"{mod}.{a.name}" in mods:
                        add(f"{mod}.{a.name}", at_top)
        graph[name] = edges
    return graph


def _reaches(graph, start: str, goal: str) -> bool:
    seen, todo = {start}, [start]
    while todo:
        for t in graph.get(todo.pop(), {}):
            if t not in seen:
                if t == goal:
                    return True
                seen.add(t)
                todo.append(t)
    return False


@pytest.fixture(scope="module")
def graph():
    return import_graph()


def test_the_graph_sees_both_kinds_of_import(graph):
    assert graph["anthroarm.chain"]["anthroarm.serial_chain"] is True
    assert graph["anthroarm.chain"]["anthroarm.chain_kernels"] is False  # compiled on first use


@pytest.mark.parametrize("higher, lower", PAIRS)
def test_no_circle(graph, higher, lower):
    assert lower in graph[higher], f"{higher} no longer imports {lower}: update PAIRS"
    assert higher not in graph[lower], f"{lower} imports {higher} (at any level)"
    assert graph[higher][lower], f"{higher} imports {lower} inside a function"
    # nor round other modules, through imports at any level
    assert not _reaches(graph, lower, higher), f"{lower} reaches {higher} through other modules"


@pytest.mark.parametrize("a, b", APART)
def test_apart(graph, a, b):
    assert not _reaches(graph, a, b), f"{a} reaches {b}"
    assert not _reaches(graph, b, a), f"{b} reaches {a}"
