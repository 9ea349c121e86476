"""Imports inside functions, and private names across packages (DESIGN.md, issue 29 item 1).

1. An import inside a function (at any depth: a method, a nested function) is for an optional
   or heavy dependency only, each listed in one place: :data:`anthroarm.optional.ALLOWED`.  Every
   other import sits at the top of its module; a circle is broken by moving the shared code down
   a layer, not by hiding the import in a function.  ``importlib.import_module("...")`` /
   ``__import__("...")`` with a literal name count as imports too, except in a module-level
   ``__getattr__`` (PEP 562: the lazy subpackages of ``anthroarm``, ``anthroarm.dynamics`` ...).
2. No private name (one leading underscore: ``_x``, a module ``_util``) is imported from
   another top-level package of anthroarm (``from ..ik.geometric import _x`` in ``dynamics/``);
   inside one package it is fine.  Top-level modules (``robot.py``, ``chain.py``) are packages of
   their own here; ``anthroarm._io`` is a public foundation module despite its name.

The files that still break a rule are listed below with their exact count: a count must not
grow, and one that shrinks must be lowered here (the test fails on a stale entry), so the lists
only shrink.  Each entry says why it is there.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from anthroarm.optional import allowed

SRC = Path(__file__).resolve().parents[2] / "src"
PACKAGE = "anthroarm"

#: file (relative to src/anthroarm) -> function-local imports of modules not in optional.ALLOWED
LOCAL_IMPORTS = {
    # upward imports (test_layers.KNOWN) of the faces: at the top they would load the viewer
    # (meshcat, tornado) with the algorithm; gone when the viewer demo moves into viewer/
}

#: file -> private names (or names from private modules) imported from another package
PRIVATE_IMPORTS: dict[str, int] = {}


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _module_name(rel: Path) -> list[str]:
    parts = [PACKAGE, *rel.with_suffix("").parts]
    return parts[:-1] if parts[-1] == "__init__" else parts


def _package_of(rel: Path) -> list[str]:
    """The package a relative import in ``rel`` starts from."""
    parts = [PACKAGE, *rel.with_suffix("").parts]
    return parts[:-1]


def _resolve(rel: Path, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = _package_of(rel)
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _targets(rel: Path, node) -> list[str]:
    """The modules an import statement may load: ``import a.b`` -> a.b; ``from m import x`` ->
    m.x (x may be a submodule) and m."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    mod = _resolve(rel, node)
    return [f"{mod}.{a.name}" for a in node.names]


def _dynamic_import(rel: Path, node: ast.Call) -> str | None:
    """The literal module name of ``importlib.import_module("...")`` / ``__import__("...")``."""
    f = node.func
    name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
    if name not in ("import_module", "__import__") or not node.args:
        return None
    arg = node.args[0]
    if isinstance(arg, ast.JoinedStr) and all(isinstance(v, ast.Constant) for v in arg.values):
        arg = ast.Constant("".join(v.value for v in arg.values))
    if not (isinstance(arg, ast.Constant) and isinstance(arg.value, str)):
        return None  # a name from a table (crosscheck's providers): not a hidden import
    text = arg.value
    if text.startswith("."):
        level = len(text) - len(text.lstrip("."))
        base = _package_of(rel)
        base = base[: len(base) - (level - 1)]
        text = ".".join(base + ([text.lstrip(".")] if text.lstrip(".") else []))
    return text


def function_imports(rel: Path, source: str) -> list[tuple[int, str]]:
    """(line, module) of every import inside a function of ``source`` (the file ``rel`` under
    src/anthroarm) of a module not in :data:`anthroarm.optional.ALLOWED`."""
    tree = ast.parse(source, str(rel))
    lazy = {
        id(n)
        for n in tree.body
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.name == "__getattr__"
    }
    out: list[tuple[int, str]] = []

    def visit(node, in_function: bool, in_lazy: bool = False) -> None:
        for child in ast.iter_child_nodes(node):
            inside = in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            if inside and isinstance(child, (ast.Import, ast.ImportFrom)):
                if isinstance(child, ast.ImportFrom):
                    mod = _resolve(rel, child)
                    bad = [t for t in _targets(rel, child) if not (allowed(t) or allowed(mod))]
                else:
                    bad = [t for t in _targets(rel, child) if not allowed(t)]
                if bad:
                    out.append((child.lineno, bad[0]))
            elif inside and not in_lazy and isinstance(child, ast.Call):
                mod = _dynamic_import(rel, child)
                if mod is not None and not allowed(mod):
                    out.append((child.lineno, mod))
            visit(child, inside, in_lazy or id(child) in lazy)

    visit(tree, False)
    return out


