"""Paths of the shipped Gait2354 walking trial and its model (imported by the tests here)."""

from pathlib import Path

import anthroarm

RECORDINGS = Path(anthroarm.__file__).parent / "data" / "opensim" / "recordings"
TRC = RECORDINGS / "subject01_walk1.trc"
SETUP = RECORDINGS / "subject01_Setup_IK.xml"
PUBLISHED_IK = RECORDINGS / "subject01_walk1_ik.mot"
MODEL = RECORDINGS.parent / "subject01_simbody.osim"
