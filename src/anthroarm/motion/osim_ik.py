"""Marker IK on a model imported from OpenSim, in its independent coordinates (OpenSim's IK).

For every frame n the coordinates minimise OpenSim's inverse-kinematics objective (Delp et al.
2007, IEEE TBME 54(11), 1940–1950; opensim-core ``InverseKinematicsSolver``)::

    min_q  Σ_k w_k v_nk ‖p_k(φ(q)) − m_nk‖²  +  Σ_j w_j (q_j − q_j⁰)²

with the marker weights w_k and the coordinate tasks (w_j, q_j⁰) of an IK setup
(:mod:`~anthroarm.motion.ik_setup`), v_nk = 0 for a marker missing in frame n, and φ the
model's coupling map (``robot.coupling`` of ``aa.load("model.osim")``: the Pinocchio
configuration, with knee translations that are splines of the knee angle, as a function of the
independent coordinates q; the identity for a model without couplings).

Method: Levenberg–Marquardt (Gauss–Newton with a damping that grows when a step does not lower
the objective), in q.  One iteration is one ``pinocchio.computeJointJacobians`` at φ(q), every
marker's position and world Jacobian from it (J_k = v_O + ω × p_k over the joints that move
the marker's body) with the chain rule J_k G(q), G = dφ/dq, accumulated into the nq × nq normal
equations by one compiled kernel (:mod:`~anthroarm.motion.osim_ik_kernels`; :meth:`evaluate`
is the numpy reference it is tested against), and their solve.  The first frame starts from
``q0`` (default: the model's default coordinates, where OpenSim's ``assemble`` starts); every
later frame from the previous two, extrapolated at constant velocity (OpenSim's ``track``
starts from the previous frame).  Gauss–Newton converges linearly on a problem whose residuals
do not vanish (markers never fit exactly); it stops when the distance to the optimum, estimated
from the contraction ρ of the last two steps as step · ρ / (1 − ρ), is below ``tol``.  Coordinate ranges bound a coordinate only where OpenSim would: ``clamped`` ones (all
of them with ``limits="all"``, none with ``limits="none"``); a bounded step is projected into
the range.

The per-frame statuses are those of :mod:`~anthroarm.motion.marker_ik`
(:data:`~anthroarm.motion.marker_ik.STATUSES`), and the result is a
:class:`~anthroarm.motion.marker_ik.MarkerIKResult` in the robot's coordinates
(``robot.joint_names``).  :func:`osim_marker_ik` runs a whole OpenSim IK setup: its markers and
weights, its coordinate tasks and its time range.
"""

from __future__ import annotations

import time as _time

import numpy as np
import pinocchio as pin

from ..errors import MarkerSetError, MotionDataError, ParameterError, UnconstrainedJointError
from ..ik.qp.tasks.marker import moved_by
from ..joint_kinds import PRISMATIC
from ..osim.coupling import FastCoupling
from .ik_setup import IKSetup, osim_marker_set
from .marker_ik import MarkerIKResult, match_markers
from .markers import MarkerSet
from .osim_ik_kernels import marker_normal_equations
from .trial import MarkerTrajectories

LIMITS = ("clamped", "all", "none")


def coordinate_index(robot, name: str) -> int:
    """Index in q of the coordinate (joint) ``name`` of ``robot``: its place in
    ``robot.joint_names`` for a model with a coupling map, its ``idx_q`` otherwise (a joint of
    one coordinate).  :class:`~anthroarm.errors.ParameterError` for another name."""
    if getattr(robot, "coupling", None) is not None:
        names = list(robot.joint_names)
        if name in names:
            return names.index(name)
    else:
        for j in robot.chain.joints:
            if j.name == name and not j.is_mimic and j.nq == 1:
                return j.idx_q
    raise ParameterError(
        f"{name!r} is not a coordinate of {robot.name}; coordinates: {', '.join(robot.joint_names)}"
    )


