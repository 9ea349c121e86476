"""The declared layers (DESIGN.md), checked on the import graph built by ``grimp``: a module
imports only from its own layer or the layers below (imports inside functions count too).

Layers, top to bottom: faces · applications · algorithms · model · foundation.  The upward
imports still open are listed in :data:`KNOWN` (issue 29 item 1); nothing may be added there,
and an entry that no longer holds fails the test, so it is deleted with the import.
"""

from __future__ import annotations

import grimp
import pytest

LAYERS = [
    ("faces", ["cli", "viewer"]),
    ("applications", ["prosthesis", "batch", "crosscheck"]),
    (
        "algorithms",
        ["kinematics", "ik", "dynamics", "mechanisms", "design", "hand", "motion", "control"]
        + ["emg", "trajectory", "collision"],
    ),
    ("model", ["models", "robot", "chain", "serial_chain", "urdf_io", "chain_kernels", "osim"]),
    (
        "foundation",
        ["errors", "_io", "spatial", "codegen", "cache", "threads", "jit", "check_rows"]
        + ["joint_kinds", "optional", "input_checks"],
    ),
]
LEVEL = {m: i for i, (_, ms) in enumerate(LAYERS) for m in ms}

#: (importer, imported) imports that still run upward: the debt of issue 29 item 1
KNOWN = {
    ("anthroarm.emg.simulate", "anthroarm.viewer"),
    ("anthroarm.hand.demo", "anthroarm.viewer"),
    ("anthroarm.hand.demo", "anthroarm.viewer.browser"),
    ("anthroarm.prosthesis.report", "anthroarm.viewer"),
}


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


def test_the_check_sees_an_upward_import(graph):
    """Not blind: an algorithm importing the CLI is reported."""
    edge = dict(importer="anthroarm.ik.cells", imported="anthroarm.cli")
    graph.add_import(**edge)
    try:
        assert ("anthroarm.ik.cells", "anthroarm.cli") in upward(graph)
    finally:
        graph.remove_import(**edge)
