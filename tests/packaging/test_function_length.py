"""A wing one can read (issue 28 item 6): no function in ``ik/`` over 80 lines without its
reason written above it: a comment ``# long: …`` in the comment lines right before the
function (or its first decorator)."""

from __future__ import annotations

import ast
from pathlib import Path

import anthroarm

IK = Path(anthroarm.__file__).resolve().parent / "ik"
LIMIT = 80


def long_without_reason(folder: Path) -> list[str]:
    """``path:line name (n lines)`` of every function of the modules below ``folder`` over
    :data:`LIMIT` lines (decorators and docstring included) with no ``# long:`` comment in the
    comment lines directly above it."""
    out = []
    for p in sorted(folder.rglob("*.py")):
        lines = p.read_text(encoding="utf-8").splitlines()
        for node in ast.walk(ast.parse("\n".join(lines))):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            first = min([d.lineno for d in node.decorator_list] + [node.lineno])
            n = node.end_lineno - first + 1
            k, block = first - 2, []  # the comment lines right above, nearest first
            while k >= 0 and lines[k].strip().startswith("#"):
                block.append(lines[k].strip())
                k -= 1
            if n > LIMIT and not any(c.startswith("# long:") for c in block):
                out.append(f"{p.relative_to(folder.parent)}:{node.lineno} {node.name} ({n} lines)")
    return out


def test_every_long_function_in_ik_says_why():
    bad = long_without_reason(IK)
    assert not bad, "functions over 80 lines with no '# long:' reason above: " + "; ".join(bad)


def test_the_check_sees_a_long_function(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(LIMIT))
    (tmp_path / "m.py").write_text(f"def f():\n{body}\n\n\n# long: a table\ndef g():\n{body}\n")
    assert long_without_reason(tmp_path) == [f"{tmp_path.name}/m.py:1 f ({LIMIT + 1} lines)"]