def rotational_coordinates(robot) -> list[str]:
    """The coordinates of ``robot`` that are angles (rad): for a model read from OpenSim, those
    that drive a rotation axis of their joint (``robot.osim``); otherwise the non-prismatic
    joints of ``robot.chain``.  The rest are lengths (m)."""
    osim = getattr(robot, "osim", None)
    if osim is not None:
        rot = {c for j in osim.joints for a in j.axes if a.name.startswith("rot") for c in a.coords}
        return [n for n in robot.joint_names if n in rot]
    return [j.name for j in robot.chain.joints if not j.is_mimic and j.kind != PRISMATIC]


class CoupledMarkerIK:
    """Marker IK in the independent coordinates of a (possibly coupled) model.

    Parameters
    ----------
    robot : anthroarm.Robot
        Typically ``aa.load("model.osim")``; any Robot whose q is Pinocchio's (no coupling).
    marker_set : MarkerSet
        Markers on frames of ``robot`` (:func:`~anthroarm.motion.ik_setup.osim_marker_set`).
    coordinate_tasks : dict, optional
        Coordinate name -> (weight w_j, value q_j⁰), rad or m.
    limits : str
        ``"clamped"`` (default: the coordinates OpenSim clamps, from ``robot.osim``; every
        coordinate for a robot not read from OpenSim), ``"all"`` or ``"none"``.
    max_iter, first_iter : int
        Iterations per frame (``first_iter`` for a frame without a previous solution).
    tol : float
        Stop when the estimated distance to the optimum (the last step times ρ/(1 − ρ), ρ the
        contraction of the last two steps) is below ``tol`` (rad or m; 1e-4 rad = 0.006°: on
        the shipped walk the result lies within 0.007° of the fully converged optimum, where
        OpenSim 4.6's IK at its accuracy 1e-5 lies within 0.12° of it).
    max_rms : float
        A frame whose RMS marker error exceeds it (m) gets status ``"large_error"``.
    """

    def __init__(
        self,
        robot,
        marker_set: MarkerSet,
        *,
        coordinate_tasks: dict | None = None,
        limits: str = "clamped",
        max_iter: int = 30,
        first_iter: int = 300,
        tol: float = 1e-4,
        max_rms: float = 0.05,
    ):
        if not isinstance(marker_set, MarkerSet):
            raise MarkerSetError(f"marker_set must be a MarkerSet, got {type(marker_set).__name__}")
        if limits not in LIMITS:
            raise ParameterError(f"limits must be one of {LIMITS}, got {limits!r}")
        for nm, v in (("max_iter", max_iter), ("first_iter", first_iter)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ParameterError(f"{nm} must be a whole number >= 1, got {v!r}")
        for nm, v in (("tol", tol), ("max_rms", max_rms)):
            if not (isinstance(v, (int, float, np.floating)) and np.isfinite(v) and v > 0):
                raise ParameterError(f"{nm} must be a finite number > 0, got {v!r}")
        self.robot, self.marker_set = robot, marker_set
        coupling = getattr(robot, "coupling", None)
        self.coupling = None if coupling is None else FastCoupling(coupling)
        self.max_iter, self.first_iter = int(max_iter), int(first_iter)
        self.tol, self.max_rms = float(tol), float(max_rms)
        chain = robot.chain
        self.model = robot.model
        self.data = pin.Data(self.model)
        self.nq = robot.nq
        M = len(marker_set)
        self.joint_id = np.empty(M, dtype=int)  # Pinocchio joint id of each marker's body
        self.local = np.empty((M, 3))
        for k, m in enumerate(marker_set):
            try:
                f = chain.frame(m.body)
            except KeyError:
                raise MarkerSetError(
                    f"marker {m.name!r}: {m.body!r} is not a frame of {robot.name}"
                ) from None
            self.joint_id[k] = f.joint + 1
            self.local[k] = f.rotation @ np.asarray(m.position, float) + f.translation
        self.mask = moved_by(chain, self.joint_id - 1).astype(float)  # (M, nv_pin)
        self.bodies = [int(b) for b in np.unique(self.joint_id)]
        self.body_of = np.searchsorted(self.bodies, self.joint_id)
        self.body_mask = moved_by(chain, np.array(self.bodies) - 1).astype(float)  # (B, nv_pin)
        self._skew = np.zeros((M, 3, 3))
        self._p = np.empty((M, 3))
        self._eye_G = np.eye(self.model.nv, self.nq)
        self.weights = marker_set.weights
        # coordinate tasks: rows sqrt(w_j) (q_j - v_j)
        tasks = coordinate_tasks or {}
        self.task_idx = np.array([coordinate_index(robot, n) for n in tasks], dtype=int)
        specs = []
        for name, spec in tasks.items():
            try:
                w, v = (float(x) for x in spec)
            except (TypeError, ValueError):
                raise ParameterError(
                    f"coordinate_tasks[{name!r}] must be (weight, value), got {spec!r}"
                ) from None
            if not (np.isfinite(w) and w >= 0 and np.isfinite(v)):
                raise ParameterError(f"coordinate_tasks[{name!r}]: finite weight >= 0 and value")
            specs.append((w, v))
        self.task_sw = np.sqrt(np.array([s[0] for s in specs])) if specs else np.zeros(0)
        self.task_value = np.array([s[1] for s in specs]) if specs else np.zeros(0)
        self.task_J = np.zeros((self.task_idx.size, self.nq))
        self.task_J[np.arange(self.task_idx.size), self.task_idx] = self.task_sw
        # bounds
        lo, hi = np.array(robot.lower, float), np.array(robot.upper, float)
        osim = getattr(robot, "osim_coordinates", None)
        if limits == "none":
            bounded = np.zeros(self.nq, bool)
        elif limits == "all" or osim is None:
            bounded = np.ones(self.nq, bool)
        else:
            bounded = np.array([bool(osim[n].clamped) for n in robot.joint_names])
        self.lo = np.where(bounded, lo, -np.inf)
        self.hi = np.where(bounded, hi, np.inf)
        self.bounded = bool(bounded.any())
        # which coordinates move each marker (for the unconstrained-joint check) and each body
        G = self._G(self._start())
        G = self._eye_G if G is None else G
        self.moves = np.abs(self.mask @ np.abs(G)) > 0
        nz = np.abs(G) > 0  # (nv_pin, nq): the Pinocchio velocities each coordinate drives
        cover = self.body_mask @ nz  # (B, nq): how many of them move body b
        whole = (cover == 0) | (cover == nz.sum(axis=0)[None, :])
        self.body_moves = (cover > 0).astype(float) if whole.all() else None
        marker_normal_equations(  # compile (or load from the disk cache) before any solve
            np.zeros((len(self.bodies), 4, 4)),
            self.body_of,
            self.local,
            np.zeros((len(self.bodies), 6, self.nq)),
            np.zeros((M, 3)),
            np.zeros(M),
            np.empty((M, 3)),
            np.empty((self.nq, self.nq)),
            np.empty(self.nq),
        )

    def _start(self) -> np.ndarray:
        r = self.robot
        return r.default_q() if hasattr(r, "default_q") else r.neutral()

    def _G(self, q):
        return None if self.coupling is None else self.coupling.jacobian(q)[1]

    # ------------------------------------------------------------------ one evaluation
    def evaluate(self, q, target, w):
        """(positions (M, 3), residual r, Jacobian J) at ``q`` for the marker ``target``
        (M, 3) with per-marker weights ``w`` (0 for a missing marker): r = √w (p − m) stacked
        with the coordinate-task rows, J = dr/dq."""
        if self.coupling is None:
            qf, G = q, None
        else:
            qf, G = self.coupling.jacobian(q)
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, qf)
        oMi = data.oMi
        T = np.array([oMi[j].homogeneous for j in self.bodies])[self.body_of]  # (M, 4, 4)
        p = np.einsum("mij,mj->mi", T[:, :3, :3], self.local) + T[:, :3, 3]
        # the world Jacobian (v_O; ω) of each body, over the joints that move it, in q
        JB = data.J[None] * self.body_mask[:, None, :]  # (B, 6, nv_pin)
        if G is not None:
            JB = (JB.reshape(-1, JB.shape[2]) @ G).reshape(JB.shape[0], 6, -1)
        JM = JB[self.body_of]  # (M, 6, nq)
        # a marker's velocity v_O + ω × p = v_O − [p]× ω
        S = self._skew
        S[:, 0, 1], S[:, 0, 2], S[:, 1, 2] = -p[:, 2], p[:, 1], -p[:, 0]
        S[:, 1, 0], S[:, 2, 0], S[:, 2, 1] = p[:, 2], -p[:, 1], p[:, 0]
        Jp = JM[:, :3] - S @ JM[:, 3:]
        sw = np.sqrt(w)
        Jm = (Jp * sw[:, None, None]).reshape(-1, Jp.shape[2])
        rm = ((p - target) * sw[:, None]).ravel()
        if self.task_idx.size:
            rt = self.task_sw * (q[self.task_idx] - self.task_value)
            return p, np.concatenate([rm, rt]), np.vstack([Jm, self.task_J])
        return p, rm, Jm

    def body_jacobians(self, Jw, G) -> np.ndarray:
        """(B, 6, nq) world Jacobians (v_O; ω) in q of the bodies that carry markers:
        (mask_b ⊙ J_world) G.  When every coordinate moves the Pinocchio joints it drives all
        together or not at all for each body (checked once: true of OpenSim joints, whose
        transform axes sit on one joint), that is J_world G with the columns of the coordinates
        that do not move the body zeroed, one product instead of B."""
        if self.body_moves is not None:
            return (Jw @ G)[None] * self.body_moves[:, None, :]
        JB = (Jw[None] * self.body_mask[:, None, :]).reshape(-1, Jw.shape[1]) @ G
        return JB.reshape(len(self.bodies), 6, -1)

    def normal_equations(self, q, target, w):
        """(positions (M, 3), H = JᵀJ, g = Jᵀr, cost rᵀr) at ``q``: what :meth:`evaluate`'s
        r and J give, computed by the compiled kernel
        :func:`~anthroarm.motion.osim_ik_kernels.marker_normal_equations` without forming J
        (tested equal to :meth:`evaluate`)."""
        if self.coupling is None:
            qf, G = q, self._eye_G
        else:
            qf, G = self.coupling.jacobian(q)
        data = self.data
        pin.computeJointJacobians(self.model, data, qf)
        oMi = data.oMi
        T = np.array([oMi[j].homogeneous for j in self.bodies])
        p, H, g = self._p, np.empty((self.nq, self.nq)), np.empty(self.nq)
        cost = marker_normal_equations(
            T, self.body_of, self.local, self.body_jacobians(data.J, G), target, w, p, H, g
        )
        if self.task_idx.size:
            e = q[self.task_idx] - self.task_value
            s2 = self.task_sw**2
            H[self.task_idx, self.task_idx] += s2
            g[self.task_idx] += s2 * e
            cost += float(s2 @ (e * e))
        return p.copy(), H, g, float(cost)

    def _solve_frame(self, q, target, w, it_max):
        """Levenberg–Marquardt from ``q``: (q, converged, iterations, positions, H)."""
        p, H, g, cost = self.normal_equations(q, target, w)
        lam = 1e-9
        last = 0.0
        eye = np.eye(self.nq)
        for it in range(1, it_max + 1):
            scale = max(float(np.trace(H)) / self.nq, 1e-12)
            while True:
                dq = -np.linalg.solve(H + lam * scale * eye, g)
                qn = q + dq
                if self.bounded:
                    qn = np.clip(qn, self.lo, self.hi)
                pn, Hn, gn, cn = self.normal_equations(qn, target, w)
                if cn <= cost or lam > 1e6:
                    break
                lam *= 10.0
            step = float(np.max(np.abs(qn - q)))
            q, p, H, g, cost = qn, pn, Hn, gn, cn
            lam = max(lam / 10.0, 1e-12)
            # Gauss-Newton converges linearly on a problem with residuals (markers never fit
            # exactly): with the contraction ρ of the last two steps the distance to the
            # solution is about step · ρ / (1 − ρ) (the a-posteriori bound of a contraction)
            rho = step / last if last > 0 else 1.0
            left = step * rho / (1.0 - rho) if rho < 0.5 else step
            last = step
            if left < self.tol:
                return q, True, it, p, H
        return q, False, it_max, p, H

    # ------------------------------------------------------------------ a trial
    def solve(
        self, trial, *, q0=None, rename=None, subject=None, frames=None, progress=None
    ) -> MarkerIKResult:
        """Solve every frame of ``trial`` (:class:`~anthroarm.motion.trial.MarkerTrajectories`;
        ``frames`` selects rows: a slice, indices or a boolean mask).  ``q0`` starts the first
        frame (default: the model's default coordinates).  ``rename``/``subject`` as
        :func:`~anthroarm.motion.marker_ik.match_markers`.  ``progress(n, N)`` every 25 frames.
        ``seconds`` of the result is the wall time of the frames' loop (``time.perf_counter``,
        as OpenSim's solver is timed in :mod:`~anthroarm.motion.opensim_oracle`).

        Raises :class:`~anthroarm.errors.MarkerSetError` when no marker of the set is in the
        trial, :class:`~anthroarm.errors.UnconstrainedJointError` when the markers present leave a
        coordinate without a marker it moves (and no coordinate task on it)."""
        if not isinstance(trial, MarkerTrajectories):
            raise MotionDataError(f"trial must be MarkerTrajectories, got {type(trial).__name__}")
        names = self.marker_set.names
        cols = match_markers(trial.names, self.marker_set, rename, subject=subject)
        if not (cols >= 0).any():
            raise MarkerSetError(
                f"{trial.source}: none of the markers of set {self.marker_set.name!r} "
                f"({', '.join(names[:8])} ...) is in the trial (labels: "
                f"{', '.join(trial.names[:8])} ...); pass rename={{trial label: marker name}}"
            )
        missing = tuple(n for n, c in zip(names, cols) if c < 0)
        seen = (self.moves[cols >= 0].any(axis=0)) if (cols >= 0).any() else np.zeros(self.nq, bool)
        seen[self.task_idx[self.task_sw > 0]] = True
        if not seen.all():
            free = [n for n, s in zip(self.robot.joint_names, seen) if not s]
            raise UnconstrainedJointError(
                f"markers {list(missing)} are not in the trial; without them coordinates {free} "
                "have no marker they move (rename the trial's labels with rename={label: marker})",
                joints=free,
            )
        idx = np.arange(trial.n_frames)[frames if frames is not None else slice(None)]
        t_all = trial.meta.get("time", trial.time)
        P = np.full((idx.size, len(names), 3), np.nan)
        P[:, cols >= 0] = trial.positions[idx][:, cols[cols >= 0]]
        N = idx.size
        q = self._start() if q0 is None else self.robot.check_q(q0, name="q0").astype(float)
        Q = np.empty((N, self.nq))
        rms, mx = np.full(N, np.nan), np.full(N, np.nan)
        nvis, iters = np.zeros(N, int), np.zeros(N, int)
        status = np.empty(N, dtype=object)
        merr = np.full((N, len(names)), np.nan)
        fresh, prev = True, None
        q_start = q.copy()
        t0 = _time.perf_counter()
        for n in range(N):
            vis = np.isfinite(P[n]).all(axis=1)
            nvis[n] = int(vis.sum())
            if not vis.any():
                Q[n], status[n], fresh = q, "skipped", True
                continue
            w = np.where(vis, self.weights, 0.0)
            target = np.where(vis[:, None], P[n], 0.0)
            start = q if fresh or prev is None else q + (q - prev)  # constant-velocity guess
            prev = None if fresh else q
            q, ok, it, p, H = self._solve_frame(
                start, target, w, self.first_iter if fresh else self.max_iter
            )
            iters[n] = it
            d = np.linalg.norm(p - target, axis=1)
            merr[n, vis] = d[vis]
            rms[n] = float(np.sqrt(np.mean(d[vis] ** 2)))
            mx[n] = float(d[vis].max())
            Q[n] = q
            ev = np.linalg.eigvalsh(H)
            fresh = False
            if ev[0] <= 1e-10 * max(ev[-1], 1e-300):
                status[n] = "too_few_markers"
            elif rms[n] > self.max_rms:
                status[n], fresh = "large_error", True
                q = q_start.copy()
            elif not ok:
                status[n] = "not_converged"
            else:
                status[n] = "ok"
            if progress is not None and (n + 1) % 25 == 0:
                progress(n + 1, N)
        seconds = _time.perf_counter() - t0
        if progress is not None:
            progress(N, N)
        return MarkerIKResult(
            q=Q,
            time=np.asarray(t_all, float)[idx],
            rms=rms,
            max_error=mx,
            n_markers=nvis,
            iterations=iters,
            status=status.astype(str),
            marker_error=merr,
            marker_names=names,
            joint_names=tuple(self.robot.joint_names),
            missing_markers=missing,
            seconds=seconds,
            info={"solver": "levenberg-marquardt", "marker_set": self.marker_set.name},
        )


