"""OpenSim's own marker IK, run from Python: the reference anthroarm's marker IK is checked
against (tests, ``benchmarks/bench_osim_ik.py``, the OpenSim notebook).

:func:`opensim_ik` runs OpenSim's ``InverseKinematicsSolver`` the way its
``InverseKinematicsTool`` does (opensim-core ``OpenSim/Tools/InverseKinematicsTool.cpp``): a
``MarkersReference`` of the marker file with the setup's marker weights (only those markers
tracked), a ``CoordinateReference`` per coordinate task (a ``Constant`` at the coordinate's
default value, or the task's value), the setup's constraint weight and accuracy, ``assemble``
at the first time of the range and ``track`` at every later one.  It returns the coordinates
(rad, m), the per-frame marker errors OpenSim computes (``computeCurrentMarkerErrors``) and
the time each ``track`` took.  :func:`opensim_tool` runs the ``InverseKinematicsTool`` itself
from the setup file and returns its motion and its run time.

Needs the ``opensim`` package (PyPI ``opensim``, Apache-2.0, in the ``test`` extra); the
import is inside the functions (:data:`anthroarm.optional.OPTIONAL`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .ik_setup import IKSetup


@dataclass
class OpenSimIK:
    """OpenSim's IK of a trial.

    Attributes
    ----------
    time : (N,) s
    q : (N, n) coordinates in ``coordinates`` order (rad, m)
    coordinates : tuple of str
    rms, max_error : (N,) marker errors of the tracked markers, m (OpenSim's)
    markers : tuple of str
        The markers OpenSim tracked.
    seconds : (N,)
        Wall time of each frame's ``assemble`` (first) or ``track`` (s).
    """

    time: np.ndarray
    q: np.ndarray
    coordinates: tuple
    rms: np.ndarray
    max_error: np.ndarray
    markers: tuple
    seconds: np.ndarray

    def __len__(self) -> int:
        return self.time.shape[0]


def quiet(osim) -> None:
    """Keep OpenSim's log off the console and out of the working folder (``opensim.log``)."""
    osim.Logger.setLevelString("Error")
    osim.Logger.removeFileSink()


def opensim_ik(model_file, marker_file, setup: IKSetup, *, time_range=None) -> OpenSimIK:
    """OpenSim's ``InverseKinematicsSolver`` on ``marker_file`` (``.trc``) with ``model_file``
    and the weights, coordinate tasks, accuracy and constraint weight of ``setup``, over
    ``time_range`` (default: the setup's; None: every frame)."""
    import opensim as osim

    quiet(osim)
    model = osim.Model(str(model_file))
    state = model.initSystem()
    weights = osim.SetMarkerWeights()
    for name, w in setup.marker_weights.items():
        weights.cloneAndAppend(osim.MarkerWeight(name, float(w)))
    mref = osim.MarkersReference(str(marker_file), weights, osim.Units("m"))
    crefs = osim.SimTKArrayCoordinateReference()
    cs = model.getCoordinateSet()
    for name, task in setup.coordinate_tasks.items():
        if not cs.contains(name):
            continue
        c = cs.get(name)
        value = c.getDefaultValue() if task.value_type == "default_value" else task.value
        ref = osim.CoordinateReference(name, osim.Constant(float(value)))
        ref.setWeight(float(task.weight))
        crefs.push_back(ref)
    cw = setup.constraint_weight
    solver = osim.InverseKinematicsSolver(model, mref, crefs, math.inf if cw is None else float(cw))
    solver.setAccuracy(float(setup.accuracy or 1e-5))
    times = np.array(mref.getMarkerTable().getIndependentColumn())
    tr = setup.time_range if time_range is None else time_range
    if tr is not None:
        times = times[(times >= tr[0] - 1e-9) & (times <= tr[1] + 1e-9)]
    names = tuple(cs.get(i).getName() for i in range(cs.getSize()))
    Q = np.empty((len(times), len(names)))
    rms = np.empty(len(times))
    mx = np.empty(len(times))
    sec = np.empty(len(times))
    errors = osim.SimTKArrayDouble()
    for n, t in enumerate(times):
        state.setTime(float(t))
        t0 = time.perf_counter()
        if n == 0:
            solver.assemble(state)
        else:
            solver.track(state)
        sec[n] = time.perf_counter() - t0
        Q[n] = [cs.get(i).getValue(state) for i in range(len(names))]
        solver.computeCurrentMarkerErrors(errors)
        e = np.array([errors.getElt(k) for k in range(errors.size())])
        rms[n] = float(np.sqrt(np.mean(e**2)))
        mx[n] = float(e.max())
    markers = tuple(solver.getMarkerNameForIndex(k) for k in range(solver.getNumMarkersInUse()))
    return OpenSimIK(times, Q, names, rms, mx, markers, sec)


def opensim_tool(setup_file, model_file, marker_file, out_dir) -> tuple[Path, float]:
    """Run OpenSim's ``InverseKinematicsTool`` from ``setup_file`` with ``model_file`` and
    ``marker_file``, writing its motion into ``out_dir``: (the motion file, seconds of
    ``run()``)."""
    import opensim as osim

    quiet(osim)
    out_dir = Path(out_dir)
    tool = osim.InverseKinematicsTool(str(setup_file))
    model = osim.Model(str(model_file))
    tool.setModel(model)
    tool.setMarkerDataFileName(str(marker_file))
    out = out_dir / "opensim_ik.mot"
    tool.setOutputMotionFileName(str(out))
    tool.setResultsDir(str(out_dir))
    t0 = time.perf_counter()
    tool.run()
    return out, time.perf_counter() - t0
