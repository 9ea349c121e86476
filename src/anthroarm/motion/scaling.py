"""A person's arm: from height, mass and sex, from measured segment lengths, or from a static trial.

Three ways, all ending in ``aa.load("human_arm7", ...)`` keywords:

* **height, mass, sex** — de Leva (1996) proportions (:mod:`anthroarm.models.human`):
  ``aa.load("human_arm7", height=1.62, mass=55, sex="female")``;
* **measured segment lengths** (m; shoulder–elbow, elbow–wrist, wrist–3rd metacarpale):
  ``aa.load("human_arm7", height=..., segment_lengths={"upperarm": 0.30, "forearm": 0.26})``;
* **a static marker trial** — :func:`scale_from_static`: least-squares segment scale factors.

Static-trial scaling (the role of OpenSim's Scale tool, Delp et al. 2007, here as one least
squares problem instead of marker-pair distances): the person stands still for a second or two;
each marker's position is the median of its visible samples.  Every body b that carries markers
and has a length (:func:`~anthroarm.motion.markers.segment_length`) gets a factor s_b that
scales everything fixed in it: the offset to the next joint (or to the tool) and its markers'
positions.  The unknowns (q, log s) minimise::

    Σ_k w_k ‖p_k(q, s) − m̄_k‖²,   q within the joint limits, 0.5 ≤ s_b ≤ 2,

(``scipy.optimize.least_squares``, trust-region reflective, on a scaled copy of the Pinocchio
model per evaluation).  Markers fixed to the base (the acromion) do not enter: the shoulder
joint centre is the base origin.  The factors are identifiable when each scaled body carries
markers away from its joint or has markers below it (the epicondyles fix the upper arm's length,
the styloids the forearm's, the metacarpal heads the hand's).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import MarkerSetError, MotionDataError, ParameterError
from ..ik.qp import comfortable_posture
from ..models.human import SEGMENT_LINKS
from .marker_ik import match_markers
from .markers import MarkerSet, default_marker_set, segment_length
from .trial import MarkerTrajectories, check_coordinates


@dataclass
class ScalingResult:
    """Outcome of :func:`scale_from_static`.

    Attributes
    ----------
    scales : dict
        Body frame name -> scale factor s (1 = the model as loaded).
    lengths : dict
        Body frame name -> scaled segment length, m.
    segment_lengths : dict
        The same for the human arm model's segments (``"upperarm"``, ``"forearm"``, ``"hand"``),
        ready for ``aa.load("human_arm7", segment_lengths=...)``.
    q : (nq,)
        Static posture, rad.
    rms, max_error : float
        Marker fit errors, m.
    marker_error : dict
        Marker name -> distance from the scaled model, m.
    marker_set : MarkerSet
        The marker set with positions scaled with their bodies; markers fixed to the base are
        moved to where the static trial saw them.
    status : str
        ``"ok"``; ``"large_error"``: the RMS marker error is above ``max_rms`` (a static trial in
        other units, mislabelled markers, another person's set); ``"at_bound"``: a scale factor
        stopped at a bound of ``bounds`` (``info["at_bound"]`` names the bodies).  Only an
        ``"ok"`` result is a measurement of the person.
    """

    scales: dict
    lengths: dict
    segment_lengths: dict
    q: np.ndarray
    rms: float
    max_error: float
    marker_error: dict
    marker_set: MarkerSet
    status: str = "ok"
    info: dict = field(default_factory=dict)

    def load_kwargs(self, robot) -> dict:
        """Keywords of ``aa.load`` that rebuild ``robot``'s person with these lengths."""
        params = dict(getattr(getattr(robot, "spec", None), "params", {}) or {})
        out = {k: params[k] for k in ("height", "mass", "sex") if k in params}
        out["segment_lengths"] = dict(self.segment_lengths)
        return out


def _static_positions(trial, marker_set, rename, subject=None):
    if isinstance(trial, MarkerTrajectories):
        cols = match_markers(trial.names, marker_set, rename, subject=subject)
        P = np.full((trial.n_frames, len(marker_set), 3), np.nan)
        P[:, cols >= 0] = trial.positions[:, cols[cols >= 0]]
    else:
        try:
            P = np.array(trial, dtype=float)
        except (TypeError, ValueError):
            raise MotionDataError("static marker positions must be numbers (m)") from None
        if P.ndim == 2:
            P = P[None]
        if P.ndim != 3 or P.shape[1:] != (len(marker_set), 3):
            raise MotionDataError(
                f"static marker positions must have shape (frames, {len(marker_set)}, 3), got "
                f"{P.shape}"
            )
        check_coordinates(P, marker_set.names)
    P[~np.isfinite(P).all(axis=2)] = np.nan
    seen = np.isfinite(P).all(axis=2).any(axis=0)
    m = np.full((len(marker_set), 3), np.nan)
    if seen.any():
        m[seen] = np.nanmedian(P[:, seen], axis=0)
    return m, seen


def scale_from_static(
    robot,
    trial,
    marker_set: MarkerSet | None = None,
    *,
    q0=None,
    rename: dict | None = None,
    subject: str | None = None,
    bounds=(0.5, 2.0),
    max_rms: float = 0.02,
) -> ScalingResult:
    """Segment scale factors of ``robot`` from a static trial (see the module docstring).

    ``trial``: :class:`~anthroarm.motion.trial.MarkerTrajectories` (a C3D read with
    :func:`~anthroarm.motion.c3d.read_c3d`) or an array ``(frames, M, 3)`` / ``(M, 3)`` in the
    marker set's order (m); ``rename`` and ``subject`` (whose markers, in a trial of several
    subjects) as in :func:`~anthroarm.motion.marker_ik.match_markers`.  The result's ``status`` says
    whether the fit can be trusted (RMS marker error at most ``max_rms`` m, no factor at a bound).
    Raises
    :class:`~anthroarm.errors.MarkerSetError` when a body to be scaled has no visible marker at
    or below its distal end, :class:`~anthroarm.errors.ParameterError` for ``bounds`` that are
    not 0 < low < 1 < high or a ``max_rms`` that is not a positive number."""
    from scipy.optimize import least_squares

    try:
        lo_b, hi_b = (float(b) for b in bounds)
        ok = 0 < lo_b < 1 < hi_b < np.inf and 0 < float(max_rms) < np.inf
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError(
            f"bounds must be two numbers 0 < low < 1 < high and max_rms a positive number (m), got "
            f"{bounds!r}, {max_rms!r}"
        )
    ms = default_marker_set(robot) if marker_set is None else marker_set
    bound = ms.bind(robot)
    mbar, seen = _static_positions(trial, ms, rename, subject)
    chain = robot.chain
    use = seen & (bound.joint >= 0)
    if not use.any():
        raise MarkerSetError(
            f"no marker of {ms.name!r} on a moving body is visible in the static trial"
        )
    # bodies to scale: those carrying a used marker and having a length
    bodies = []
    for j in sorted(set(bound.joint[use].tolist())):
        frame = next(f for f in chain.frames if f.joint == j and f.is_body)
        try:
            L = segment_length(robot, frame.name)
        except MarkerSetError:
            continue
        if L > 0:
            bodies.append((j, frame.name, L))
    # identifiability: a visible marker on the body's descendants (or the body itself, off-origin)
    for j, name, _L in bodies:
        below = [
            k
            for k in np.flatnonzero(use)
            if j in chain.path(bound._frame_of(k))
            and (bound.joint[k] != j or np.linalg.norm(bound.local[k]) > 0)
        ]
        if not below:
            raise MarkerSetError(
                f"the length of {name!r} cannot be found: no visible marker on it or below it"
            )
    model0 = robot.model
    scaled_joint = {j: [c for c in chain.children(j)] for j, _, _ in bodies}
    body_index = {j: i for i, (j, _, _) in enumerate(bodies)}
    w = np.sqrt(ms.weights[use])
    local = bound.local[use]
    mjoint = bound.joint[use]
    target = mbar[use]
    nq = robot.nq
    lo = np.concatenate([robot.lower, np.full(len(bodies), np.log(bounds[0]))])
    hi = np.concatenate([robot.upper, np.full(len(bodies), np.log(bounds[1]))])

    def scaled_model(s):
        m = pin.Model(model0)
        for j, i in body_index.items():
            for c in scaled_joint[j]:
                pl = m.jointPlacements[c + 1]
                pl.translation = pl.translation * s[i]
                m.jointPlacements[c + 1] = pl
        return m

    def positions(x):
        q, s = x[:nq], np.exp(x[nq:])
        m = scaled_model(s)
        d = m.createData()
        pin.forwardKinematics(m, d, q)
        fac = np.array([s[body_index[j]] if j in body_index else 1.0 for j in mjoint])
        out = np.empty_like(local)
        for k, j in enumerate(mjoint):
            M = d.oMi[int(j) + 1]
            out[k] = M.rotation @ (fac[k] * local[k]) + M.translation
        return out

    def fun(x):
        return ((positions(x) - target) * w[:, None]).ravel()

    qs = comfortable_posture(robot) if q0 is None else robot.check_q(q0, name="q0")
    x0 = np.concatenate([np.clip(qs, robot.lower, robot.upper), np.zeros(len(bodies))])
    best = None
    seeds = [x0] + [
        np.concatenate([robot.random_q(rng=i, margin=0.05), np.zeros(len(bodies))])
        for i in range(4)
    ]
    for xs in seeds:
        sol = least_squares(
            fun, xs, bounds=(lo, hi), x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12
        )
        if best is None or sol.cost < best.cost:
            best = sol
        if np.sqrt(2 * sol.cost / max(use.sum(), 1)) < 0.01:
            break
    x = best.x
    s = np.exp(x[nq:])
    d = np.linalg.norm(positions(x) - target, axis=1)
    scales = {name: float(s[i]) for i, (j, name, L) in enumerate(bodies)}
    lengths = {name: float(s[i] * L) for i, (j, name, L) in enumerate(bodies)}

    seg = {key: lengths[link] for key, link in SEGMENT_LINKS.items() if link in lengths}
    new_markers = []
    for k, m in enumerate(ms):
        j = bound.joint[k]
        if j < 0 and seen[k]:
            # fixed to the base: the marker is where the static trial saw it (base frame = world)
            f = chain.frame(m.body)
            pos = f.rotation.T @ (mbar[k] - f.translation)
        else:
            fac = scales.get(next((nm for jj, nm, _ in bodies if jj == j), ""), 1.0)
            pos = np.asarray(m.position, float) * fac
        new_markers.append(type(m)(m.name, m.body, tuple(float(v) for v in pos), m.weight))
    err = {n: float(e) for n, e in zip(np.array(ms.names)[use], d)}
    rms = float(np.sqrt(np.mean(d**2)))
    at_bound = [
        name
        for name, f in scales.items()
        if not bounds[0] * (1 + 1e-6) < f < bounds[1] * (1 - 1e-6)
    ]
    status = "large_error" if not rms <= max_rms else "at_bound" if at_bound else "ok"
    return ScalingResult(
        scales,
        lengths,
        seg,
        x[:nq].copy(),
        rms,
        float(d.max()),
        err,
        MarkerSet(new_markers, name=f"{ms.name} (scaled)"),
        status,
        info={
            "cost": float(best.cost),
            "nfev": int(best.nfev),
            "status": int(best.status),
            "markers_used": [n for n, u in zip(ms.names, use) if u],
            "at_bound": at_bound,
        },
    )
