"""`anthroarm check`, `anthroarm models` and `anthroarm urdf` end to end: any robot in (catalog,
example-robot-data names, URDF paths), real rows out, non-zero exit when a row fails."""

import importlib.util
import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
from test_chain import USER_URDF

import anthroarm as aa
from anthroarm import cli, crosscheck
from anthroarm.models import book as book_models

#: the rows every robot gets (book models get more)
GENERIC = {
    "fk batched chain robot.fk(Q)",
    "jacobian batched chain LWA",
    "fk yourdfpy (all links)",
    "J_L (6-118) vs FD of perturbed placements",
    "perturbed FK T(q, L+dL) vs pin on the perturbed model",
    "dyn M(q) Lagrange",
    "dyn C(q,qd)qd Christoffel",
    "dyn g(q) = dV/dq",
    "dyn tau = M qdd + C qd + g",
    "dyn forward dynamics",
    "aa.ik.solve: FK(solve(T)) = T within limits",
}


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", *args], capture_output=True, text=True, timeout=300
    )


def check_json(argv, capsys):
    rc = cli.main(["check", *argv, "--json"])
    out, err = capsys.readouterr()
    return rc, json.loads(out) if out.strip() else None, err


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


def test_check_json_rows():
    p = run("check", "--models", "prosthetic_arm", "planar2r", "--samples", "30", "--json")
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)
    assert {r["model"] for r in rows} >= {"prosthetic_arm", "planar2r"}
    ours = [r for r in rows if r["model"] in ("prosthetic_arm", "planar2r")]
    assert ours and all(r["ok"] and r["status"] == "ok" for r in ours)
    assert all(r["samples"] == 30 for r in ours if r["quantity"].startswith(("fk", "jacobian")))
    assert GENERIC <= {r["quantity"] for r in ours if r["model"] == "planar2r"}
    assert "fk printed Fig. 7-14 (y, z)" in {
        r["quantity"] for r in ours if r["model"] == "planar2r"
    }


def test_check_example_robot_data_name(capsys):
    rc, rows, err = check_json(["ur10", "--samples", "20"], capsys)
    assert rc == 0, err
    ur10 = [r for r in rows if r["model"] == "ur10"]
    geometry = {"closed form by geometry: FK(IK(T)) = T, all branches"}  # a 6R class (ik.geometric)
    if importlib.util.find_spec("ik_geo"):
        geometry.add("closed form by geometry: branches = IK-Geo's")
    assert {r["quantity"] for r in ur10} == GENERIC | geometry | {
        "dyn C(q,qd) Christoffel matrix",
        "dyn kinetic energy T",
        "dyn potential energy V",
        "collision distances = coal.distance",  # its URDF's <collision> bodies (issue 33)
        "collision damper: d >= d_s - 1e-4 along QP steps",
    }
    assert all(r["ok"] for r in rows)
    assert all(r["max_abs_err"] <= r["tol"] for r in ur10)
    # no book rows for an arm that is not a book model
    assert not [r for r in ur10 if "printed" in r["quantity"] or "H-D" in r["quantity"]]


def test_check_user_urdf_with_continuous_and_mimic_joints(user_urdf, capsys):
    rc, rows, err = check_json([str(user_urdf), "--tool", "tool", "--samples", "20"], capsys)
    assert rc == 0, err
    ours = [r for r in rows if r["model"] == "user_arm"]
    assert GENERIC <= {r["quantity"] for r in ours}
    assert all(r["ok"] for r in rows), [r for r in rows if not r["ok"]]
    assert any("mimic" in r["note"] for r in ours if r["quantity"] == "fk yourdfpy (all links)")
    # --tool applies to every model given: a model without that frame is a one-line error
    rc2 = cli.main(["check", f"--models={user_urdf},kinova", "--tool", "tool", "--samples", "5"])
    out, err = capsys.readouterr()
    assert rc2 == 2 and "kinova" in err and "unknown tool frame 'tool'" in err


