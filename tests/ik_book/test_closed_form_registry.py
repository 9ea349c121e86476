"""The closed-form registry (models/closed_forms.py), the public predicate and cost hint, the
typed error for robots without a closed form, and the generated FK check built from
``robot.chain`` in the one expression graph (codegen/graph.py).

Oracles: Pinocchio's FK for the generated code; plain float arithmetic node by node for the
emitter; the catalog for which arms have a closed form."""

from __future__ import annotations

import gc
import math
import re
import weakref
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.codegen.graph import Graph, straight_line
from anthroarm.errors import UnknownFrameError, UnsupportedModelError
from anthroarm.ik import closed_form as cf
from anthroarm.ik.fk_codegen import FKStages
from anthroarm.models import closed_forms

IK_DIR = Path(cf.__file__).parent


def test_no_arm_names_in_ik():
    """Arm knowledge lives in models/: no catalog or example-robot-data arm name is a string
    literal in the closed-form modules."""
    names = set(aa.models.names()) | {"panda", "ur5", "ur10", "talos_arm", "human_right_arm", "kinova"}
    pat = re.compile(r"""["'](%s)["']""" % "|".join(map(re.escape, sorted(names))))
    for f in ("closed_form.py", "analytic_plan.py", "analytic_scalar.py", "analytic_soa.py", "analytic_c.py",
              "fk_codegen.py", "checks.py", "cells.py"):
        hits = pat.findall((IK_DIR / f).read_text(encoding="utf-8"))
        assert not hits, f"{f}: arm names {hits}"


@pytest.mark.parametrize("name", closed_forms.names())
def test_registry_entries_solve_their_arm(name):
    robot = aa.load(name)
    form = cf.closed_form_info(robot)
    assert form is closed_forms.REGISTRY[name]
    assert aa.ik.has_analytic(robot) and aa.ik.has_analytic(robot, robot.tool) and aa.ik.has_analytic(robot, robot.tool_id)
    assert cf.analytic_cost(robot) == form.cost_us > 0
    assert form.nq == robot.nq
    q = robot.random_q(None, np.random.default_rng(3), margin=0.05)
    T = robot.fk(q)
    kw = {"swivel": aa.ik.swivel_angle(robot, q)} if form.swivel else {}
    res = aa.ik.analytic(robot, T, **kw)
    assert res.model == robot.name
    batch = aa.ik.analytic_batch(robot, T[None], **kw)
    assert len(batch.branches) == form.branches
    assert np.abs(res.solutions - q).max(1).min() < 1e-8          # the sampled q is among them
    other = next(f.name for f in robot.chain.frames if f.is_body and f.name != robot.tool)
    assert not aa.ik.has_analytic(robot, other)
    with pytest.raises(UnknownFrameError):
        aa.ik.has_analytic(robot, "no_such_frame")


def test_a_closed_form_is_a_property_of_the_model_not_of_its_label():
    assert aa.ik.has_analytic(aa.load("sixr_arm", name="my_arm"))
    robot = aa.load("prosthetic_arm", L2=0.24)                    # other lengths: the same family
    q = np.array([-1.0, 1.2, 0.3, 1.0, 0.2, -0.4])
    res = aa.ik.analytic(robot, robot.fk(q))
    assert np.abs(res.solutions - q).max(1).min() < 1e-9


@pytest.mark.parametrize("name", ["unimate5", "rrprr5"])   # ur10, kinova, panda: closed form by geometry
def test_no_closed_form_is_a_typed_error(name):
    robot = aa.load(name)
    assert not aa.ik.has_analytic(robot)
    assert cf.closed_form_info(robot) is None
    assert math.isinf(cf.analytic_cost(robot))
    with pytest.raises(UnsupportedModelError,
                       match=r"no closed-form IK is registered.*no closed form for this geometry.*aa\.ik\.solve"):
        aa.ik.analytic(robot, robot.fk(robot.neutral()))
    with pytest.raises(UnsupportedModelError, match="aa.ik.solve"):
        aa.ik.analytic_batch(robot, robot.fk(robot.neutral())[None])


def test_locked_joints_or_another_tool_have_no_closed_form():
    robot = aa.load("sixr_arm", locked={robot_joint: 0.0 for robot_joint in [aa.load("sixr_arm").joint_names[5]]})
    assert not aa.ik.has_analytic(robot)
    with pytest.raises(UnsupportedModelError, match="locked"):
        aa.ik.analytic(robot, np.eye(4))
    frame = aa.load("sixr_arm").chain.joints[4].name
    robot = aa.load("sixr_arm", tool=frame)
    assert not aa.ik.has_analytic(robot)
    with pytest.raises(UnsupportedModelError, match="tool frame"):
        aa.ik.analytic(robot, np.eye(4))


