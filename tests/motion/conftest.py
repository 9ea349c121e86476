"""Fixtures of the motion tests (synthetic trials: motion_synthetic.py)."""

import pytest

import anthroarm as aa
from anthroarm.motion import default_marker_set


@pytest.fixture(scope="session")
def arm():
    return aa.load("human_arm7")


@pytest.fixture(scope="session")
def markers(arm):
    return default_marker_set(arm)
