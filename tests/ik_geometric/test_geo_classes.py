"""The registry of IK-Geo classes (:mod:`anthroarm.ik.classes`): each class one module (its
condition, the joints whose axes meet, its branches, its kernels), the order of the classes one
table.  The last test adds a class as a user would — one new file and one line of the table, in
a copy of the package — and the classification, the plan, the branch labels, the dispatch and
``anthroarm check`` all take it up: nothing else names a class."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.ik import classes, classify, geometric, search
from anthroarm.ik.classes.base import CLOSED_FORM, SEARCH_1D, GeoClass, Relations
from anthroarm.jit import Kernel

# IK-Geo Table I (arXiv 2211.05737), 0-based: (spherical triple, parallel pairs, intersecting
# pairs, three-parallel triple) a class asks for
TABLE_I = {
    "spherical_two_parallel": dict(spherical=3, parallel=1),
    "spherical_two_intersecting": dict(spherical=3, intersecting=0),
    "three_parallel_two_intersecting": dict(three_parallel=1, intersecting=4),
    "spherical": dict(spherical=3),
    "three_parallel": dict(three_parallel=1),
    "two_parallel": dict(parallel=1),
    "two_intersecting": dict(intersecting=4),
    "gen_six_dof": {},
}


def _relations(**holds):
    r = {
        k: np.zeros(5 if k in ("parallel", "intersecting") else 4, bool) for k in Relations._fields
    }
    for k, i in holds.items():
        r[k][i] = True
    return Relations(**r)


def test_the_registry_is_ik_geos_table_in_its_order():
    assert classes.ORDER == tuple(TABLE_I) == classify.CLASSES
    assert classes.CLOSED == classify.CLOSED_FORM_CLASSES == tuple(classes.ORDER[:5])
    assert (
        classes.SEARCHED
        == geometric.SEARCHED
        == ("two_parallel", "two_intersecting", "gen_six_dof")
    )
    for name, c in zip(classes.ORDER, classes.REGISTRY):
        assert c.name == name and classes.get(name) is c
        # its own condition holds on the relations of Table I; no class before it holds there
        # unless its condition is contained in this one (the order: simplest solution first)
        assert c.holds(_relations(**TABLE_I[name]))
        assert classes.holding(_relations(**TABLE_I[name]))[0] == name


# IK-Geo's decompositions (arXiv 2211.05737 §IV; the reference implementation's IK_* functions):
# the branching subproblems of each closed class, outermost first, and the joints slid to one
# point (0-based) — the order of the branches is the order of these loops
DECOMPOSITION = {
    "spherical_two_parallel": ((("q1", 2), ("q3", 2), ("q5", 2)), ((3, 4, 5),)),
    "spherical_two_intersecting": ((("q3", 2), ("q1q2", 2), ("q5", 2)), ((0, 1), (3, 4, 5))),
    "three_parallel_two_intersecting": ((("q1", 2), ("q5", 2), ("q3", 2)), ((4, 5),)),
    "spherical": ((("q1q2q3", 4), ("q5", 2)), ((3, 4, 5),)),
    "three_parallel": ((("q1q5", 4), ("q3", 2)), ()),
    "two_parallel": ("q1", ()),
    "two_intersecting": ("q4", ((4, 5),)),
    "gen_six_dof": ("q1q2", ()),
}


def test_each_class_holds_its_decomposition_and_its_kernels():
    for c in classes.REGISTRY:
        branching, meets = DECOMPOSITION[c.name]
        assert c.meets == meets
        if c.closed:
            assert c.labels == branching and isinstance(c.solve, Kernel)
            assert c.inner is None and c.assemble is None
        else:
            assert c.searched == branching and c.solve is None
            one_d = c.solution == SEARCH_1D
            assert isinstance(c.inner, Kernel) == isinstance(c.assemble, Kernel) == one_d
        labels = geometric.branch_labels(c.name)
        assert len(labels) == geometric.n_branches(c.name) == (8 if c.closed else 16)
    assert geometric.branch_labels("spherical_two_intersecting")[:3] == (
        "q3=0,q1q2=0,q5=0",
        "q3=0,q1q2=0,q5=1",
        "q3=0,q1q2=1,q5=0",
    )
    assert geometric.branch_labels("two_intersecting")[15] == "q4root=15"


def test_the_dispatch_follows_the_registry():
    """The compiled dispatch of the closed classes and of the 1-D searches' inner subproblems is
    the registry's kernels in the registry's order (``jit.switch``)."""
    closed = [classes.get(n).solve for n in classes.CLOSED]
    assert list(classes.solve_closed.kernels) == closed
    assert [k for k in classes.search_inner.kernels] == [
        classes.get(n).inner for n in classes.SEARCHED_1D
    ]
    assert search.CLASSES == classes.SEARCHED_1D + classes.SEARCHED_2D


def test_a_malformed_class_is_refused():
    with pytest.raises(ValueError, match="solve kernel iff closed"):
        GeoClass("x", "", lambda r: True, CLOSED_FORM)
    with pytest.raises(KeyError, match="no IK-Geo class 'nope'; the classes are spherical_two"):
        classes.get("nope")


ADD = r"""
import json, sys
import numpy as np
import anthroarm as aa
from anthroarm.ik import classes, classify
r = aa.load("ur5")
Q = r.random_q(6, np.random.default_rng(3))
T = r.fk(Q)
out = {"order": classes.ORDER, "class": classify.classify(r).name, "err": [], "branches": None}
for i in range(len(T)):
    res = aa.ik.analytic(r, T[i])
    out["branches"] = [str(b) for b in res.branches]
    out["err"].append(float(np.abs(r.fk(res.solutions) - T[i]).max()) if len(res.solutions) else 1.0)
    out.setdefault("n", []).append(len(res.solutions))
