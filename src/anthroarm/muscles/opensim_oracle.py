"""OpenSim's own static optimisation, run from Python: the reference
:func:`anthroarm.muscles.static_optimization` is checked against
(``tests/muscles/test_static_opt_vs_opensim.py``, ``benchmarks/bench_muscles.py``).

:func:`opensim_static_optimization` runs OpenSim's ``StaticOptimization`` analysis in an
``AnalyzeTool`` (opensim-core ``OpenSim/Simulation/Analyses/StaticOptimization.cpp``,
``OpenSim/Tools/AnalyzeTool.cpp``) on a coordinates file: no low-pass filter
(``lowpass_cutoff_frequency`` −1), no external loads, ``use_model_force_set``, activation
exponent 2 (the objective Σ aᵢ² over muscles and actuator controls), ``use_muscle_physiology``
on (a muscle's force a·F_A with F_A = f_L f_V cos φ F₀), and the model's muscles plus one
``CoordinateActuator`` per coordinate named ``<coordinate>_reserve`` of optimal force
``strength`` and controls bounded by ±1e6.  The model with its actuators and the tool's setup
are written into ``out_dir`` and the tool is run from that setup file, as OpenSim's GUI and
``opensim-cmd`` run it; its activations and forces are read back from the ``.sto`` files it
writes.

:func:`opensim_kinematics` gives q, q̇ and q̈ at given times as that run forms them: the
AnalyzeTool's q̇ is the derivative of a degree-5 GCV spline of the coordinates
(``GCVSplineSet(5, ·).constructStorage(1)``), and ``StaticOptimization::begin`` builds its
target accelerations q̈ as the derivative of a GCV spline of q̇ (Woltring 1986, the GCV
spline).

Needs the ``opensim`` package (PyPI ``opensim``, Apache-2.0, in the ``test`` extra); the
import is inside the functions (:data:`anthroarm.optional.OPTIONAL`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MuscleError

#: the bounds of the reserve actuators' controls (OpenSim's ±inf stand-in)
CONTROL_BOUND = 1e6
#: how far (s) a time may be from a row of the motion: OpenSim prints its results' times to 8
#: decimals
TIME_TOL = 1e-6


@dataclass
class OpenSimStaticOptimization:
    """OpenSim's static optimisation of a motion.

    Attributes
    ----------
    time : (N,) s
        The frames the analysis solved.
    activation : (N, M)
        The muscles' activations, in the order asked for.
    force : (N, M) N
        The muscles' forces a·F_A.
    reserve : (N, n) N m (or N)
        The reserve actuators' generalized forces (optimal force × control), by coordinate.
    seconds : float
        Wall time of ``AnalyzeTool.run()`` (model set-up, splines and every frame's solve).
    states_q, states_u : (N, n) or None
        The coordinates and speeds of the states OpenSim solved at (its ``StatesReporter``),
        when asked for with ``states=True``.
    """

    time: np.ndarray
    activation: np.ndarray
    force: np.ndarray
    reserve: np.ndarray
    seconds: float
    states_q: np.ndarray | None = None
    states_u: np.ndarray | None = None

    def __len__(self) -> int:
        return self.time.shape[0]


def _opensim():
    import opensim as osim

    osim.Logger.setLevelString("Error")
    osim.Logger.removeFileSink()  # no opensim.log in the working folder
    return osim


def columns(osim, store) -> tuple[np.ndarray, list[str], np.ndarray]:
    """(time (N,), labels, data (N, columns)) of an OpenSim ``Storage``, time left out of the
    labels and the data."""
    tt = osim.ArrayDouble()
    store.getTimeColumn(tt)
    t = np.array([tt.get(i) for i in range(tt.getSize())])
    labels = store.getColumnLabels()
    labels = [labels.get(i) for i in range(1, labels.getSize())]
    data = []
    for lab in labels:
        a = osim.ArrayDouble()
        store.getDataColumn(lab, a)
        data.append([a.get(i) for i in range(a.getSize())])
    return t, labels, np.array(data).T.reshape(len(t), len(labels))


def pick(labels, data, names, suffix: str = "") -> np.ndarray:
    """The columns of ``data`` named ``names``: a label equal to the name, or a path ending in
    ``/<name><suffix>`` (OpenSim 4's state names, ``/jointset/hip_r/hip_flexion_r/value``).
    A name with no column: :class:`~anthroarm.errors.MuscleError`."""
    idx = []
    for n in names:
        found = [i for i, lab in enumerate(labels) if lab == n or lab.endswith(f"/{n}{suffix}")]
        if not found:
            raise MuscleError(f"no column {n!r}{suffix and f' ({suffix})'} in OpenSim's storage")
        idx.append(found[0])
    return data[:, idx]


def opensim_static_optimization(
    model_file,
    motion_file,
    coordinates,
    strength,
    muscle_names,
    t0: float,
    t1: float,
    out_dir,
    *,
    criterion: float = 1e-10,
    max_iterations: int | None = None,
    states: bool = False,
) -> OpenSimStaticOptimization:
    """OpenSim's ``StaticOptimization`` (module docstring) of ``motion_file`` (a ``.mot`` of
    coordinates) with ``model_file`` over [t0, t1].

    Parameters
    ----------
    coordinates : sequence of str
        The coordinates that get a reserve actuator, in the order of ``reserve``.
    strength : (n,)
        Each reserve's optimal force (its generalized force is strength × control).
    muscle_names : sequence of str
        The muscles whose activations and forces are returned, in that order.
    out_dir : path
        Where the model, the setup and OpenSim's results are written.
    criterion : float
        The optimizer's convergence criterion (OpenSim's default 1e-4).
    max_iterations : int, optional
        Default 2000 under a criterion tighter than 1e-4, OpenSim's 100 otherwise.
    states : bool
        Also report the states OpenSim solved at (a ``StatesReporter``).

    Raises
    ------
    MuscleError
        ``strength`` not one per coordinate, a time range that is empty, a run that fails, or
        a name not in OpenSim's results.
    """
    strength = np.asarray(strength, dtype=float)
    coordinates = list(coordinates)
    if strength.shape != (len(coordinates),) or not np.all(strength > 0):
        raise MuscleError(
            f"strength: one positive optimal force per coordinate ({len(coordinates)}), "
            f"got shape {strength.shape}"
        )
    if not t1 > t0:
        raise MuscleError(f"the time range [{t0}, {t1}] is empty")
    if max_iterations is None:
        max_iterations = 2000 if criterion < 1e-4 else 100
    osim = _opensim()
    out = Path(out_dir)
    model = osim.Model(str(model_file))
    for n, f in zip(coordinates, strength):
        ca = osim.CoordinateActuator(n)
        ca.setName(f"{n}_reserve")
        ca.setOptimalForce(float(f))
        ca.setMinControl(-CONTROL_BOUND)
        ca.setMaxControl(CONTROL_BOUND)
        model.addForce(ca)
    model.finalizeConnections()
    model.printToXML(str(out / "model.osim"))
    tool = osim.AnalyzeTool()
    tool.setName("so")
    tool.setModelFilename(str(out / "model.osim"))
    tool.setCoordinatesFileName(str(motion_file))
    tool.setLowpassCutoffFrequency(-1)
    tool.setInitialTime(t0)
    tool.setFinalTime(t1)
    tool.setResultsDir(str(out))
    so = osim.StaticOptimization()
    so.setStartTime(t0)
    so.setEndTime(t1)
    so.setUseModelForceSet(True)
    so.setActivationExponent(2)
    so.setUseMusclePhysiology(True)
    so.setConvergenceCriterion(float(criterion))
    so.setMaxIterations(int(max_iterations))
    tool.getAnalysisSet().cloneAndAppend(so)
    if states:
        reporter = osim.StatesReporter()
        reporter.setStartTime(t0)
        reporter.setEndTime(t1)
        tool.getAnalysisSet().cloneAndAppend(reporter)
    tool.printToXML(str(out / "setup.xml"))
    tool = osim.AnalyzeTool(str(out / "setup.xml"))
    tic = time.perf_counter()
    ok = tool.run()
    seconds = time.perf_counter() - tic
    if not ok:
        raise MuscleError(f"OpenSim's AnalyzeTool failed on {motion_file} (setup {out}/setup.xml)")
    t, la, A = columns(osim, osim.Storage(str(out / "so_StaticOptimization_activation.sto")))
    _, lf, F = columns(osim, osim.Storage(str(out / "so_StaticOptimization_force.sto")))
    res = OpenSimStaticOptimization(
        time=t,
        activation=pick(la, A, muscle_names),
        force=pick(lf, F, muscle_names),
        reserve=pick(lf, F, [f"{n}_reserve" for n in coordinates]),
        seconds=seconds,
    )
    if states:
        _, ls, S = columns(osim, osim.Storage(str(out / "so_StatesReporter_states.sto")))
        res.states_q = pick(ls, S, coordinates, "/value")
        res.states_u = pick(ls, S, coordinates, "/speed")
    return res


def opensim_kinematics(model_file, motion_file, coordinates, times):
    """q, q̇ and q̈ of ``coordinates`` (rad, m) at the rows of ``motion_file`` nearest to
    ``times``, as OpenSim's AnalyzeTool and StaticOptimization form them (module docstring:
    degree-5 GCV splines of q, then of q̇).  ``times`` as OpenSim's results print them (8
    decimals): a time further than :data:`TIME_TOL` from every row of the file is a
    :class:`~anthroarm.errors.MuscleError`."""
    osim = _opensim()
    model = osim.Model(str(model_file))
    model.initSystem()
    store = osim.Storage(str(motion_file))
    if store.isInDegrees():
        model.getSimbodyEngine().convertDegreesToRadians(store)
    d1 = osim.GCVSplineSet(5, store).constructStorage(1)
    d2 = osim.GCVSplineSet(5, d1).constructStorage(1)
    t_all, lq, q_all = columns(osim, store)
    times = np.atleast_1d(np.asarray(times, dtype=float))
    rows = np.array([int(np.argmin(np.abs(t_all - t))) for t in times], dtype=int)
    off = np.abs(t_all[rows] - times) if len(times) else np.zeros(0)
    if np.any(off > TIME_TOL):
        raise MuscleError(f"times not rows of {motion_file}: {times[off > TIME_TOL].tolist()}")
    Q = pick(lq, q_all, coordinates)[rows]
    QD = pick(*columns(osim, d1)[1:], coordinates)[rows]
    QDD = pick(*columns(osim, d2)[1:], coordinates)[rows]
    return Q, QD, QDD


__all__ = [
    "CONTROL_BOUND",
    "TIME_TOL",
    "OpenSimStaticOptimization",
    "columns",
    "opensim_kinematics",
    "opensim_static_optimization",
    "pick",
]


def stationarity(x, C, M: int, lower, tol: float = 1e-6) -> float:
    """KKT stationarity of x for min |x|² s.t. C x = d, x[:M] ≥ ``lower`` (the problem
    :func:`opensim_static_optimization` poses): the largest |2x + Cᵀλ| over the variables off
    their bounds (more than ``tol`` above ``lower``), λ by least squares — ~0 where x is an
    optimum, which tells the frames where OpenSim's answer is one."""
    x = np.asarray(x, dtype=float)
    free = np.ones(len(x), dtype=bool)
    free[:M] = x[:M] > np.asarray(lower, dtype=float) + tol
    lam = np.linalg.lstsq(C[:, free].T, -2.0 * x[free], rcond=None)[0]
    return float(np.abs(2.0 * x[free] + C[:, free].T @ lam).max())
