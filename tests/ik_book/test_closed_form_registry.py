"""Which arms have a closed form (read from the chain, never from a name), the public predicate
and cost hint, the typed error for robots without a closed form, and the straight-line emitter
of the one expression graph (codegen/graph.py).

Oracles: Pinocchio's FK for the solutions; plain float arithmetic node by node for the emitter."""

from __future__ import annotations

import gc
import math
import re
import weakref
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.codegen.graph import Graph, straight_line
from anthroarm.errors import UnknownFrameError, UnsupportedModelError
from anthroarm.ik import closed_form as cf

IK_DIR = Path(cf.__file__).parent
#: the catalog arms with a closed form, and which family
CLOSED = {
    n: f.family for n in aa.models.names() if (f := cf.closed_form_info(aa.load(n))) is not None
}


def test_no_arm_names_in_ik():
    """Arm knowledge lives in models/: no catalog or example-robot-data arm name is a string
    literal in the closed-form modules."""
    names = set(aa.models.names()) | {
        "panda",
        "ur5",
        "ur10",
        "talos_arm",
        "human_right_arm",
        "kinova",
    }
    pat = re.compile(r"""["'](%s)["']""" % "|".join(map(re.escape, sorted(names))))
    for f in (
        "closed_form.py",
        "geometric",
        "families",
        "search",
        "subproblems",
        "classify.py",
        "vec3.py",
        "checks.py",
        "cells.py",
    ):
        for p in [IK_DIR / f] if f.endswith(".py") else sorted((IK_DIR / f).glob("*.py")):
            hits = pat.findall(p.read_text(encoding="utf-8"))
            assert not hits, f"{p.relative_to(IK_DIR)}: arm names {hits}"


def test_the_book_arms_have_their_closed_forms():
    assert CLOSED["sixr_arm"] == CLOSED["care_robot"] == "spherical_two_parallel"
    assert CLOSED["prosthetic_arm"] == "spherical_two_intersecting"  # a spherical shoulder
    assert CLOSED["human_arm7"] == cf.SRS and CLOSED["planar2r"] == cf.PLANAR


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_closed_forms_solve_their_arm(name):
    robot = aa.load(name)
    form = cf.closed_form_info(robot)
    assert (
        aa.ik.has_analytic(robot)
        and aa.ik.has_analytic(robot, robot.tool)
        and aa.ik.has_analytic(robot, robot.tool_id)
    )
    assert cf.analytic_cost(robot) == form.cost_us > 0
    assert form.nq == len(robot.chain.path(robot.tool))  # the joints on the path (a tree: its arm)
    q = robot.random_q(None, np.random.default_rng(3), margin=0.05)
    T = robot.fk(q)
    kw = {"swivel": aa.ik.swivel_angle(robot, q)} if form.swivel else {}
    if form.param:  # the last joint on the path held at its sampled value
        kw = {"param": q[robot.chain.independent.index(robot.chain.path(robot.tool)[-1])]}
    res = aa.ik.analytic(robot, T, q_rest=q, **kw)  # a tree's other joints as sampled
    assert res.model == robot.name
    batch = aa.ik.analytic_batch(robot, T[None], **kw)
    assert len(batch.branches) == form.branches
    # the sampled q is among them (one representative per branch: modulo 2π where a joint's
    # range is wider than a turn)
    d = np.angle(np.exp(1j * (res.solutions - q)))
    assert np.abs(d).max(1).min() < 1e-8
    other = next(f.name for f in robot.chain.frames if f.is_body and f.name != robot.tool)
    assert not aa.ik.has_analytic(robot, other)
    with pytest.raises(UnknownFrameError):
        aa.ik.has_analytic(robot, "no_such_frame")


def test_a_closed_form_is_a_property_of_the_model_not_of_its_label():
    assert aa.ik.has_analytic(aa.load("sixr_arm", name="my_arm"))
    robot = aa.load("prosthetic_arm", L2=0.24)  # other lengths: the same family
    q = np.array([-1.0, 1.2, 0.3, 1.0, 0.2, -0.4])
    res = aa.ik.analytic(robot, robot.fk(q))
    assert np.abs(res.solutions - q).max(1).min() < 1e-9