from anthroarm.ik.geometric import check_rows
rows = check_rows(r, 8, np.random.default_rng(0))
out["check"] = [[row.quantity, row.max_abs_err, row.tol] for row in rows]
print(json.dumps(out))
"""


def test_a_class_is_one_new_file_and_one_registry_line(tmp_path):
    """Copy the package, add ``ur_family`` (the kernel of ``three_parallel_two_intersecting``
    under a new name, its elbow's subproblem labelled ``elbow``) and its line at the head of
    the table: ur5 is now of that class, and solved and labelled by it."""
    src = Path(aa.__file__).resolve().parent
    dst = tmp_path / "src" / "anthroarm"
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("__pycache__"))
    text = (src / "ik" / "classes" / "three_parallel_two_intersecting.py").read_text()
    text = text.replace('"three_parallel_two_intersecting"', '"ur_family"')
    text = text.replace('("q3", 2)),', '("elbow", 2)),')
    assert '"ur_family"' in text and '"elbow"' in text
    (dst / "ik" / "classes" / "ur_family.py").write_text(text)
    reg = dst / "ik" / "classes" / "__init__.py"
    table = reg.read_text()
    new = re.sub(r"ORDER = \(\n", 'ORDER = (\n    "ur_family",\n', table, count=1)
    assert new != table
    reg.write_text(new)
    env = dict(
        os.environ,
        PYTHONPATH=str(tmp_path / "src"),
        ANTHROARM_JIT="reference",
        ANTHROARM_CACHE=str(tmp_path / "cache"),
    )
    p = subprocess.run(
        [sys.executable, "-c", ADD], capture_output=True, text=True, env=env, timeout=600
    )
    assert p.returncode == 0, p.stderr[-3000:]
    out = json.loads(p.stdout)
    assert out["order"][0] == "ur_family" and out["class"] == "ur_family"
    assert max(out["err"]) < 1e-9 and min(out["n"]) >= 1
    assert all(re.fullmatch(r"q1=\d,q5=\d,elbow=\d", b) for b in out["branches"])
    # anthroarm check: the FK check of every branch; IK-Geo (the peer) has no such class, so
    # its row is left out rather than failing
    assert [c for c, _, _ in out["check"]] == [
        "closed form by geometry: FK(IK(T)) = T, all branches"
    ]
    assert all(v <= tol for _, v, tol in out["check"])
    # the unchanged package still says three_parallel_two_intersecting
    assert classify.classify(aa.load("ur5")).name == "three_parallel_two_intersecting"
