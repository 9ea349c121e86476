"""A dict-valued builder parameter (human_arm7's ``segment_lengths``) on the command line:
``--segment-lengths upperarm=0.30,forearm=0.26`` (or ``--segment_lengths``, or ``--param
segment_lengths=...``) is parsed into a dict; malformed values are one-line errors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import cli, models


def test_help_shows_the_dict_parameter_as_key_value_pairs(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["urdf", "human_arm7", "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.strip().startswith("--segment_lengths"))
    assert "--segment-lengths KEY=VALUE,..." in line


def test_segment_lengths_as_an_option_and_as_param(tmp_path):
    a, b, c = tmp_path / "a.urdf", tmp_path / "b.urdf", tmp_path / "c.urdf"
    assert (
        cli.main(
            ["urdf", "human_arm7", "-o", str(a), "--segment-lengths", "upperarm=0.30,forearm=0.26"]
        )
        == 0
    )
    assert (
        cli.main(
            [
                "urdf",
                "human_arm7",
                "-o",
                str(b),
                "--param",
                "segment_lengths=upper_arm=0.30, forearm=0.26",
            ]
        )
        == 0
    )
    assert cli.main(["urdf", "human_arm7", "-o", str(c), "--segment_lengths", "hand=0.1"]) == 0
    want = models.urdf_text("human_arm7", segment_lengths={"upperarm": 0.30, "forearm": 0.26})
    assert a.read_text() == b.read_text() == want
    # the file's arm really has those lengths: shoulder to hand point at q = 0 (Pinocchio FK)
    default = aa.load("human_arm7").spec.params
    for path, (l1, l2, l3) in (
        (a, (0.30, 0.26, default["l3"])),
        (c, (default["l1"], default["l2"], 0.1)),
    ):
        model = pin.buildModelFromUrdf(str(path))
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        np.testing.assert_allclose(
            data.oMf[model.getFrameId("hand_point")].translation, [0, 0, -(l1 + l2 + l3)], atol=1e-9
        )


@pytest.mark.parametrize(
    "value, needle",
    [
        ("0.3", "KEY=VALUE"),
        ("upperarm=long", "KEY=VALUE"),
        ("upperarm=nan", "finite"),
        ("upperarm=0.3,upperarm=0.31", "each KEY once"),
        ("=0.3", "KEY=VALUE"),
        ("femur=0.4", "known: ['upperarm', 'forearm', 'hand']"),
        ("upperarm=-0.3", "0.02 ... 1.0 m"),
        ("upperarm=1e300", "0.02 ... 1.0 m"),
        ("upperarm=0.3,upper_arm=0.31", "given twice"),
    ],
)
def test_bad_segment_lengths_are_one_line_errors(tmp_path, capsys, value, needle):
    out = tmp_path / "x.urdf"
    assert cli.main(["urdf", "human_arm7", "-o", str(out), "--segment-lengths", value]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not out.exists()
