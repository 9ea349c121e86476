"""A bare name of a file shipped with anthroarm (the OpenSim models and gait trial) works from
any folder, as the OpenSim guide writes its commands; a file in the folder comes first."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

import anthroarm as aa
from anthroarm.cli.runtime import input_file

DATA = Path(aa.__file__).parent / "data" / "opensim"


def _sha(p) -> str:
    return hashlib.sha256(Path(p).read_bytes()).hexdigest()


@pytest.mark.parametrize(
    "name, expected",
    [
        ("gait2392.osim", DATA / "gait2392_thelen2003muscle.osim"),
        ("gait2392_thelen2003muscle.osim", DATA / "gait2392_thelen2003muscle.osim"),
        ("Tug_of_War.osim", DATA / "Tug_of_War.osim"),
        ("subject01_walk1.trc", DATA / "recordings" / "subject01_walk1.trc"),
        ("subject01_Setup_IK.xml", DATA / "recordings" / "subject01_Setup_IK.xml"),
    ],
)
def test_a_bare_shipped_name_is_the_shipped_file(name, expected):
    assert aa.osim.shipped_file(name) == expected
    assert expected.is_file()


@pytest.mark.parametrize(
    "name", ["nope.osim", "sub/gait2392.osim", "/tmp/subject01_walk1.trc", "CREDITS.md", "gait2392"]
)
def test_other_names_are_not_shipped_files(name):
    assert aa.osim.shipped_file(name) is None


def test_a_file_in_the_folder_comes_first(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "arm26.osim").write_bytes((DATA / "Tug_of_War.osim").read_bytes())
    assert input_file("arm26.osim") == "arm26.osim"  # the user's own file, not ours
    assert capsys.readouterr().err == ""
    got = input_file("subject01_walk1.trc")
    assert _sha(got) == _sha(DATA / "recordings" / "subject01_walk1.trc")
    assert "copy shipped with anthroarm" in capsys.readouterr().err
    assert input_file("missing.trc") == "missing.trc"  # left to the reader's clear error
    assert not os.path.exists("missing.trc")
