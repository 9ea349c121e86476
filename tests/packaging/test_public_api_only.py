"""Only public APIs of dependencies: no private name of a third-party or standard-library module
is imported, read, set, overridden or passed as a keyword by ``src/anthroarm`` (issue 28).

A private name is one with a single leading underscore.  What the scan sees (``ast`` over every
source file, then the imported classes):
- ``from numpy._core.umath import clip``, ``import x._y``, ``from x import _y``;
- ``obj._name`` where no code of ours defines ``_name`` (a def, a class, a ``self.``/``cls.``
  attribute, a module or class variable, a parameter, a slot);
- ``obj._name = ...`` on anything but ``self``/``cls``, unless a class of that file declares it;
- a keyword argument ``_name=`` that none of our functions takes;
- a method of one of our classes that overrides a private method of a third-party base class.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "anthroarm"

#: The debt still open, by (file, what): none.  (The Numba cache overrides, ``_nrt`` and the
#: intrinsics' private struct methods of ``anthroarm.jit`` are gone: issue 28 item 3.)  Nothing
#: may be added here; an entry that no longer matches fails the test.
KNOWN: set[tuple[str, str]] = set()


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _trees():
    return {p: ast.parse(p.read_text(), filename=str(p)) for p in sorted(SRC.rglob("*.py"))}


def _own_names(trees) -> set[str]:
    own: set[str] = set()
    for t in trees.values():
        for n in ast.walk(t):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                own.add(n.name)
                for a in n.args.args + n.args.kwonlyargs if not isinstance(n, ast.ClassDef) else []:
                    own.add(a.arg)
            elif isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
                own.add(n.id)
            elif (
                isinstance(n, ast.Attribute)
                and isinstance(n.ctx, ast.Store)
                and isinstance(n.value, ast.Name)
                and n.value.id in ("self", "cls")
            ):
                own.add(n.attr)
            elif isinstance(n, ast.alias):
                own.add(n.asname or n.name.split(".")[0])
            elif (
                isinstance(n, ast.Constant) and isinstance(n.value, str) and n.value.isidentifier()
            ):
                own.add(n.value)  # __slots__ entries, getattr names
    return own


def _declared(tree) -> set[str]:
    """The attributes a file's own classes declare: class-body names and ``self.`` stores."""
    names = set()
    for c in ast.walk(tree):
        if isinstance(c, ast.ClassDef):
            for n in ast.walk(c):
                if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
                    names.add(n.id)
                elif isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store):
                    if isinstance(n.value, ast.Name) and n.value.id in ("self", "cls"):
                        names.add(n.attr)
    return names


def scan(trees) -> set[tuple[str, str]]:
    own = _own_names(trees)
    ours = {"anthroarm"} | {p.stem for p in trees}  # the viewer's server imports _store by path
    found = set()
    for p, t in trees.items():
        rel = str(p.relative_to(SRC))
        for n in ast.walk(t):
            if isinstance(n, ast.ImportFrom) and n.level == 0 and n.module:
                if n.module.split(".")[0] in ours:
                    continue
                if any(_private(x) for x in n.module.split(".")):
                    found.add((rel, f"from {n.module}"))
                found.update(
                    (rel, f"from {n.module} import {a.name}") for a in n.names if _private(a.name)
                )
            elif isinstance(n, ast.Import):
                found.update(
                    (rel, f"import {a.name}")
                    for a in n.names
                    if a.name.split(".")[0] != "anthroarm"
                    and any(_private(x) for x in a.name.split("."))
                )
            elif isinstance(n, ast.Attribute) and _private(n.attr):
                if isinstance(n.ctx, ast.Store):
                    base = n.value.id if isinstance(n.value, ast.Name) else None
                    if base not in ("self", "cls") and n.attr not in _declared(t):
                        found.add((rel, f"{ast.unparse(n)} ="))
                elif n.attr not in own:
                    found.add((rel, ast.unparse(n)))
            elif isinstance(n, ast.keyword) and n.arg and _private(n.arg) and n.arg not in own:
                found.add((rel, f"keyword {n.arg}"))
    return found


def overrides() -> set[tuple[str, str]]:
    """Private methods of third-party base classes that our classes override."""
    found = set()
    for p in sorted(SRC.rglob("*.py")):
        parts = p.relative_to(SRC.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if "_server" in name:  # the viewer's server script runs as a program of its own
            continue
        mod = importlib.import_module(name)
        for cls in vars(mod).values():
            if not inspect.isclass(cls) or cls.__module__ != name:
                continue
            foreign = [b for b in cls.__mro__[1:] if not b.__module__.startswith("anthroarm")]
            for attr in vars(cls):
                inherited = any(attr in vars(b) for b in foreign)
                if _private(attr) and attr != "_abc_impl" and inherited:  # ABCMeta sets _abc_impl
                    found.add((str(p.relative_to(SRC)), f"{cls.__name__}.{attr}"))
    return found


def test_no_private_api_of_any_dependency():
    found = scan(_trees()) | overrides()
    new = sorted(found - KNOWN)
    assert not new, "private names of dependencies used:\n" + "\n".join(f"{f}: {w}" for f, w in new)
    gone = sorted(KNOWN - found)
    assert not gone, "no longer used, delete from KNOWN: " + ", ".join(f"{f}: {w}" for f, w in gone)


@pytest.mark.parametrize(
    "source, what",
    [
        ("from numpy._core.umath import clip\n", "from numpy._core.umath"),
        ("import argparse\np = argparse.ArgumentParser()\nx = p._actions\n", "p._actions"),
        ("import numba\nd = numba.njit(f)\nd._cache = 1\n", "d._cache ="),
        ("import numba\nd = numba.njit(_nrt=False)\n", "keyword _nrt"),
        ("from concurrent.futures import _base\n", "from concurrent.futures import _base"),
    ],
)
def test_the_scan_sees_each_kind(source, what):
    """The scan is not blind: each kind of private use in a snippet is reported."""
    found = {w for _, w in scan({SRC / "snippet.py": ast.parse(source)})}
    assert what in found
