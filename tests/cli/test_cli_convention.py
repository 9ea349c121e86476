"""One CLI convention over every command's parser (issue 31 item 3; docs/guide/cli.md): the model
is the positional MODEL (``--model`` only as a deprecated alias), a file or folder written is
``-o/--out`` (old spellings as aliases of the same option), ``--json`` wherever JSON is printed,
"did you mean" for a misspelled model; and ``--help`` loads neither numpy nor pinocchio."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from anthroarm import cli
from anthroarm.cli import runtime

#: commands that take a model: the positional MODEL (``check`` takes several)
MODEL = {"check", "ik", "view", "teach", "urdf", "batch", "size", "ik-markers"}
#: ... optional (the person's arm by default), with --model kept as a deprecated alias
OPTIONAL_MODEL = {"batch", "size", "ik-markers"}
#: commands that write a file or a folder
WRITES = {"urdf", "view", "teach", "demo", "bench", "batch", "size", "ik-markers"}
#: commands that print JSON (always, or with --json)
JSON = {"check", "models", "ik", "demo", "cache", "batch", "size", "ik-markers"}
#: old spellings of -o/--out, kept as aliases
OLD_OUT = {"urdf": {"--output"}, "view": {"--html"}, "teach": {"--html"}, "demo": {"--html"}}


def subparsers() -> dict[str, argparse.ArgumentParser]:
    ap = cli.build_parser([])
    (sub,) = [a for a in ap._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(sub.choices)


COMMANDS = sorted(subparsers())


def options(p) -> dict[str, argparse.Action]:
    return {s: a for a in p._actions for s in a.option_strings}


def test_the_lists_cover_every_command():
    assert set(COMMANDS) == {
        "check",
        "models",
        "ik",
        "view",
        "teach",
        "demo",
        "urdf",
        "bench",
        "cache",
        "batch",
        "size",
        "ik-markers",
    }
    assert MODEL | WRITES | JSON <= set(COMMANDS)


@pytest.mark.parametrize("name", COMMANDS)
def test_model_is_the_positional(name):
    p = subparsers()[name]
    positional = {a.dest: a for a in p._actions if not a.option_strings}
    opts = options(p)
    if name not in MODEL:
        assert "model" not in positional and "--model" not in opts
        return
    assert "model" in positional and positional["model"].metavar == "MODEL"
    if name in OPTIONAL_MODEL:
        assert positional["model"].nargs == "?"
        assert opts["--model"].dest == "model_alias" and "deprecated" in opts["--model"].help
    else:
        assert "--model" not in opts or name == "check"  # check: --models A,B,C (more models)


@pytest.mark.parametrize("name", COMMANDS)
def test_output_is_dash_o_out(name):
    opts = options(subparsers()[name])
    if name not in WRITES:
        assert not {"-o", "--out", "--output", "--html"} & set(opts)
        return
    out = opts["--out"]
    assert opts["-o"] is out and out.dest == "out"
    assert set(out.option_strings) == {"-o", "--out", *OLD_OUT.get(name, set())}


@pytest.mark.parametrize("name", COMMANDS)
def test_json_where_json_is_printed(name):
    opts = options(subparsers()[name])
    assert ("--json" in opts) == (name in JSON)


@pytest.mark.parametrize(
    "argv, model",
    [
        (["size", "prosthetic_arm"], "prosthetic_arm"),
        (["size", "--model", "prosthetic_arm"], "prosthetic_arm"),
        (["size"], "human_arm7"),
        (["batch", "reach", "panda"], "panda"),
        (["batch", "reach", "--model", "panda"], "panda"),
        (["ik-markers", "t.c3d", "ur5", "-o", "x.csv"], "ur5"),
        (["ik-markers", "t.c3d", "--model", "ur5", "--out", "x.csv"], "ur5"),
    ],
)
def test_optional_model_positional_and_deprecated_alias(argv, model):
    a = cli.build_parser(argv).parse_args(argv)
    runtime.resolve_model(a)
    assert a.model == model


def test_two_different_models_are_refused():
    argv = ["size", "panda", "--model", "ur5"]
    a = cli.build_parser(argv).parse_args(argv)
    with pytest.raises(cli.UserError, match="two models"):
        runtime.resolve_model(a)


@pytest.mark.parametrize(
    "argv",
    [
        ["urdf", "planar2r", "--output", "x.urdf"],
        ["urdf", "planar2r", "-o", "x.urdf"],
        ["view", "planar2r", "--html", "x.urdf"],
        ["teach", "planar2r", "--out", "x.urdf"],
        ["demo", "--html", "x.urdf"],
    ],
)
def test_old_output_spellings_still_work(argv):
    assert cli.build_parser(argv).parse_args(argv).out == "x.urdf"


def test_batch_takes_the_model_parameters_as_options():
    argv = ["batch", "reach", "human_arm7", "--height", "1.62"]
    a = cli.build_parser(argv).parse_args(argv)
    assert runtime.parse_params(a.param, a.model, a) == {"height": 1.62}


def test_a_misspelled_model_gets_did_you_mean(tmp_path, capsys):
    rc = cli.main(["urdf", "human_arm8", "-o", str(tmp_path / "a.urdf")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1
    assert "did you mean 'human_arm7'" in err
    assert runtime.suggestions("pandaa")[0] == "panda"
    assert runtime.suggestions("zzzzzz") == []


HELP = """
import sys
from anthroarm import cli
for argv in [[], *[[c] for c in {commands!r}]]:
    try:
        cli.main([*argv, "--help"])
    except SystemExit:
        pass
heavy = sorted(m for m in ("numpy", "pinocchio", "scipy", "anthroarm.robot") if m in sys.modules)
print("HEAVY", heavy)
"""


def test_help_imports_neither_numpy_nor_pinocchio():
    """``anthroarm --help`` and every ``anthroarm COMMAND --help`` (what makes them fast: ~2 s
    of imports before, ~0.1 s now); not ``demo --help``, which lists the parameters of the
    person's arm it shows (like ``anthroarm urdf MODEL --help``), read from the catalog."""
    light = [c for c in COMMANDS if c != "demo"]
    r = subprocess.run(
        [sys.executable, "-c", HELP.format(commands=light)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert "usage: anthroarm ik-markers" in r.stdout
    assert r.stdout.strip().splitlines()[-1] == "HEAVY []", r.stdout[-500:]
