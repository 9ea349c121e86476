"""Fixtures of the OpenSim recording tests: OpenSim itself (paths: osim_recordings_data.py)."""

import pytest


@pytest.fixture(scope="session")
def osim():
    """The ``opensim`` package (PyPI, the test extra), its log quiet and not written to the
    working folder."""
    osim = pytest.importorskip("opensim")
    osim.Logger.setLevelString("Error")
    osim.Logger.removeFileSink()
    return osim
