"""Hostile input to :mod:`anthroarm.prosthesis` (issue 30): catalogue and trajectory paths
that are not regular files or not CSV text, and the sizing study and weight rules fed
NaN/inf/negative masses, wrong types and empty activity lists.  Each is refused with a typed
error naming the file or the value (:class:`~anthroarm.errors.CatalogueError`,
``ActivityError``, ``ParameterError``, ``InertiaError``), never a numpy or Python error.

Before the fixes of issue 30: /dev/zero as a catalogue read until MemoryError (the process
was killed); a FIFO blocked; a NUL byte and a field beyond csv's size limit raised csv.Error;
the weight rules took a string DOF (TypeError), NaN DOF, negative unsized joints and True as
a mass; a failed activity with a payload "heavy" raised numpy's UFuncTypeError and one with a
NaN payload was recorded as NaN kg.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.cli.size_run import read_trajectory as _read_trajectory
from anthroarm.errors import ActivityError, CatalogueError, InertiaError, ParameterError
from anthroarm.prosthesis import catalogue as C
from anthroarm.prosthesis import envelope, study, weight_rules

HEADER = ",".join(C.MOTOR_COLUMNS)
ROW = "M1,RE,16,12,10,20,1,10,10000,40"


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


# ------------------------------------------------------------------ catalogue files
def test_dev_zero_is_refused_unread():
    with pytest.raises(CatalogueError, match="/dev/zero: is a device"):
        C.load_motors("/dev/zero")


def test_source_note_of_dev_zero_is_refused():
    with pytest.raises(CatalogueError, match="device"):
        C.source_note("/dev/zero")


def test_fifo_is_refused_without_waiting(tmp_path):
    f = tmp_path / "m.csv"
    os.mkfifo(f)
    t0 = time.monotonic()
    with pytest.raises(CatalogueError, match="FIFO"):
        C.load_motors(f)
    assert time.monotonic() - t0 < 5


def test_folder_is_refused(tmp_path):
    with pytest.raises(CatalogueError, match="folder"):
        C.load_gearboxes(tmp_path)


def test_file_beyond_the_size_bound(tmp_path, monkeypatch):
    m = tmp_path / "m.csv"
    m.write_text(f"{HEADER}\n{ROW}\n")
    monkeypatch.setattr(C, "MAX_FILE_BYTES", 10)
    with pytest.raises(CatalogueError, match="more than the bound"):
        C.load_motors(m)


def test_nul_bytes(tmp_path):
    m = tmp_path / "m.csv"
    m.write_text(f"{HEADER}\n\x00{ROW}\n")
    with pytest.raises(CatalogueError, match="NUL"):
        C.load_motors(m)


def test_field_beyond_the_csv_limit(tmp_path):
    m = tmp_path / "m.csv"
    m.write_text(f'{HEADER}\n"{"x" * 200_000}"\n')
    with pytest.raises(CatalogueError, match="not a readable CSV"):
        C.load_motors(m)


def test_too_many_rows(tmp_path, monkeypatch):
    m = tmp_path / "m.csv"
    m.write_text(HEADER + "\n" + "\n".join(ROW.replace("M1", f"M{i}") for i in range(20)) + "\n")
    monkeypatch.setattr(C, "MAX_ROWS", 10)
    with pytest.raises(CatalogueError, match="more than 10 products"):
        C.load_motors(m)


# ------------------------------------------------------------------ trajectory files
def test_trajectory_from_dev_zero(arm):
    with pytest.raises(ActivityError, match="device"):
        _read_trajectory(Path("/dev/zero"), arm)


# ------------------------------------------------------------------ weight rules
@pytest.mark.parametrize(
    "args",
    [
        (1.0, 70.0, "7"),
        (1.0, 70.0, float("nan")),
        (1.0, 70.0, True),
        (1.0, 70.0, 7, -3),
        (True, 70.0, 7),
        (1.0, True, 7),
        (float("nan"), 70.0, 7),
        (1.0, -70.0, 7),
        (1.0, float("inf"), 7),
        (-1.0, 70.0, 7),
    ],
)
def test_weight_rules_refuse_bad_numbers(args):
    with pytest.raises(ParameterError, match="weight rules need"):
        weight_rules.check(*args)


# ------------------------------------------------------------------ the study
def _still(arm, n=10):
    return dict(t=np.linspace(0.0, 1.0, n), q=np.zeros((n, arm.nq)))


def test_failed_activity_with_a_payload_that_is_not_a_number(arm):
    with pytest.raises(ActivityError, match="'payload' must be"):
        study.run(arm, [dict(name="x", status="failed", payload="heavy"), _still(arm)])


def test_failed_activity_with_a_nan_payload(arm):
    with pytest.raises(ActivityError, match="payload must be a mass"):
        study.run(arm, [dict(name="x", status="failed", payload=float("nan")), _still(arm)])


@pytest.mark.parametrize(
    "kw, error",
    [
        (dict(activities=[]), ActivityError),
        (dict(activities=[5]), ActivityError),
        (dict(activities=[{"t": [0.0, 1.0]}]), ActivityError),
        (dict(payload=float("nan")), ActivityError),
        (dict(payload=-1.0), ActivityError),
        (dict(margin=float("inf")), ActivityError),
        (dict(person=dict(mass=float("nan"))), ParameterError),
        (dict(person=dict(mass=-60.0)), ParameterError),
    ],
)
def test_study_refuses_hostile_parameters(arm, kw, error):
    kw.setdefault("activities", [_still(arm)])
    with pytest.raises(error):
        study.run(arm, **kw)


@pytest.mark.parametrize("mass", [float("nan"), float("inf"), -1.0, 0.0, 1e308])
def test_held_object_masses(mass):
    with pytest.raises(InertiaError, match="mass"):
        envelope.held_object(mass)


def test_adl_with_a_nan_payload(arm):
    with pytest.raises(ActivityError, match="payload"):
        study.adl_activities(arm, payload=float("nan"))