def test_check_comma_separated_models_and_locked(capsys):
    rc, rows, err = check_json(["--models", "z1,planar2r", "--samples", "10"], capsys)
    assert rc == 0, err
    assert {"z1", "planar2r"} <= {r["model"] for r in rows}
    rc, rows, err = check_json(
        ["so101", "--tool", "gripper_frame_link", "--locked", "gripper", "--samples", "10"], capsys
    )
    assert rc == 0, err
    assert GENERIC <= {r["quantity"] for r in rows if r["model"] == "so101"}


def test_check_tree_without_tool_lists_the_tips(capsys):
    rc = cli.main(["check", "baxter"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "l_gripper_r_finger_tip" in err and "tool=" in err
    rc = cli.main(["check", "--tool", "tool0"])
    assert rc == 2 and "name one" in capsys.readouterr().err
    rc = cli.main(["check", "ur10", "--locked", "shoulder_pan_joint=abc"])
    assert rc == 2 and "NAME=VALUE" in capsys.readouterr().err


def test_check_unknown_model_is_one_line_error():
    p = run("check", "--models", "nope")
    assert p.returncode == 2
    assert (
        p.stderr.count("\n") == 1
        and "unknown model 'nope'" in p.stderr
        and "prosthetic_arm" in p.stderr
    )
    assert "Traceback" not in p.stderr


def test_check_fails_loudly(monkeypatch, capsys):
    real = book_models.sixr_hand_pose

    def wrong(q, *a):  # a planted 1 mm error in the hand height
        T = real(q, *a)
        T[..., 2, 3] += 1e-3
        return T

    monkeypatch.setattr(book_models, "sixr_hand_pose", wrong)
    rc = cli.main(["check", "sixr_arm", "--samples", "5", "--jobs", "1"])  # planted here only
    out = capsys.readouterr().out
    assert rc == 1
    bad = [ln for ln in out.splitlines() if ln.rstrip().endswith("FAIL")]
    assert len(bad) == 1 and "fk printed (6-16)/(6-17)" in bad[0]
    assert "1 failed, 0 unsupported" in out


def test_rows_the_same_in_two_processes():
    """--jobs 2 (two spawned processes, each loading its models by name) gives the rows of one
    process, in the same order, to the last digit (the notes may say where a process found its
    generated code: in memory, on disk)."""
    kw = dict(samples=8, seed=3)
    one = crosscheck.run(["planar2r", "sixr_arm"], **kw)
    two = crosscheck.run(["planar2r", "sixr_arm"], workers=2, **kw)

    def rows(rs):
        return [{k: v for k, v in json.loads(crosscheck.to_json([r]))[0].items() if k != "note"}
                for r in rs]  # fmt: skip

    assert len(one) > 10
    assert rows(one) == rows(two)


@pytest.mark.parametrize("jobs", ["0", "-1", "65"])
def test_check_jobs_out_of_range_is_one_line_error(jobs):
    p = run("check", "planar2r", "--samples", "2", "--jobs", jobs)
    assert p.returncode == 2 and "--jobs must be in 1..64" in p.stderr
    assert "Traceback" not in p.stderr


def test_unsupported_row_does_not_pass():
    """A robot loaded from a pin.Model has no URDF: the yourdfpy row says so and does not pass;
    every other row still runs."""
    model = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path("ur10")))
    robot = aa.load(model, name="ur10_model")
    rows = crosscheck.run([robot], samples=5, providers=list(crosscheck.ROBOT_PROVIDERS))
    bad = [r for r in rows if not r.ok]
    assert [(r.quantity, r.status) for r in bad] == [("fk yourdfpy (all links)", "unsupported")]
    assert "no URDF" in bad[0].note and np.isnan(bad[0].max_abs_err)
    table = crosscheck.format_table(rows)
    assert f"{len(rows) - 1} passed, 0 failed, 1 unsupported" in table
    assert "ur10_model: fk yourdfpy (all links): unsupported: loaded from a pin.Model" in table


