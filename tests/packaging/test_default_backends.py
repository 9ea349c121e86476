"""Every default works with the core install (issue 31): the QP backend a public function uses
by default is a core dependency in pyproject.toml, and a missing backend's message names both
remedies (install it, or pick an installed one)."""

import inspect
import re
from pathlib import Path

import pytest
import tomllib

import anthroarm.ik.qp as qp
from anthroarm import hand
from anthroarm.errors import SolverNotAvailableError
from anthroarm.hand.problems import reachable_grasps
from anthroarm.ik.qp.backends import PIP_NAMES, make_backend
from anthroarm.motion.marker_ik import MarkerIK

ROOT = Path(__file__).resolve().parents[2]


def _core_requirements() -> set[str]:
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    names = set()
    for d in deps:
        m = re.match(r"([A-Za-z0-9_.-]+)(\[([^\]]*)\])?", d)
        names.add(m.group(1).lower())
        if m.group(3):  # qpsolvers[osqp] installs osqp
            names.update(x.strip().lower() for x in m.group(3).split(","))
    return names


@pytest.mark.parametrize(
    "fn",
    [qp.step, hand.solve_grasp, reachable_grasps, MarkerIK],
    ids=lambda f: f.__qualname__,
)
def test_the_default_backend_is_a_core_dependency(fn):
    default = inspect.signature(fn).parameters["solver"].default
    assert PIP_NAMES[default] in _core_requirements(), (fn.__qualname__, default)


def test_a_missing_backend_names_both_remedies():
    with pytest.raises(SolverNotAvailableError) as e:
        make_backend("no_such_solver_xyz", 3)
    assert "installed solvers" in str(e.value) and "install it" in str(e.value).lower()
    with pytest.raises(SolverNotAvailableError) as e:
        make_backend("clarabel" if "clarabel" not in qp.available_solvers() else "ecos", 3)
    assert "pip install" in str(e.value)
