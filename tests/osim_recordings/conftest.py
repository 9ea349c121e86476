"""Fixtures of the OpenSim recording tests: the shipped Gait2354 trial and OpenSim itself."""

from pathlib import Path

import pytest

import anthroarm

RECORDINGS = Path(anthroarm.__file__).parent / "data" / "opensim" / "recordings"
TRC = RECORDINGS / "subject01_walk1.trc"
SETUP = RECORDINGS / "subject01_Setup_IK.xml"
PUBLISHED_IK = RECORDINGS / "subject01_walk1_ik.mot"
MODEL = RECORDINGS.parent / "subject01_simbody.osim"


@pytest.fixture(scope="session")
def osim():
    """The ``opensim`` package (PyPI, the test extra), its log quiet and not written to the
    working folder."""
    osim = pytest.importorskip("opensim")
    osim.Logger.setLevelString("Error")
    osim.Logger.removeFileSink()
    return osim
