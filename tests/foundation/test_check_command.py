"""`anthroarm check` and `anthroarm models` end to end (a real subprocess)."""

import json
import subprocess
import sys


def run(*args):
    return subprocess.run([sys.executable, "-m", "anthroarm.cli", *args], capture_output=True, text=True, timeout=300)


def test_check_json_rows():
    p = run("check", "--models", "prosthetic_arm", "planar2r", "--samples", "30", "--json")
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)
    assert {r["model"] for r in rows} >= {"prosthetic_arm", "planar2r"}
    ours = [r for r in rows if r["model"] in ("prosthetic_arm", "planar2r")]
    assert ours and all(r["ok"] for r in ours)
    assert all(r["samples"] == 30 for r in ours if r["quantity"].startswith(("fk", "jacobian")))


def test_check_unknown_model_is_one_line_error():
    p = run("check", "--models", "nope")
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and "unknown model 'nope'" in p.stderr and "prosthetic_arm" in p.stderr
    assert "Traceback" not in p.stderr


def test_models_json():
    p = run("models", "--json")
    assert p.returncode == 0
    names = [m["name"] for m in json.loads(p.stdout)]
    assert "human_arm7" in names and "panda" in names


def test_urdf_command_writes_parameterised_file(tmp_path):
    out = tmp_path / "arm.urdf"
    p = run("urdf", "human_arm7", "-o", str(out), "--param", "height=1.62", "--param", "sex=female")
    assert p.returncode == 0, p.stderr
    import anthroarm as aa

    assert out.read_text() == aa.models.urdf_text("human_arm7", height=1.62, sex="female")
    p = run("urdf", "human_arm7", "-o", str(tmp_path / "missing" / "a.urdf"))
    assert p.returncode == 2 and "does not exist" in p.stderr and "Traceback" not in p.stderr
