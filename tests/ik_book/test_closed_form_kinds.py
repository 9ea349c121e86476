"""The kinds of closed form (issue 28 items 5 and 6): every kind in the registry implements the one
interface (:class:`anthroarm.ik.closed.kinds.ClosedFormKind`), the registry is the one place the
kinds are listed, no module of ik/ compares a kind's name, each IK-Geo class is solved by exactly
one kind, a new kind is one class and one registry line, and the closed-form modules stay small
(≤ 800 lines a file, ≤ 80 lines a function unless a comment above it says why, no import inside a
function but an optional or heavy one).

Oracles: the source itself (ast); the catalog arms' solutions by FK (Pinocchio)."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.ik import closed_form as cf
from anthroarm.ik import geometric as geo
from anthroarm.ik.closed import kinds as kinds_pkg
from anthroarm.ik.closed.kinds import KINDS, ClosedForm, ClosedFormKind
from anthroarm.ik.closed.kinds.planar import Planar2R

IK_DIR = Path(cf.__file__).parent
CLOSED_DIR = IK_DIR / "closed"
#: the modules of the closed form (this work's scope for size and imports)
CLOSED_FILES = [IK_DIR / "closed_form.py", *sorted(CLOSED_DIR.rglob("*.py"))]
#: the names the kinds had as strings before the registry
OLD_KIND_NAMES = {"geo", "srs", "planar"}
#: imports a function of the closed form may make, and why
LOCAL_IMPORTS = {
    "scipy.optimize": "~1 s of import time paid only by a pose with a candidate to polish"
}


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.name)
def test_every_registered_kind_implements_the_interface(kind):
    cls = type(kind)
    assert isinstance(kind, ClosedFormKind) and not inspect.isabstract(cls)
    for method in ("plan", "form", "solve_batch"):  # what each kind must say for itself
        assert getattr(cls, method) is not getattr(ClosedFormKind, method), (cls, method)
    for method in (
        "labels",
        "held_joint",
        "one_call",
        "solve_one",
        "nearest",
        "nearest_swivel",
        "outside",
        "tolerance_note",
    ):
        assert callable(getattr(kind, method))
    for flag in ("swivel", "position_only", "checks_rotation", "rescues"):
        assert isinstance(getattr(kind, flag), bool), flag
    assert isinstance(kind.name, str) and kind.name
    assert 0.0 < kind.cost_us < float("inf")


def test_kind_names_are_unique():
    names = [k.name for k in KINDS]
    assert len(set(names)) == len(names)
    assert len({type(k) for k in KINDS}) == len(KINDS)


def test_every_ik_geo_class_is_solved_by_exactly_one_kind():
    claims = [c for k in KINDS for c in getattr(k, "classes", ())]
    assert sorted(claims) == sorted(geo.SOLVED)


def _compared_strings(node: ast.Compare) -> set:
    out = set()
    for side in (node.left, *node.comparators):
        if isinstance(side, ast.Constant) and isinstance(side.value, str):
            out.add(side.value)
        elif isinstance(side, (ast.Tuple, ast.List, ast.Set)):
            out |= {
                e.value
                for e in side.elts
                if isinstance(e, ast.Constant) and isinstance(e.value, str)
            }
    return out


def test_no_string_comparison_of_kind_names_in_ik():
    """The kinds are told apart by their attributes, never by comparing a name: no ``==``,
    ``!=``, ``in`` or ``not in`` against "geo", "srs" or "planar" (nor a registry name) in ik/."""
    names = OLD_KIND_NAMES | {k.name for k in KINDS}
    hits = []
    for path in sorted(IK_DIR.rglob("*.py")):
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.Compare) and _compared_strings(node) & names:
                hits.append(f"{path.relative_to(IK_DIR)}:{node.lineno}")
    assert not hits, hits


def test_the_registry_is_the_one_place_kinds_are_listed():
    """Each kind's class is instantiated once, in the registry module, and closed_form reads
    that table."""
    kind_classes = {type(k).__name__ for k in KINDS}
    registry = Path(kinds_pkg.__file__)
    where = {}
    for path in sorted(IK_DIR.rglob("*.py")):
        for node in ast.walk(_tree(path)):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id in kind_classes
            ):
                where.setdefault(node.func.id, []).append(path)
    assert where == {c: [registry] for c in kind_classes}
    assert cf.KINDS is KINDS


@pytest.mark.parametrize(
    "name", ["planar2r", "human_arm7", "sixr_arm", "prosthetic_arm", "ur5", "panda"]
)
def test_an_arm_is_solved_by_its_registered_kind(name):
    robot = aa.load(name)
    s = cf._solver(robot)
    assert s.kind in KINDS
    first = next(k for k in KINDS if k.plan(robot) is not None)  # the registry's order
    assert s.kind is first and s.form == first.form(s.plan)
    assert len(s.kind.labels(s.plan)) == s.form.branches == cf.closed_form_info(robot).branches
    assert cf.analytic_cost(robot) == s.kind.cost_us
    assert (cf.held_joint(robot) is not None) == s.form.param
    assert s.form.swivel == s.kind.swivel and s.form.position_only == s.kind.position_only


def test_a_new_kind_is_one_class_and_one_registry_line(monkeypatch):
    """A kind put first in the table is the one an arm gets, with its own form and cost; the
    solutions stay those of its plan."""

    class Echo(Planar2R):
        name = "echo"
        cost_us = 7.0

        def form(self, plan) -> ClosedForm:
            return ClosedForm("echo", 2, 2, position_only=True, cost_us=self.cost_us)

    monkeypatch.setattr(cf, "KINDS", (Echo(), *KINDS))
    robot = aa.load("planar2r")
    info = cf.closed_form_info(robot)
    assert info.family == "echo" and cf.analytic_cost(robot) == 7.0
    q = np.array([0.3, 0.5])
    res = aa.ik.analytic(robot, robot.fk(q))
    assert np.abs(res.solutions - q).max(1).min() < 1e-9


def test_no_arm_names_in_the_closed_form_modules():
    names = set(aa.models.names()) | {"panda", "ur5", "ur10", "talos_arm", "kinova"}
    for path in CLOSED_FILES:
        text = path.read_text(encoding="utf-8")
        hits = [n for n in names if f'"{n}"' in text or f"'{n}'" in text]
        assert not hits, f"{path.name}: arm names {hits}"


@pytest.mark.parametrize("path", CLOSED_FILES, ids=lambda p: str(p.relative_to(IK_DIR)))
def test_the_closed_form_modules_stay_small(path):
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    assert len(lines) <= 800, f"{path.name}: {len(lines)} lines"
    for node in ast.walk(ast.parse(text)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        start = min([d.lineno for d in node.decorator_list] + [node.lineno])
        n = node.end_lineno - start + 1
        if n > 80:  # allowed with the reason written in a comment right above it
            above = lines[start - 2].strip() if start >= 2 else ""
            assert above.startswith("#"), f"{path.name}:{node.lineno} {node.name}: {n} lines"
        for inner in ast.walk(node):
            if isinstance(inner, (ast.Import, ast.ImportFrom)):
                mod = inner.module if isinstance(inner, ast.ImportFrom) else inner.names[0].name
                assert mod in LOCAL_IMPORTS, f"{path.name}:{inner.lineno} imports {mod}"