def osim_marker_ik(
    robot, trial, setup: IKSetup, *, time_range=None, q0=None, rename=None, progress=None, **options
) -> MarkerIKResult:
    """Run an OpenSim IK setup with anthroarm: marker IK of ``trial`` on ``robot`` (the model
    the setup names, loaded with ``aa.load``), with the setup's marker weights, its coordinate
    tasks (``default_value`` ones at the model's default coordinates) and the frames of its
    ``time_range`` (or ``time_range=(t0, t1)``, s, on the trial's own time column; None in the
    setup: every frame).  ``options`` go to :class:`CoupledMarkerIK`.

    Markers of the setup that the model lacks are left out (as OpenSim's IK tool leaves them
    out); markers the trial lacks are listed in ``missing_markers`` of the result (zero weight).

    Raises
    ------
    MotionDataError
        A time range that selects no frame of the trial.
    """
    ms = osim_marker_set(robot, setup)
    default = robot.default_q() if hasattr(robot, "default_q") else robot.neutral()
    tasks = {}
    for name, task in setup.coordinate_tasks.items():
        try:
            i = coordinate_index(robot, name)
        except ParameterError:
            continue  # a locked or dependent coordinate: not a coordinate of the robot
        if task.value_type == "from_file":
            raise MotionDataError(
                f"coordinate task {name!r} takes its value from a coordinate file, which is not "
                "read: use default_value or manual_value",
                setup.source or None,
            )
        tasks[name] = (
            task.weight,
            default[i] if task.value_type == "default_value" else task.value,
        )
    tr = setup.time_range if time_range is None else np.asarray(time_range, float)
    frames = None
    if tr is not None:
        t = np.asarray(trial.meta.get("time", trial.time), float)
        frames = (t >= tr[0] - 1e-9) & (t <= tr[1] + 1e-9)
        if not frames.any():
            raise MotionDataError(
                f"time range {tr[0]:g}..{tr[1]:g} s selects no frame of the trial "
                f"({t[0]:g}..{t[-1]:g} s)",
                trial.source,
            )
    solver = CoupledMarkerIK(robot, ms, coordinate_tasks=tasks, **options)
    return solver.solve(trial, q0=q0, rename=rename, frames=frames, progress=progress)