def test_models_prints_nq_nv_and_kinds_for_every_entry(capsys):
    assert cli.main(["models", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [o["name"] for o in out] == aa.models.names()
    for o in out:  # oracle: Pinocchio on the URDF text, minus the joints the catalog locks
        if o["name"] in aa.models.BOOK_MODELS:
            m = pin.buildModelFromXML(aa.models.urdf_text(o["name"]), mimic=True)
            assert (o["nq"], o["nv"]) == (m.nq, m.nv)
        else:
            arm = aa.models.ERD_ARMS[o["name"]]
            m = pin.buildModelFromUrdf(str(arm.urdf_path()))
            n = len(arm.active) if arm.active else m.nq
            assert (o["nq"], o["nv"]) == (n, n)
        # every joint with a coordinate of its own is counted once (a mimic joint has none)
        own = sum(v for k, v in o["kinds"].items() if k != "mimic")
        assert own == o["nq"] and o["error"] is None and not o["needs_tool"]
        if o["name"] in aa.models.BOOK_MODELS:  # and the mimic joints are Pinocchio's
            assert o["kinds"].get("mimic", 0) == sum(
                1 for j in m.joints[1:] if "Mimic" in j.shortname()
            )
    assert cli.main(["models"]) == 0
    text = capsys.readouterr().out
    assert "nq=?" not in text
    assert "ur5" in text and "nq=6" in text.split("ur5", 1)[1].splitlines()[0]


def test_models_all_lists_every_example_robot_data_robot(capsys):
    assert cli.main(["models", "--all", "--json"]) == 0
    out = {o["name"]: o for o in json.loads(capsys.readouterr().out)}
    assert set(aa.models.erd_names()) <= set(out)
    k = out["kinova"]
    m = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path("kinova")))
    assert (k["nq"], k["nv"], k["kinds"].get("continuous")) == (m.nq, m.nv, 3)
    assert out["so101"]["needs_tool"] and "gripper_frame_link" in out["so101"]["tips"]
    assert out["baxter"]["needs_tool"] and out["baxter"]["kinds"]["mimic"] == 2
    assert out["ur10"]["tool"] == "tool0" and not out["ur10"]["needs_tool"]
    assert cli.main(["models", "--all"]) == 0
    text = capsys.readouterr().out
    line = next(ln for ln in text.splitlines() if ln.startswith("so101 "))
    assert "needs tool=" in line and "gripper_frame_link" in line


def test_urdf_command_writes_parameterised_file(tmp_path):
    out = tmp_path / "arm.urdf"
    p = run("urdf", "human_arm7", "-o", str(out), "--param", "height=1.62", "--param", "sex=female")
    assert p.returncode == 0, p.stderr
    assert out.read_text() == aa.models.urdf_text("human_arm7", height=1.62, sex="female")
    p = run("urdf", "human_arm7", "-o", str(tmp_path / "missing" / "a.urdf"))
    assert p.returncode == 2 and "does not exist" in p.stderr and "Traceback" not in p.stderr


def test_urdf_command_takes_example_robot_data_names_and_paths(tmp_path, user_urdf, capsys):
    out = tmp_path / "xarm7.urdf"
    assert cli.main(["urdf", "xarm7", "-o", str(out)]) == 0
    assert out.read_text() == aa.models.erd_urdf_path("xarm7").read_text()
    copy = tmp_path / "copy.urdf"
    assert cli.main(["urdf", str(user_urdf), "-o", str(copy)]) == 0
    assert copy.read_text() == USER_URDF
    capsys.readouterr()
    assert cli.main(["urdf", "xarm7", "-o", str(out), "--param", "height=2"]) == 2
    assert "takes no parameters" in capsys.readouterr().err


def test_book_rows_only_for_the_book_model_as_catalogued():
    """human_arm7 with another tool is not the chain the printed forms describe: generic rows
    only (and they pass on the elbow frame), no printed FK, no closed-form IK rows."""
    provs = [*crosscheck.ROBOT_PROVIDERS, "anthroarm.ik.checks:rows"]
    rows = crosscheck.run(["human_arm7"], samples=10, providers=provs, tool="elbow_flexion")
    assert {r.quantity for r in rows} >= GENERIC and all(r.ok for r in rows)
    assert not [r for r in rows if "printed" in r.quantity or "analytic" in r.quantity]
    rows = crosscheck.run(["human_arm7"], samples=10, providers=provs)
    assert {"fk printed (6-34)-(6-39)", "(6-119) vs FD of perturbed placements"} <= {
        r.quantity for r in rows
    }
    assert any("analytic IK" in r.quantity for r in rows) and all(r.ok for r in rows)