def test_plan_cache_does_not_keep_robots_alive():
    robot = aa.load("planar2r")
    aa.ik.analytic(robot, robot.fk(np.array([0.3, 0.5])))
    aa.ik.analytic_batch(robot, robot.fk(np.array([[0.3, 0.5]] * 3)))
    ref = weakref.ref(robot)
    del robot
    gc.collect()
    assert ref() is None


def _unaligned_robot():
    """A 4-joint chain with revolute and prismatic joints about oblique axes (a pin.Model)."""
    model = pin.Model()
    rng = np.random.default_rng(5)
    parent, frame = 0, 0
    for k, joint in enumerate([pin.JointModelRevoluteUnaligned(*(rng.normal(size=3))),
                               pin.JointModelRZ(),
                               pin.JointModelPrismaticUnaligned(*(rng.normal(size=3))),
                               pin.JointModelRevoluteUnaligned(*(rng.normal(size=3)))]):
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3) * 0.2)
        parent = model.addJoint(parent, joint, placement, f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
        frame = model.addBodyFrame(f"link{k}", parent, pin.SE3.Identity(), model.addJointFrame(parent, frame))
    model.addBodyFrame("tool", parent, pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3) * 0.1), frame)
    model.lowerPositionLimit = np.full(model.nq, -2.0)
    model.upperPositionLimit = np.full(model.nq, 2.0)
    return aa.load(model, tool="tool")


@pytest.mark.parametrize("name", ["ur10", "panda", "unimate5", "oblique"])
def test_generated_fk_from_the_chain_matches_pinocchio(name):
    """The generated FK check of any chain (aligned, oblique and prismatic axes) returns
    Pinocchio's max |FK(q) − T|, in the numpy and the scalar form, for every stage split."""
    robot = _unaligned_robot() if name == "oblique" else aa.load(name)
    rng = np.random.default_rng(7)
    Q = robot.random_q(60, rng)
    T = robot.fk(Q)
    Tw = robot.fk(Q + rng.normal(scale=1e-3, size=Q.shape))
    n = robot.nq
    for splits in ((), (1,), (2, n - 1)):
        bounds = [0, *splits, n]
        for po in (False, True):
            fk = FKStages(robot.chain, splits, position_only=po)
            want = np.abs(T[:, :3, 3] - Tw[:, :3, 3]).max(1) if po else np.abs(T[:, :3] - Tw[:, :3]).max((1, 2))
            rows = tuple(Tw[:, i, j] for i in range(3) for j in range(4))
            st = None
            for k, f in enumerate(fk.numpy):
                args = [Q[:, j] for j in range(bounds[k], bounds[k + 1])]
                st = f(*(([st] if k else []) + args + ([rows] if k == fk.n_stages - 1 else [])))
            np.testing.assert_allclose(st, want, rtol=1e-9, atol=1e-15)
            for q, Tx, w in zip(Q[:10], Tw[:10], want[:10]):
                st = None
                for k, f in enumerate(fk.scalar):
                    args = list(q[bounds[k]:bounds[k + 1]])
                    st = f(*(([st] if k else []) + args + ([tuple(Tx[:3].ravel())] if k == fk.n_stages - 1 else [])))
                assert st == pytest.approx(w, rel=1e-9, abs=1e-15)


def test_generated_fk_refuses_continuous_joints():
    with pytest.raises(NotImplementedError, match="continuous"):
        FKStages(aa.load("kinova").chain)


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
            v = g.add(a, b) if r < 0.3 else g.mul(a, b) if r < 0.55 else g.add(a, g.mul(-1.0, b)) if r < 0.8 \
                else g.mul(float(rng.choice([-1.0, -2.5, 3.0])), a)
            if not isinstance(v, float):
                pool.append(v)
        outs = pool[-3:]
        stmts, ref = straight_line(g, outs, lambda inp: inp.name, name_outputs=bool(trial % 2))
        src = "def f(x0, x1, x2, x3):\n" + "".join(f"    {n} = {e}\n" for n, e in stmts) \
            + f"    return ({', '.join(ref(o) for o in outs)},)\n"
        ns = {}
        exec(src, ns)
        for _ in range(5):
            x = rng.normal(size=4) * 3
            got = ns["f"](*x)
            want = _evaluate(g, outs, {f"x{k}": x[k] for k in range(4)})
            assert list(got) == want, src
