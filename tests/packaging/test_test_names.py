"""Test files are found by name (issue 29 item 7): a module's tests are in
``tests/<area>/test_<module>.py``, and no two test files share a file name.

pytest imports test files by their base name (no ``__init__.py`` in the test folders, the default
``prepend`` import mode): two files ``test_x.py`` in different folders stop the collection of
the whole suite with "import file mismatch".  Where two areas test modules of the same name, the
file carries its area (``test_spatial_checks.py``, ``test_mech_checks.py``,
``test_emg_envelope.py``)."""

from collections import defaultdict
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def shared_names(tests: Path = TESTS) -> dict[str, list[str]]:
    """Base name -> the test files that have it, for the names used more than once."""
    seen = defaultdict(list)
    for p in sorted(tests.rglob("test_*.py")):
        seen[p.name].append(p.relative_to(tests).as_posix())
    return {name: paths for name, paths in seen.items() if len(paths) > 1}


def test_no_two_test_files_share_a_name():
    twice = shared_names()
    assert not twice, (
        "test files with the same name (rename one, e.g. with its area): "
        + "; ".join(f"{name}: {', '.join(paths)}" for name, paths in sorted(twice.items()))
    )


def test_the_check_sees_a_shared_name(tmp_path):
    for area in ("emg", "prosthesis"):
        (tmp_path / area).mkdir()
        (tmp_path / area / "test_envelope.py").write_text("")
    (tmp_path / "emg" / "test_synth.py").write_text("")
    assert shared_names(tmp_path) == {
        "test_envelope.py": ["emg/test_envelope.py", "prosthesis/test_envelope.py"]
    }
