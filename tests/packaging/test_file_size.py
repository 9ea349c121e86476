"""DESIGN.md's house rule for the whole package: no source file over 800 lines (the IK wing's
stricter rules, functions included, are ``tests/ik_book/test_closed_form_kinds.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "anthroarm"
FILES = sorted(SRC.rglob("*.py"))


def test_the_package_has_sources():
    assert len(FILES) > 100


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(SRC)))
def test_no_file_over_800_lines(path):
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= 800, f"{path.relative_to(SRC)}: {n} lines"
