"""Arm-specific knowledge lives in ``models/`` and nowhere else (DESIGN.md; issue 29 item 2).

Counts, with :mod:`ast` and :mod:`tokenize`, the lines of code outside ``src/anthroarm/models``
that name a catalog arm (:func:`anthroarm.models.names`): an identifier that contains a name
(``human_arm7_points``) or a string constant that is not documentation (``load("planar2r")``,
a help text, an f-string part).  Documentation may cite the catalog: docstrings, other bare
string statements and comments do not count.

The files other engineers still own carry the lines listed in :data:`ALLOWED`, each an exact
count: a file that names more fails, and one that names fewer fails too until its entry is
lowered (or deleted at 0), so the list only shrinks.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

import anthroarm as aa

SRC = Path(__file__).resolve().parents[2] / "src" / "anthroarm"

#: file (relative to src/anthroarm) -> lines of code naming a catalog arm, still to go
ALLOWED = {
    # examples in help texts (epilog) of the commands
    "cli/batch.py": 1,
    "cli/check.py": 1,
    "cli/ik.py": 1,
    "cli/urdf.py": 2,
    "cli/view.py": 3,
    "viewer/demo.py": 1,
}


def name_pattern(names) -> re.Pattern:
    """A catalog name inside an identifier or text, not inside a longer word: ``human_arm7``
    in ``human_arm7_points``, but not ``panda`` in ``pandas``."""
    alts = "|".join(map(re.escape, sorted(names, key=len, reverse=True)))
    return re.compile(rf"(?<![A-Za-z0-9])({alts})(?![A-Za-z0-9])")


def _documentation(tree: ast.AST) -> set[int]:
    """ids of the string constants that are documentation: every string statement (module,
    class and function docstrings, attribute docstrings)."""
    return {
        id(node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Expr)
        and isinstance(node.value, ast.Constant)
        and isinstance(node.value.value, str)
    }


def code_lines(source: str, pattern: re.Pattern) -> dict[int, str]:
    """line number -> line, for the lines of ``source`` whose code names a catalog arm."""
    lines = source.splitlines()
    tree = ast.parse(source)
    docs = _documentation(tree)
    hits: set[int] = set()
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and id(node) not in docs
            and pattern.search(node.value)
        ):
            span = range(node.lineno, (node.end_lineno or node.lineno) + 1)
            hits.update(n for n in span if pattern.search(lines[n - 1]))
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.NAME and pattern.search(tok.string):
            hits.add(tok.start[0])
    return {n: lines[n - 1].strip() for n in sorted(hits)}


def count_outside_models(src: Path = SRC) -> dict[str, dict[int, str]]:
    """file (relative to ``src``) -> its lines of code naming a catalog arm, for every file
    outside ``models/`` that has any."""
    pattern = name_pattern(aa.models.names())
    out = {}
    for path in sorted(src.rglob("*.py")):
        rel = path.relative_to(src).as_posix()
        if rel.startswith("models/"):
            continue
        found = code_lines(path.read_text(encoding="utf-8"), pattern)
        if found:
            out[rel] = found
    return out


@pytest.fixture(scope="module")
def found():
    return count_outside_models()


def test_no_arm_named_in_code_outside_models(found):
    extra = {f: lines for f, lines in found.items() if f not in ALLOWED}
    assert not extra, (
        "code naming a catalog arm outside models/ (put it in models/):\n"
        + "\n".join(f"  {f}:{n}: {text}" for f, lines in extra.items() for n, text in lines.items())
    )


@pytest.mark.parametrize("rel", sorted(ALLOWED))
def test_allowed_counts_only_shrink(found, rel):
    lines = found.get(rel, {})
    listing = "\n".join(f"  {rel}:{n}: {text}" for n, text in lines.items())
    assert len(lines) <= ALLOWED[rel], f"{rel} names catalog arms in more code lines:\n{listing}"
    assert len(lines) == ALLOWED[rel], (
        f"{rel} names catalog arms in {len(lines)} code lines now: lower ALLOWED[{rel!r}] to "
        f"{len(lines)} (delete it at 0)"
    )


def test_the_count_sees_code_and_skips_documentation():
    """Not blind, not noisy: identifiers, calls, f-string parts and keyword defaults count;
    docstrings, attribute docstrings, comments and longer words do not."""
    pattern = name_pattern(["human_arm7", "panda"])
    source = '''"""Module docstring citing human_arm7."""
import pandas

X = 1
"""An attribute docstring: human_arm7."""


def human_arm7_points(q):  # a comment: human_arm7
    """Docstring: load("human_arm7")."""
    return load("human_arm7", model=f"{q}panda")


def f(model="panda"):
    return pandas
'''
    assert list(code_lines(source, pattern)) == [8, 10, 13]