def private_imports(rel: Path, source: str) -> list[tuple[int, str]]:
    """(line, dotted name) of every private name, or name from a private module, that ``source``
    imports from another top-level package of anthroarm."""
    tree = ast.parse(source, str(rel))
    own = _module_name(rel)[1:2] or ["__init__"]
    out: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            names = [_resolve(rel, node).split(".") + [a.name] for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name.split(".") for a in node.names]
        else:
            continue
        for parts in names:
            if parts[0] != PACKAGE or len(parts) < 3 or parts[1] == own[0]:
                continue
            if any(_private(p) for p in parts[2:]):
                out.append((node.lineno, ".".join(parts)))
    return out


def _files() -> dict[str, str]:
    root = SRC / PACKAGE
    return {
        p.relative_to(root).as_posix(): p.read_text(encoding="utf-8")
        for p in sorted(root.rglob("*.py"))
    }


def _check(found: dict[str, list], known: dict[str, int], what: str) -> None:
    problems = []
    for rel, hits in sorted(found.items()):
        n, allowed_n = len(hits), known.get(rel, 0)
        where = ", ".join(f"{rel}:{line} {mod}" for line, mod in hits)
        if n > allowed_n:
            problems.append(f"{rel}: {n} {what} (allowed {allowed_n}): {where}")
        elif n < allowed_n:
            problems.append(f"{rel}: {n} {what} now, lower its entry from {allowed_n} to {n}")
    for rel in sorted(set(known) - set(found)):
        problems.append(f"{rel}: no {what} left, delete its entry ({known[rel]})")
    assert not problems, "\n".join(problems)


def test_imports_inside_functions_are_optional_or_heavy_only():
    found = {}
    for rel, source in _files().items():
        hits = function_imports(Path(rel), source)
        if hits:
            found[rel] = hits
    _check(found, LOCAL_IMPORTS, "imports inside functions of modules not in anthroarm.optional")


def test_no_private_name_imported_across_packages():
    found = {}
    for rel, source in _files().items():
        hits = private_imports(Path(rel), source)
        if hits:
            found[rel] = hits
    _check(found, PRIVATE_IMPORTS, "private names imported from another package")


def test_the_lists_name_existing_files():
    files = _files()
    stale = sorted((set(LOCAL_IMPORTS) | set(PRIVATE_IMPORTS)) - set(files))
    assert not stale, f"entries for files that do not exist: {stale}"


SNIPPET = """
import sympy
from . import lagrange


def f():
    import sympy as sp
    import matplotlib.pyplot as plt
    from scipy.optimize import minimize
    from .. import chain_kernels
    return sp, plt, minimize, chain_kernels


def g():
    from .x import y
    import numpy
    import importlib
    importlib.import_module(".simulate", __name__)
    return y, numpy


class C:
    def m(self):
        from ..ik.geometric import helper
        return helper


def __getattr__(name):
    return importlib.import_module(f".{name}", __name__)
"""


@pytest.mark.parametrize("rel", ["dynamics/fake.py"])
def test_the_check_sees_a_function_local_import(rel):
    """Not blind: a function-local ``from .x import y``, a plain ``import numpy``, a literal
    ``importlib.import_module`` and one in a method are reported; optional and heavy modules
    (sympy, matplotlib, scipy.optimize, the kernel module), imports at the top and the lazy
    module ``__getattr__`` are not."""
    hits = function_imports(Path(rel), SNIPPET)
    assert [m for _, m in hits] == [
        "anthroarm.dynamics.x.y",
        "numpy",
        "importlib",
        "anthroarm.dynamics.simulate",
        "anthroarm.ik.geometric.helper",
    ]


def test_the_check_sees_a_private_name_across_packages():
    source = (
        "from ..ik.geometric import _solve, public\n"
        "from . import _util\n"
        "from ..control import _check\n"
        "from .._io import atomic_write_text\n"
        "def f():\n"
        "    from anthroarm.robot import _make\n"
    )
    hits = private_imports(Path("dynamics/fake.py"), source)
    assert [m for _, m in hits] == [
        "anthroarm.ik.geometric._solve",
        "anthroarm.control._check",
        "anthroarm.robot._make",
    ]


def test_the_list_is_what_it_says():
    assert allowed("sympy") and allowed("matplotlib.pyplot") and allowed("scipy.optimize._min")
    assert allowed("anthroarm.chain_kernels")
    for core in ("numpy", "scipy", "scipy.linalg", "pinocchio", "os", "anthroarm.robot"):
        assert not allowed(core), core
