"""The declared layers (DESIGN.md), checked on the import graph built by ``grimp``: a module
imports only from its own layer or the layers below (imports inside functions count too), and
no modules import each other in a circle (:func:`test_no_import_circle`).

Layers, top to bottom: faces · applications · algorithms · model · foundation.  The upward
imports still open are listed in :data:`KNOWN` (issue 29 item 1); nothing may be added there,
and an entry that no longer holds fails the test, so it is deleted with the import.
"""

from __future__ import annotations

import grimp
import pytest

LAYERS = [
    ("faces", ["cli", "viewer"]),
    ("applications", ["prosthesis", "batch", "crosscheck", "warmup"]),
    (
        "algorithms",
        ["kinematics", "ik", "dynamics", "mechanisms", "design", "hand", "motion", "control"]
        + ["emg", "trajectory", "collision", "muscles"],
    ),
    (
        "model",
        ["models", "loading", "robot", "chain", "serial_chain", "urdf_io", "chain_kernels", "osim"],
    ),
    (
        "foundation",
        [
            "errors",
            "_io",
            "spatial",
            "codegen",
            "cache",
            "threads",
            "jit",
            "jit_arrays",
            "check_rows",
        ]
        + ["joint_kinds", "optional", "input_checks"],
    ),
]
LEVEL = {m: i for i, (_, ms) in enumerate(LAYERS) for m in ms}

#: (importer, imported) imports that still run upward: none left (issue 29 item 1); nothing may
#: be added here
KNOWN: set[tuple[str, str]] = set()


#: (importer, imported) imports that still close a circle (any path back from the imported
#: module to the importer); nothing may be added, and an entry that no longer closes one fails
KNOWN_CIRCLE_EDGES: set[tuple[str, str]] = set()  # none left (anthroarm.load: anthroarm.loading)


def _top(module: str) -> str:
    return module.split(".")[1]


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("anthroarm")


def upward(graph) -> set[tuple[str, str]]:
    out = set()
    for imp in graph.find_matching_direct_imports(import_expression="anthroarm.** -> anthroarm.**"):
        a, b = imp["importer"], imp["imported"]
        if b == "anthroarm" or _top(a) == _top(b):
            continue
        if LEVEL[_top(b)] < LEVEL[_top(a)]:
            out.add((a, b))
    return out


def test_every_package_has_a_layer(graph):
    tops = {_top(m) for m in graph.modules if m.count(".")}
    assert tops <= set(LEVEL), f"modules without a layer: {sorted(tops - set(LEVEL))}"


def test_no_new_upward_import(graph):
    found = upward(graph)
    new = sorted(found - KNOWN)
    assert not new, "imports that run upward:\n" + "\n".join(f"{a} -> {b}" for a, b in new)
    gone = sorted(KNOWN - found)
    assert not gone, "no longer imported, delete from KNOWN: " + ", ".join(map(str, gone))


def circles(graph, without=()) -> list[list[str]]:
    """The strongly connected components of more than one module of the import graph (imports
    inside functions and under ``TYPE_CHECKING`` included), without the edges ``without``."""
    skip = set(without)
    adj = {
        m: sorted(t for t in graph.find_modules_directly_imported_by(m) if (m, t) not in skip)
        for m in graph.modules
    }
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    for root in sorted(adj):
        if root in index:
            continue
        work = [(root, iter(adj[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on.add(root)
        while work:  # Tarjan's algorithm without recursion
            v, it = work[-1]
            for w in it:
                if w not in adj:
                    continue
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(adj[w])))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_import_circle(graph):
    found = circles(graph, without=KNOWN_CIRCLE_EDGES)
    assert not found, "modules that import each other in a circle:\n" + "\n".join(
        " <-> ".join(c) for c in found
    )
    for a, b in sorted(KNOWN_CIRCLE_EDGES):
        assert graph.direct_import_exists(importer=a, imported=b), f"{a} no longer imports {b}"
        assert graph.chain_exists(importer=b, imported=a), (
            f"{a} -> {b} closes no circle any more: delete it from KNOWN_CIRCLE_EDGES"
        )


def test_the_circle_check_sees_a_circle(graph):
    """Not blind: the catalog importing an algorithm that reads robots closes a circle."""
    edge = dict(importer="anthroarm.models", imported="anthroarm.ik.cells")
    graph.add_import(**edge)
    try:
        found = circles(graph, without=KNOWN_CIRCLE_EDGES)
        assert any({"anthroarm.models", "anthroarm.ik.cells"} <= set(c) for c in found)
    finally:
        graph.remove_import(**edge)


def test_the_check_sees_an_upward_import(graph):
    """Not blind: an algorithm importing the CLI is reported."""
    edge = dict(importer="anthroarm.ik.cells", imported="anthroarm.cli")
    graph.add_import(**edge)
    try:
        assert ("anthroarm.ik.cells", "anthroarm.cli") in upward(graph)
    finally:
        graph.remove_import(**edge)
