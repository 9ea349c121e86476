"""Marker-based inverse kinematics, frame by frame (OpenSim's IK tool, on anthroarm's QP layer).

For every frame n the joint angles minimise the weighted sum of squared marker errors::

    min_q  Σ_k w_k v_nk ‖p_k(q) − m_nk‖²    subject to  q_min ≤ q ≤ q_max,

with v_nk = 0 where marker k is missing in frame n (a gap costs nothing) and w_k the marker
set's weights (Delp et al. 2007, "OpenSim: open-source software to create and analyze dynamic
simulations of movement", IEEE TBME 54(11), 1940–1950, the IK tool's objective; Lu & O'Connor
1999, J. Biomech. 32(2), 129–134, global optimisation with joint constraints).

Method: Gauss–Newton with box limits through anthroarm's QP layer.  Each iteration is one
:func:`anthroarm.ik.qp.step` (dt = 1) with a :class:`~anthroarm.ik.qp.tasks.marker.MarkerTask`
(all markers, in one pass over the bodies that carry them), a faint
:class:`~anthroarm.ik.qp.PostureTask` toward the previous frame's solution (cost
``regularization``, 1e-4 by default: a joint no visible marker determines keeps its last value
instead of drifting) and a :class:`~anthroarm.ik.qp.ConfigurationLimit` of gain 1 (the step is
the Gauss–Newton step projected into the limits by the QP; each iterate is inside the limits).
The first frame starts from ``q0`` (default: the comfortable posture) and other seeds (see
below); every later frame is warm-started from the previous one, so it usually converges in
2–4 iterations.  The iteration stops when the largest joint change is below ``tol`` (rad).

Per frame the result holds q, the RMS and largest marker error of the visible markers (m), the
number of visible markers, the iterations and a status:

* ``"ok"``;
* ``"too_few_markers"``: the visible markers leave some joints undetermined (none of them is
  downstream of a joint, or their Jacobian's rank is below nv at the solution); those joints
  keep the previous frame's values (through the regulariser) and the frame is still solved;
* ``"not_converged"``: ``max_iter`` iterations without the step falling below ``tol``; q is the
  last iterate (inside the limits);
* ``"skipped"``: no visible marker (a NaN frame): q repeats the previous frame (the seed for the
  first), and the frame's errors are NaN (there is nothing to measure them on);
* ``"large_error"``: the RMS marker error is above ``max_rms`` (2 cm by default): a wrong local
  minimum or a mislabelled marker; the next frame starts afresh.

A frame without a previous solution (the first, and the one after a skipped or large-error
frame) is started from ``q0`` and from ``seeds`` uniform postures inside the limits (a few
Gauss–Newton iterations each, the best continued): marker IK is a non-convex problem and a
single start from the comfortable posture can end in a wrong local minimum.

The marker set is checked once before solving: a joint that no marker is downstream of, or a
marker Jacobian whose rank is below nv at the comfortable posture, raises
:class:`~anthroarm.errors.UnconstrainedJointError` naming the joints.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field

import numpy as np

from ..errors import MarkerSetError, MotionDataError, ParameterError, UnconstrainedJointError
from ..ik import qp
from ..ik.qp.tasks.marker import MarkerTask
from .markers import BoundMarkers, MarkerSet, default_marker_set
from .trial import MarkerTrajectories, check_coordinates

STATUSES = ("ok", "too_few_markers", "not_converged", "skipped", "large_error")


@dataclass
class MarkerIKResult:
    """Per-frame output of :func:`marker_ik`.

    Attributes
    ----------
    q : (N, nq)
        Joint configuration per frame (rad; Pinocchio's layout), always finite and within the
        limits.
    time : (N,)
        s.
    rms, max_error : (N,)
        RMS and largest error of the visible markers, m (NaN for a skipped frame).
    n_markers : (N,) int
        Visible markers used.
    iterations : (N,) int
    status : (N,) str
        One of :data:`STATUSES`.
    marker_error : (N, M)
        Distance of each marker from its model position, m (NaN where missing).
    marker_names, joint_names : tuple of str
    missing_markers : tuple of str
        Markers of the set not found in the trial (zero weight throughout).
    seconds : float
        Process time of the solve (s).
    """

    q: np.ndarray
    time: np.ndarray
    rms: np.ndarray
    max_error: np.ndarray
    n_markers: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    marker_error: np.ndarray
    marker_names: tuple
    joint_names: tuple
    missing_markers: tuple = ()
    seconds: float = 0.0
    info: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return self.q.shape[0]

    @property
    def ok(self) -> np.ndarray:
        """(N,) bool: status ``"ok"``."""
        return self.status == "ok"

    def counts(self) -> dict:
        """Frames per status."""
        return {s: int(np.sum(self.status == s)) for s in STATUSES}

    def summary(self) -> dict:
        """Counts, median/max RMS error (m) of the solved frames (None when every frame was
        skipped: the dict is printed as strict JSON), ms per frame."""
        solved = self.status != "skipped"
        r = self.rms[solved]
        return {
            "frames": len(self),
            **self.counts(),
            "rms_median_m": float(np.median(r)) if r.size else None,
            "rms_max_m": float(np.max(r)) if r.size else None,
            "max_error_m": float(np.max(self.max_error[solved])) if r.size else None,
            "ms_per_frame": 1e3 * self.seconds / max(len(self), 1),
            "missing_markers": list(self.missing_markers),
        }


def _split_label(label: str) -> tuple[str | None, str]:
    """``"Subject1:EL"`` -> ``("Subject1", "EL")``; a label without a prefix -> ``(None,
    label)``."""
    pre, sep, base = str(label).rpartition(":")
    return (pre.strip() or None, base.strip()) if sep else (None, str(label).strip())


def match_markers(
    trial_names, marker_set: MarkerSet, rename: dict | None = None, *, subject: str | None = None
) -> np.ndarray:
    """Column of each marker of ``marker_set`` in a trial with labels ``trial_names`` (−1 if
    absent).  A label matches a marker by exact name, after ``rename`` (trial label -> marker
    name), or after stripping a subject prefix (``"Subject1:EL"`` -> ``"EL"``) and case.

    A trial may hold several subjects (labels ``"Subj1:RSHO"``, ``"Subj2:RSHO"``, as Vicon
    Nexus writes them).  When the labels of more than one subject match markers of the set,
    ``subject`` must say whose markers to use (labels without a prefix are used too);
    otherwise a :class:`~anthroarm.errors.MarkerSetError` lists the subjects.  A ``subject``
    that is not in the trial, or a ``rename`` target that is not a marker of the set, is a
    :class:`~anthroarm.errors.MarkerSetError` too (a typo would otherwise leave markers silently
    missing)."""
    rename = dict(rename or {})
    unknown = sorted(str(v) for v in rename.values() if v not in marker_set.names)
    if unknown:
        raise MarkerSetError(
            f"rename maps trial labels to {unknown}, which are not markers of {marker_set.name!r} "
            f"({', '.join(marker_set.names)})"
        )
    labels = [str(s) for s in trial_names]
    split = [_split_label(lab) for lab in labels]
    subjects = sorted({pre for pre, _ in split if pre is not None})
    if subject is not None:
        if not isinstance(subject, str) or subject.strip() not in subjects:
            raise MarkerSetError(
                f"subject {subject!r} is not in the trial; its subjects: "
                f"{', '.join(subjects) if subjects else 'none (no label has a SUBJECT: prefix)'}"
            )
        subject = subject.strip()

    def columns(keep) -> dict:
        cols = {}
        for i, (lab, (pre, base)) in enumerate(zip(labels, split)):
            if keep(pre):
                for key in (rename.get(lab, lab), base):
                    cols.setdefault(key, i)
                    cols.setdefault(key.upper(), i)
        return cols

    if subject is None and len(subjects) > 1:
        found = {}
        for sub in subjects:
            cols = columns(lambda pre, sub=sub: pre == sub)
            n = sum(1 for m in marker_set if m.name in cols or m.name.upper() in cols)
            if n:
                found[sub] = n
        if len(found) > 1:
            listed = ", ".join(f"{k} ({v} markers)" for k, v in found.items())
            first = next(iter(found))
            raise MarkerSetError(
                f"the trial holds markers of {len(found)} subjects of set {marker_set.name!r}: "
                f"{listed}; choose one: subject={first!r} (anthroarm ik-markers --subject {first})"
            )
    cols = columns(lambda pre: subject is None or pre in (None, subject))
    out = np.full(len(marker_set), -1, dtype=int)
    for k, m in enumerate(marker_set):
        out[k] = cols.get(m.name, cols.get(m.name.upper(), -1))
    return out


class MarkerIK:
    """Marker IK solver for one robot and marker set (reusable across trials).

    Parameters
    ----------
    robot : anthroarm.Robot
    marker_set : MarkerSet, optional
        Default: :func:`~anthroarm.motion.markers.default_marker_set` (a person's arm model).
    solver : str
        QP backend of :func:`anthroarm.ik.qp.step` (``"daqp"`` default: the fastest dense one).
    max_iter, first_iter : int
        Gauss–Newton iterations per frame (``first_iter`` for the first frame and after a
        skipped one, which may start far from the answer).
    seeds : int
        Extra starting postures for such a fresh frame (deterministic uniform samples inside
        the limits, :meth:`~anthroarm.chain.Chain.random_q`), each given ``seed_iter``
        iterations; the one with the smallest marker error is iterated to convergence.
    max_rms : float
        A frame whose RMS marker error exceeds ``max_rms`` (m) gets status ``"large_error"`` and
        the next frame is started afresh (a wrong local minimum, a mislabelled marker).
    tol : float
        Stop when the largest joint change of an iteration is below ``tol`` (rad).
    regularization : float
        Cost of the posture task toward the previous frame (per rad; markers cost 1 per m).
    check : bool
        Check that the set constrains every joint (:meth:`BoundMarkers.check_constrains`).
    coordinate_tasks : dict, optional
        Joint name -> (weight w_j, value): the term w_j (q_j − value)² added to the objective,
        OpenSim's ``IKCoordinateTask`` (:func:`~anthroarm.motion.ik_setup.coordinate_targets`
        makes it from a setup file); rad or m.
    limits : bool
        Keep every iterate inside the joint limits (default).  False solves without them, as
        OpenSim's IK does for coordinates that are not clamped.
    """

    def __init__(
        self,
        robot,
        marker_set: MarkerSet | None = None,
        *,
        solver: str = "daqp",
        max_iter: int = 20,
        first_iter: int = 200,
        tol: float = 1e-6,
        regularization: float = 1e-4,
        check: bool = True,
        seeds: int = 24,
        seed_iter: int = 25,
        max_rms: float = 0.02,
        coordinate_tasks: dict | None = None,
        limits: bool = True,
    ):
        if getattr(robot, "coupling", None) is not None:
            raise ParameterError(
                f"{robot.name} has coupled coordinates (an OpenSim model with splines or "
                "couplers): its marker IK is anthroarm.motion.CoupledMarkerIK (or "
                "osim_marker_ik with an OpenSim IK setup), which works in its coordinates"
            )
        self.robot = robot
        self.marker_set = default_marker_set(robot) if marker_set is None else marker_set
        if not isinstance(self.marker_set, MarkerSet):
            raise MarkerSetError(
                f"marker_set must be a MarkerSet, got {type(self.marker_set).__name__}"
            )
        self.bound = BoundMarkers(robot, self.marker_set)
        if check:
            self.bound.check_constrains()
        for nm, v, least in (
            ("max_iter", max_iter, 1),
            ("first_iter", first_iter, 1),
            ("seed_iter", seed_iter, 1),
            ("seeds", seeds, 0),
        ):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ParameterError(f"{nm} must be a whole number >= {least}, got {v!r}")
        for nm, v in (("tol", tol), ("regularization", regularization), ("max_rms", max_rms)):
            if not (isinstance(v, (int, float, np.floating)) and np.isfinite(v) and v > 0):
                raise ParameterError(f"{nm} must be a finite number > 0, got {v!r}")
        self.solver, self.max_iter, self.first_iter = solver, int(max_iter), int(first_iter)
        self.tol, self.regularization = float(tol), float(regularization)
        self.seed_iter, self.max_rms = int(seed_iter), float(max_rms)
        self.seed_q = (
            robot.random_q(int(seeds), rng=0, margin=0.05) if seeds else np.zeros((0, robot.nq))
        )
        qp.make_backend(solver, robot.nv, 0)  # SolverNotAvailableError now, not mid-trial
        self.limits = bool(limits)
        self.coordinate_task = self._coordinate_task(coordinate_tasks or {})
        self._rank_cache: dict = {}

    def _coordinate_task(self, tasks: dict):
        """A posture task of cost √w_j on the joints of ``tasks`` (0 elsewhere), toward their
        values: Σ w_j (q_j − value_j)² in the QP's objective (None when there are none)."""
        if not tasks:
            return None
        robot = self.robot
        cost = np.zeros(robot.nv)
        target = qp.comfortable_posture(robot)
        for name, spec in tasks.items():
            try:
                j = robot.chain.joint(name)
                w, value = (float(x) for x in spec)
            except (KeyError, TypeError, ValueError) as exc:
                raise ParameterError(
                    f"coordinate_tasks[{name!r}] must be (weight, value) of a joint of "
                    f"{robot.name} ({exc})"
                ) from None
            if j.is_mimic or j.nq != 1 or not (np.isfinite(w) and w >= 0 and np.isfinite(value)):
                raise ParameterError(
                    f"coordinate_tasks[{name!r}]: a one-coordinate joint, a finite weight >= 0 "
                    f"and a finite value, got {spec!r}"
                )
            cost[j.idx_v] = np.sqrt(w)
            target[j.idx_q] = value
        return qp.PostureTask(robot, cost=cost, target=target)

    # ------------------------------------------------------------------ one frame
    def _iterate(self, conf, tasks, limits, it_max: int) -> tuple[bool, int]:
        """Gauss–Newton steps (QP steps with dt = 1) until the largest joint change is below
        ``tol``: (converged, iterations)."""
        it = 0
        for it in range(1, it_max + 1):
            v = qp.step(conf, None, tasks, 1.0, limits=limits, solver=self.solver)
            conf.integrate_inplace(v, 1.0)
            if np.max(np.abs(v)) < self.tol:
                return True, it
        return False, it

    def _best_start(self, conf, task, reg, tasks, limits, vis, q_first) -> int:
        """Multi-start for a frame without a previous solution: ``q_first`` and the seed
        postures, ``seed_iter`` iterations each; leaves ``conf`` at the best.  Returns the
        iterations spent."""
        best_q, best_cost, spent = None, np.inf, 0
        w = self.marker_set.weights
        for q in (q_first, *self.seed_q):
            conf.update(q)
            reg.target = conf.q.copy()
            _, it = self._iterate(conf, tasks, limits, self.seed_iter)
            spent += it
            d = np.linalg.norm(task.positions(conf) - task.target, axis=1)
            cost = float(np.sum(w[vis] * d[vis] ** 2))
            if cost < best_cost:
                best_q, best_cost = conf.q.copy(), cost
            if np.sqrt(np.mean(d[vis] ** 2)) < 0.1 * self.max_rms:
                break
        conf.update(best_q)
        return spent

    def _determined(self, task: MarkerTask, visible: np.ndarray, conf) -> bool:
        """The visible markers determine every joint at ``conf``: each joint has one downstream
        (cached per visibility pattern) and J (weighted) has full column rank."""
        key = visible.tobytes()
        s = self._rank_cache.get(key)
        if s is None:
            s = self._rank_cache[key] = not self.bound.unconstrained_joints(visible)
        if not s:
            return False
        WJ = task.cost[:, None] * task.compute_jacobian(conf)
        ev = np.linalg.eigvalsh(WJ.T @ WJ)
        return bool(ev[0] > 1e-10 * max(ev[-1], 1e-300))

    def solve(
        self,
        trial,
        *,
        q0=None,
        rename: dict | None = None,
        subject: str | None = None,
        progress=None,
        rate: float = 100.0,
    ) -> MarkerIKResult:
        """Solve every frame of ``trial`` (:class:`~anthroarm.motion.trial.MarkerTrajectories`,
        or an ``(N, M, 3)`` array in the marker set's order, m, sampled at ``rate`` Hz).  ``q0``
        seeds the first frame (default: the comfortable posture).  ``progress(n_done, n_total)`` is
        called every 50 frames (the CLI's progress bar).  ``rename`` and ``subject`` (whose markers
        to use in a trial of several subjects) are those of :func:`match_markers`.

        Raises :class:`~anthroarm.errors.MarkerSetError` when no marker of the set is in the
        trial and :class:`~anthroarm.errors.UnconstrainedJointError` when the markers present
        leave a joint without a marker below it.
        """
        robot = self.robot
        names = self.marker_set.names
        if isinstance(trial, MarkerTrajectories):
            cols = match_markers(trial.names, self.marker_set, rename, subject=subject)
            if not (cols >= 0).any():
                raise MarkerSetError(
                    f"{trial.source}: none of the markers {list(names)} of set "
                    f"{self.marker_set.name!r} is in the trial (labels: {', '.join(trial.names)}); "
                    "pass rename={trial label: marker name}"
                )
            N = trial.n_frames
            P = np.full((N, len(names), 3), np.nan)
            P[:, cols >= 0] = trial.positions[:, cols[cols >= 0]]
            t = trial.time
        else:
            try:
                P = np.array(trial, dtype=float)
            except (TypeError, ValueError):
                raise MotionDataError("marker positions must be numbers (m)") from None
            if P.ndim != 3 or P.shape[1:] != (len(names), 3):
                raise MotionDataError(
                    f"marker positions must have shape (frames, {len(names)}, 3) in the order "
                    f"{list(names)}, got {P.shape}"
                )
            check_coordinates(P, names)
            P[~np.isfinite(P).all(axis=2)] = np.nan
            N = P.shape[0]
            cols = np.where(np.isfinite(P).all(axis=2).any(axis=0), np.arange(len(names)), -1)
            if not (isinstance(rate, (int, float, np.floating)) and np.isfinite(rate) and rate > 0):
                raise MotionDataError(f"rate must be a positive number (Hz), got {rate!r}")
            t = np.arange(N) / float(rate)
        missing = tuple(n for n, c in zip(names, cols) if c < 0)
        if missing:
            free = self.bound.unconstrained_joints(cols >= 0)
            if free:
                raise UnconstrainedJointError(
                    f"markers {list(missing)} are not in the trial; without them joints {free} "
                    "have no marker below them (rename the trial's labels with rename={label: "
                    "marker} or use another set)",
                    joints=free,
                )

        q_seed = qp.comfortable_posture(robot) if q0 is None else robot.check_q(q0, name="q0")
        q_seed = (
            np.clip(q_seed, robot.lower, robot.upper) if not robot.chain.has_continuous else q_seed
        )
        conf = qp.IKConfiguration(robot, q_seed)
        task = MarkerTask(robot, self.bound.joint, self.bound.local, self.marker_set.weights)
        reg = qp.PostureTask(robot, cost=self.regularization, target=q_seed)
        limits = [qp.ConfigurationLimit(robot, gain=1.0)] if self.limits else []
        tasks = [task, reg] + ([self.coordinate_task] if self.coordinate_task is not None else [])
        M = len(names)
        Q = np.empty((N, robot.nq))
        rms = np.full(N, np.nan)
        mx = np.full(N, np.nan)
        nvis = np.zeros(N, dtype=int)
        iters = np.zeros(N, dtype=int)
        status = np.empty(N, dtype=object)
        merr = np.full((N, M), np.nan)
        fresh = True
        t0 = _time.process_time()
        for n in range(N):
            vis = np.isfinite(P[n]).all(axis=1)
            nvis[n] = int(vis.sum())
            if not vis.any():
                Q[n] = conf.q
                status[n] = "skipped"
                fresh = True
                continue
            task.set_target(P[n], vis)
            extra = 0
            if fresh:
                extra = self._best_start(
                    conf, task, reg, tasks, limits, vis, q_seed if n == 0 else conf.q
                )
            reg.target = conf.q.copy()
            it_max = self.first_iter if fresh else self.max_iter
            converged, it = self._iterate(conf, tasks, limits, it_max)
            iters[n] = it + extra
            d = np.linalg.norm(task.positions(conf) - task.target, axis=1)
            merr[n, vis] = d[vis]
            rms[n] = float(np.sqrt(np.mean(d[vis] ** 2)))
            mx[n] = float(d[vis].max())
            Q[n] = conf.q
            fresh = False
            if not self._determined(task, vis, conf):
                status[n] = "too_few_markers"
            elif rms[n] > self.max_rms:
                status[n] = "large_error"
                fresh = True
            elif not converged:
                status[n] = "not_converged"
            else:
                status[n] = "ok"
            if progress is not None and (n + 1) % 50 == 0:
                progress(n + 1, N)
        seconds = _time.process_time() - t0
        if progress is not None:
            progress(N, N)
        return MarkerIKResult(
            q=Q,
            time=t,
            rms=rms,
            max_error=mx,
            n_markers=nvis,
            iterations=iters,
            status=status.astype(str),
            marker_error=merr,
            marker_names=names,
            joint_names=tuple(robot.chain.q_names),
            missing_markers=missing,
            seconds=seconds,
            info={"solver": self.solver, "marker_set": self.marker_set.name},
        )


def marker_ik(
    robot,
    trial,
    marker_set: MarkerSet | None = None,
    *,
    q0=None,
    rename: dict | None = None,
    subject: str | None = None,
    progress=None,
    rate: float = 100.0,
    **options,
) -> MarkerIKResult:
    """Marker IK of a whole trial: ``MarkerIK(robot, marker_set, **options).solve(trial, ...)``
    (see :class:`MarkerIK` for the options and the module docstring for the method)."""
    return MarkerIK(robot, marker_set, **options).solve(
        trial, q0=q0, rename=rename, subject=subject, progress=progress, rate=rate
    )
