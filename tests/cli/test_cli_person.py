"""One default person, units in range messages, --deg, "did you mean" (issue 31 item 3).

The CLI's person (anthroarm.cli.person) is checked against the catalog's person models — their
builders' defaults (inspect) and the ranges segment_parameters accepts (the model, not the CLI,
decides) — and every command that takes a person is checked to offer the same defaults, the
same sex choices, and to refuse a value in the wrong unit with the unit and the remedy.
"""

from __future__ import annotations

import inspect

import pytest

from anthroarm import cli, models
from anthroarm.cli import build_parser, person
from anthroarm.errors import AnthroarmError
from anthroarm.models.human import segment_parameters

PERSON_MODELS = [
    n
    for n, b in models.BOOK_MODELS.items()
    if {"height", "mass", "sex"} <= set(inspect.signature(b).parameters)
]


def test_the_person_is_the_catalog_models_person():
    assert PERSON_MODELS, "no person model in the catalog"
    for name in PERSON_MODELS:
        sig = inspect.signature(models.BOOK_MODELS[name]).parameters
        assert {k: sig[k].default for k in person.PERSON} == person.PERSON, name
    for sex in person.SEXES:
        segment_parameters(sex=sex)
    with pytest.raises(AnthroarmError):
        segment_parameters(sex="other")
    for name, (lo, hi, *_) in person.RANGES.items():
        segment_parameters(**{name: lo})
        segment_parameters(**{name: hi})
        for bad in (lo * 0.99, hi * 1.01):
            with pytest.raises(AnthroarmError):
                segment_parameters(**{name: bad})


def options(argv):
    """{option: its help text} of the command's parser."""
    ap = build_parser(argv)
    sp = ap.commands[argv[0]]
    text = sp.format_help()
    return text


@pytest.mark.parametrize(
    "argv",
    [["size"], ["ik-markers", "t.c3d"], ["demo"], ["view", "human_arm7"], ["urdf", "human_arm7"]],
)
def test_every_command_offers_the_same_person(argv):
    text = " ".join(options(argv).split())
    assert "1.75" in text and "75" in text and "{male,female}" in text, text
    assert "0.5–2.6" in text and "10–300" in text, text


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["size", "--height", "175"], "--height 175 is outside 0.5–2.6 m: give metres"),
        (["size", "--mass", "75000"], "--mass 75000 is outside 10–300 kg: give kilograms"),
        (["demo", "--height", "175"], "--height 175 is outside 0.5–2.6 m: give metres"),
        (["urdf", "human_arm7", "--mass", "7"], "outside 10–300 kg"),
        (["ik-markers", "t.c3d", "--height", "162"], "give metres"),
        (["demo", "--sex", "f"], "invalid choice: 'f'"),
        (["batch", "population", "--heights", "150,160"], "--heights 150 is outside 0.5–2.6 m"),
        (["batch", "population", "--masses", "55000"], "give kilograms"),
        (["batch", "population", "--sexes", "m"], "male and female"),
        (["size", "--payload", "-1"], "kg"),
    ],
)
def test_a_value_in_the_wrong_unit_is_refused_with_the_unit(tmp_path, capsys, argv, needle):
    out = tmp_path / ("x.csv" if argv[0] == "ik-markers" else "x.html")
    if argv[0] == "batch":
        out = tmp_path / "x.npz"
    if argv[0] == "urdf":
        out = tmp_path / "x.urdf"
    code = None
    try:
        code = cli.main([*argv, "-o", str(out)])
    except SystemExit as e:  # argparse's own errors exit
        code = e.code
    assert code == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1, err
    assert not out.exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["ik", "human_arm7", "--xyz", "0.3", "0", "0", "--rpy", "180", "0", "0"],
        ["view", "human_arm7", "--q", "40", "-20", "10", "70", "0", "0", "10"],
        ["teach", "human_arm7", "--q", "40", "-20", "10", "70", "0", "0", "10"],
        ["ik", "human_arm7", "--xyz", "0.3", "0", "0", "--q0", "90", "0", "0", "0", "0", "0", "0"],
    ],
)
def test_degrees_without_deg_are_refused_with_the_remedy(tmp_path, capsys, argv):
    out = tmp_path / "x.html"
    extra = ["-o", str(out)] if argv[0] in ("view", "teach") else []
    assert cli.main([*argv, *extra]) == 2
    err = capsys.readouterr().err
    assert "more than a full turn" in err and "--deg" in err and err.count("\n") == 1, err
    assert not out.exists()


def test_radians_and_degrees_with_deg_still_work(tmp_path, capsys):
    out = tmp_path / "x.html"
    q = ["0.7", "-0.35", "0.17", "1.2", "0", "0", "0.17"]
    assert cli.main(["view", "human_arm7", "--q", *q, "-o", str(out)]) == 0
    deg = ["40", "-20", "10", "70", "0", "0", "10"]
    assert cli.main(["view", "human_arm7", "--q", *deg, "--deg", "-o", str(out)]) == 0


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["ik", "human_arm", "--xyz", "0.3", "0", "0"], "did you mean 'human_arm7'"),
        (["ik", "human_arm7", "--xyz", "0.3", "0", "0", "--tol", "1"], "did you mean --tool?"),
        (["size", "--actvities", "adl"], "did you mean --activities?"),
        (["view", "human_arm7", "--camra", "front"], "did you mean --camera?"),
        (["size", "--activities", "hand_to_mouht"], "did you mean 'hand_to_mouth'"),
        (["size", "--activities", "adk"], "did you mean 'adl'"),
    ],
)
def test_did_you_mean(tmp_path, capsys, argv, needle):
    extra = [] if argv[0] == "ik" else ["-o", str(tmp_path / "x.html")]
    assert cli.main([*argv, *extra]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1, err


def test_camera_choices_are_the_viewers():
    from anthroarm.cli.common import CAMERA_FITS, CAMERA_VIEWS
    from anthroarm.viewer.framing import FITS, VIEWS

    assert set(CAMERA_VIEWS) == set(VIEWS) and set(CAMERA_FITS) == set(FITS)
    for cmd in (["view", "human_arm7"], ["teach", "human_arm7"], ["demo"]):
        text = options(cmd)
        assert "--camera" in text and "--fit" in text, cmd