@pytest.mark.parametrize(
    "name", ["unimate5", "rrprr5"]
)  # ur10, kinova, panda: closed form by geometry
def test_no_closed_form_is_a_typed_error(name):
    robot = aa.load(name)
    assert not aa.ik.has_analytic(robot)
    assert cf.closed_form_info(robot) is None
    assert math.isinf(cf.analytic_cost(robot))
    with pytest.raises(
        UnsupportedModelError, match=r"no closed form for this geometry.*aa\.ik\.solve"
    ):
        aa.ik.analytic(robot, robot.fk(robot.neutral()))
    with pytest.raises(UnsupportedModelError, match="aa.ik.solve"):
        aa.ik.analytic_batch(robot, robot.fk(robot.neutral())[None])


def test_locked_joints_or_another_tool_have_no_closed_form():
    robot = aa.load(
        "sixr_arm",
        locked={robot_joint: 0.0 for robot_joint in [aa.load("sixr_arm").joint_names[5]]},
    )
    assert not aa.ik.has_analytic(robot)
    with pytest.raises(UnsupportedModelError, match="5 joints from the base to the frame, not 6"):
        aa.ik.analytic(robot, np.eye(4))
    frame = aa.load("sixr_arm").chain.joints[4].name
    robot = aa.load("sixr_arm", tool=frame)
    assert not aa.ik.has_analytic(robot)
    with pytest.raises(UnsupportedModelError, match="joints from the base to the frame, not 6"):
        aa.ik.analytic(robot, np.eye(4))


def test_plan_cache_does_not_keep_robots_alive():
    robot = aa.load("planar2r")
    aa.ik.analytic(robot, robot.fk(np.array([0.3, 0.5])))
    aa.ik.analytic_batch(robot, robot.fk(np.array([[0.3, 0.5]] * 3)))
    ref = weakref.ref(robot)
    del robot
    gc.collect()
    assert ref() is None
    # a tree: its cached arm (a robot of its own) goes with it
    limb = aa.load("human_upper_limb")
    q = limb.random_q(rng=2)
    assert len(aa.ik.analytic(limb, limb.fk(q), swivel=aa.ik.swivel_angle(limb, q)))
    refs = [weakref.ref(limb), weakref.ref(cf._solver(limb).arm.robot)]
    del limb
    gc.collect()
    assert all(r() is None for r in refs)


def _evaluate(g, outputs, env):
    """Node-by-node float evaluation of the graph (the mathematics the emitter must print)."""
    val = {}
    for i in g.cone(outputs):
        op = g.ops[i]
        if op[0] == "in":
            val[i] = env[op[1].name]
            continue
        a = op[1] if isinstance(op[1], float) else val[op[1]]
        val[i] = a + val[op[2]] if op[0] == "add" else a * val[op[2]]
    return [val[o.i] if not isinstance(o, float) else o for o in outputs]


def test_straight_line_inlining_keeps_the_graph_evaluation_order():
    """Random sums, products and negations: the emitted Python (shared nodes named, the rest
    inlined) gives bit-for-bit the node-by-node result."""
    rng = np.random.default_rng(11)
    for trial in range(20):
        g = Graph()
        pool = [g.input("x", k) for k in range(4)]
        for _ in range(40):
            a, b = (pool[int(rng.integers(len(pool)))] for _ in range(2))
            r = rng.random()
            v = (
                g.add(a, b)
                if r < 0.3
                else g.mul(a, b)
                if r < 0.55
                else g.add(a, g.mul(-1.0, b))
                if r < 0.8
                else g.mul(float(rng.choice([-1.0, -2.5, 3.0])), a)
            )
            if not isinstance(v, float):
                pool.append(v)
        outs = pool[-3:]
        stmts, ref = straight_line(g, outs, lambda inp: inp.name, name_outputs=bool(trial % 2))
        src = (
            "def f(x0, x1, x2, x3):\n"
            + "".join(f"    {n} = {e}\n" for n, e in stmts)
            + f"    return ({', '.join(ref(o) for o in outs)},)\n"
        )
        ns = {}
        exec(src, ns)
        for _ in range(5):
            x = rng.normal(size=4) * 3
            got = ns["f"](*x)
            want = _evaluate(g, outs, {f"x{k}": x[k] for k in range(4)})
            assert list(got) == want, src
