"""The linkage hand of §2-3 (Fig. 2-8 / 2-9; analysed in §6-5): the book's mechanisms on one
palm, as an exact closed-loop model, and the mimic fit of its plain-URDF tree.

Index, middle, ring and little finger are the planar six-bar of Fig. 2-8
(:mod:`anthroarm.mechanisms.finger`: one driven proximal phalanx, fingertip on the Chapter 3
grasp curve f(x)); the thumb is the RRSS spatial four-bar plus the planar four-bar of Fig. 2-9
(:mod:`anthroarm.mechanisms.thumb`, the Chapter 4 geometry).  Five mechanisms, five motors,
five closed loop pairs: the hand has 5 DOF.

* :func:`closed_loop` — the exact model: the spanning tree of all five mechanisms on one palm
  with their closures, a :class:`~anthroarm.mechanisms.closed_loop.ClosedLoop` (Pinocchio model
  + ``pin.RigidConstraintModel`` s); :func:`solve` closes every loop for given driver angles
  and returns the fingertips.  Its fingertip paths equal the mechanism solvers' (tested to
  1e-9 m).
* :func:`mimic_fit` — every passive joint of the tree as a line θ_j ≈ a_j θ_driver + b_j of its
  finger's driver, fitted by least squares on the exact closed-loop solution over the driver
  range, with the largest joint and fingertip errors.  The catalog model
  ``aa.load("prosthetic_hand")`` (:mod:`anthroarm.models.prosthetic_hand`, a plain URDF for
  viewers and simulators without loop constraints) is this tree with these mimic lines:
  :func:`tree_table` is what the catalog reads (committed as
  ``anthroarm/data/models/linkage_hand.json``, a test proves it equals this module's output;
  :func:`write_tree_table` regenerates it).

Dimensions: the index finger is :meth:`FingerGeometry.default` (fitted to f(x) — no finger
dimensions are printed in the book); middle, ring and little are the same six-bar scaled by
their length relative to the index in Buchholz et al. (1992) (phalanges 2–4: 0.544, 0.516,
0.414 vs 0.485 hand lengths); the thumb is :meth:`ThumbGeometry.book` (§4-5).  They are
mounted on a palm laid out like :mod:`anthroarm.models.hand` at its default size (middle MCP
pivot on the palm axis, HB/4 apart; thumb base radial, palmar and proximal).  ``scale``
scales the whole hand.

Palm frame (the base): −z toward the fingers, +y out of the palm, +x to the thumb side (a right
hand), origin at the wrist.  Each finger's six-bar lies in a plane x = const of the palm; its
planar frame (the frame of f(x)) is mounted so that the straight line MCP pivot → fingertip at
the start pose points along −z and flexion moves the fingertip palmar (+y).  Driver variables
(rad) are the tree's: ``{finger}_mcp`` = φ1 − φ_start (the six-bar's design range φ_start →
φ_end is *decreasing*, −12.8°: the range is [−0.2236, 0]), ``thumb_r1`` = θ1 ∈ [0, 30°] (the
Chapter 3 range of f2).  Sites ``{digit}_tip`` are the fingertips (P8 of the six-bar, S of the
thumb).  Units: m, rad, kg.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from .._io import atomic_write_text
from ..errors import ParameterError
from ..models.hand import (
    BREADTH_RATIO,
    BUCHHOLZ_1992,
    DIGITS,
    FINGERS,
    LINKAGE_HAND_TABLE,
    Q_ORDER,
    THUMB_REST_DIRECTION,
    check_hand_scale,
    digit_bases,
    hand_dimensions,
)
from ..models.human import segment_parameters
from ..spatial.rotations import homogeneous
from .closed_loop import ClosedLoop, LoopSpec, TreeJoint
from .finger import FingerGeometry, finger, finger_spec
from .rrss import RRSSGeometry
from .thumb import ThumbGeometry, thumb, thumb_spec

DEG = np.pi / 180.0
#: driver range of the thumb (rad): θ1 ∈ [0, 30°], where the Chapter 3 coupling f2 is defined
THUMB_RANGE = (0.0, 30.0 * DEG)
#: the name of the hand's closed-loop model and the prefix of its messages
NAME = "linkage hand"


def _finger_length(d: str) -> float:
    return float(sum(BUCHHOLZ_1992[d][1:]))


def scaled_finger(geom: FingerGeometry, s: float) -> FingerGeometry:
    """The six-bar ``geom`` with every length multiplied by ``s`` (angles, branches and driver
    range unchanged: the fingertip path is the scaled path)."""
    return FingerGeometry(
        P1=geom.P1 * s,
        P4=geom.P4 * s,
        R=tuple(r * s for r in geom.R),
        alpha=geom.alpha,
        branches=geom.branches,
        phi_range=geom.phi_range,
    )


def scaled_thumb(geom: ThumbGeometry, s: float) -> ThumbGeometry:
    """The thumb ``geom`` with every length multiplied by ``s``."""
    g = geom.rrss
    r = RRSSGeometry(a0=g.a0 * s, u0=g.u0, a1=g.a1 * s, u1=g.u1, b0=g.b0 * s, b1=g.b1 * s)
    return ThumbGeometry(
        rrss=r,
        ex=geom.ex,
        P0=geom.P0 * s,
        F0=geom.F0 * s,
        C=geom.C * s,
        R3=geom.R3 * s,
        beta=geom.beta,
    )


def _frame_from(e, m):
    """Orthonormal columns (e, m⊥, e × m⊥)."""
    e = np.asarray(e, float) / np.linalg.norm(e)
    m = np.asarray(m, float) - e * (e @ m)
    m /= np.linalg.norm(m)
    return np.column_stack([e, m, np.cross(e, m)])


@dataclass(frozen=True)
class ProstheticHand:
    """The hand's mechanisms and where they sit on the palm.

    ``fingers``: digit -> :class:`FingerGeometry` (planar frame = the frame of f(x), m);
    ``thumb``: :class:`ThumbGeometry` (its world frame, m); ``mounts``: digit -> 4×4 pose of
    the mechanism's frame in the palm frame; ``palm_size``: (breadth, length) of the palm (m)."""

    fingers: dict
    thumb: ThumbGeometry
    mounts: dict
    palm_size: tuple
    scale: float = 1.0
    thumb_range: tuple = THUMB_RANGE

    def driver_range(self, digit: str) -> tuple[float, float]:
        """(lower, upper) of the digit's driver variable (rad, tree convention, see module doc)."""
        if digit == "thumb":
            return tuple(self.thumb_range)
        g = self.fingers[digit]
        d = g.phi_range[1] - g.phi_range[0]
        return (min(0.0, d), max(0.0, d))

    def tip_exact(self, digit: str, driver) -> tuple[np.ndarray, np.ndarray]:
        """Fingertip(s) in the palm frame (m) from the mechanism solver at driver value(s)
        (tree convention), and the solver's status(es)."""
        T = self.mounts[digit]
        drv = np.asarray(driver, float)
        if digit == "thumb":
            s = thumb(self.thumb, drv)
            p = np.asarray(s.S)
        else:
            g = self.fingers[digit]
            s = finger(g, g.phi_range[0] + drv)
            p = np.concatenate([np.asarray(s.tip), np.zeros(np.shape(s.tip)[:-1] + (1,))], -1)
        return p @ T[:3, :3].T + T[:3, 3], np.asarray(s.status)


def default_hand(scale: float = 1.0) -> ProstheticHand:
    """The hand described in the module docstring, every length times ``scale``."""
    s = check_hand_scale(scale, NAME)
    # the palm of the default adult hand of models.hand (HL = de Leva hand / 0.446, HB = 0.45 HL)
    HL = segment_parameters()["hand"]["length"] / BUCHHOLZ_1992["middle"][0]
    dims = hand_dimensions(HL, BREADTH_RATIO * HL)
    l_palm = BUCHHOLZ_1992["middle"][0] * HL
    bases = digit_bases(dims, l_palm)
    g0 = FingerGeometry.default()
    fingers, mounts = {}, {}
    target = np.column_stack([[0, 0, -1.0], [0, 1.0, 0], [1.0, 0, 0]])  # (-z, +y, +x) of the palm
    for d in FINGERS:
        g = scaled_finger(g0, s * _finger_length(d) / _finger_length("index"))
        fingers[d] = g
        a, b = finger(g, g.phi_range[0]), finger(g, g.phi_range[1])
        e = np.r_[np.asarray(a.tip) - g.P1, 0.0]
        m = np.r_[np.asarray(b.tip) - np.asarray(a.tip), 0.0]
        R = target @ _frame_from(e, m).T
        mcp = bases[d][:3, 3] * s
        mounts[d] = homogeneous(R, mcp - R @ np.r_[g.P1, 0.0])
    th = scaled_thumb(ThumbGeometry.book(), s)
    a, b = thumb(th, 0.0), thumb(th, THUMB_RANGE[1])
    e = np.asarray(a.S) - th.rrss.a0
    m = np.asarray(b.S) - np.asarray(a.S)
    d_t = THUMB_REST_DIRECTION
    R = _frame_from(d_t, [-1.0, 1.0, 0.0]) @ _frame_from(e, m).T
    mounts["thumb"] = homogeneous(R, bases["thumb"][:3, 3] * s - R @ th.rrss.a0)
    return ProstheticHand(
        fingers=fingers,
        thumb=th,
        mounts=mounts,
        palm_size=(dims["hand_breadth"] * s, l_palm * s),
        scale=s,
    )


def _prefixed(spec: LoopSpec, digit: str, mount: np.ndarray, tip_site: str) -> tuple:
    """Joints, closures, inputs and sites of one mechanism renamed ``{digit}_...`` on the palm
    (a passive joint hanging on the palm: ``{digit}_{driver}_...``)."""

    def link(n):
        return "palm" if n == spec.root else f"{digit}_{n}"

    def site(n):
        return f"{digit}_tip" if n == tip_site else f"{digit}_{n}"

    def joint(j):
        # Pinocchio reads a link's child joints in name order and a <mimic> joint must come after
        # the joint it copies: a passive joint on the palm is named after its mechanism's driver
        if j.parent == spec.root and j.name not in spec.inputs:
            return f"{digit}_{spec.inputs[0]}_{j.name}"
        return f"{digit}_{j.name}"

    joints = tuple(
        TreeJoint(
            joint(j),
            link(j.parent),
            link(j.child),
            j.type,
            mount @ j.origin if j.parent == spec.root else j.origin,
            j.axis,
        )
        for j in spec.joints
    )
    # a planar loop's closure compares world x, y; mounted on the palm its plane is another one:
    # compare all three components (the out-of-plane row is redundant: least-norm Newton)
    closures = tuple(
        replace(c, frame_a=site(c.frame_a), frame_b=site(c.frame_b), components=(0, 1, 2))
        for c in spec.closures
    )
    sites = tuple((site(n), link(p), T) for n, p, T in spec.sites)
    return joints, closures, tuple(f"{digit}_{n}" for n in spec.inputs), sites


def loop_spec(hand: ProstheticHand | None = None) -> LoopSpec:
    """Spanning tree + closures of the whole hand: the five mechanisms' own trees
    (:func:`~anthroarm.mechanisms.finger.finger_spec`,
    :func:`~anthroarm.mechanisms.thumb.thumb_spec`) renamed ``{digit}_…`` and mounted on the
    ``palm``; inputs ``index_mcp``, ``little_mcp``, ``middle_mcp``, ``ring_mcp``, ``thumb_r1`` (the
    order of the plain URDF's q,
    :data:`anthroarm.models.hand.Q_ORDER`); fingertip sites ``{digit}_tip``.  q = 0 is every
    mechanism's start pose."""
    hand = hand or default_hand()
    parts = [
        _prefixed(thumb_spec(hand.thumb), "thumb", hand.mounts["thumb"], "S")
        if d == "thumb"
        else _prefixed(finger_spec(hand.fingers[d]), d, hand.mounts[d], "P8")
        for d in Q_ORDER
    ]
    return LoopSpec(
        name="linkage_hand",
        joints=sum((p[0] for p in parts), ()),
        closures=sum((p[1] for p in parts), ()),
        inputs=sum((p[2] for p in parts), ()),
        sites=sum((p[3] for p in parts), ()),
        root="palm",
        length_scale=float(
            sum(hand.fingers[d].length_scale for d in FINGERS) + hand.thumb.length_scale
        ),
    )


def closed_loop(hand: ProstheticHand | None = None) -> ClosedLoop:
    """The exact closed-loop model of the hand (Pinocchio + ``RigidConstraintModel`` s), see
    :func:`loop_spec`."""
    return ClosedLoop(loop_spec(hand))


@dataclass(frozen=True)
class HandState:
    """The hand at given drivers: tree configuration ``q`` of the closed-loop model, fingertips
    ``tips`` (digit -> (3,) in the palm frame, m), the largest closure residual (m), and a
    ``status`` "ok" or "out_of_range" / "not_converged" with a ``reason``."""

    q: np.ndarray
    tips: dict
    residual: float
    status: str
    reason: str

    @property
    def ok(self) -> bool:
        return self.status == "ok"


def _drivers(loop: ClosedLoop, drivers) -> np.ndarray:
    names = loop.spec.inputs
    if isinstance(drivers, dict):
        unknown = sorted(set(drivers) - set(names))
        if unknown:
            raise ParameterError(
                f"{NAME}: unknown driver(s) {unknown}; drivers: {', '.join(names)}"
            )
        vals = [drivers.get(n, 0.0) for n in names]
    else:
        vals = drivers
    try:
        x = np.atleast_1d(np.array(vals, dtype=float))
    except (TypeError, ValueError):
        raise ParameterError(f"{NAME}: drivers must be numbers (rad), got {drivers!r}") from None
    if x.shape != (len(names),):
        raise ParameterError(
            f"{NAME}: {len(names)} drivers ({', '.join(names)}), got shape {x.shape}"
        )
    if not np.all(np.isfinite(x)):
        raise ParameterError(f"{NAME}: drivers must be finite (rad), got {x.tolist()}")
    return x


def solve(
    loop: ClosedLoop, drivers, hand: ProstheticHand | None = None, steps: int = 12
) -> HandState:
    """Close every loop of the hand at the driver values (dict name -> rad, or the 5 values in
    ``loop.spec.inputs`` order), by continuation from the start pose q = 0 (the assembly
    branch of the mechanism solvers), and read the fingertips by Pinocchio FK.

    Drivers outside the hand's driver ranges give ``status="out_of_range"`` (nothing solved, tips
    NaN-free: empty dict); a continuation that cannot close a loop gives ``"not_converged"``."""
    hand = hand or default_hand()
    x = _drivers(loop, drivers)
    digits = [n.split("_")[0] for n in loop.spec.inputs]
    for d, v, n in zip(digits, x, loop.spec.inputs):
        lo, hi = hand.driver_range(d)
        if not (lo - 1e-12 <= v <= hi + 1e-12):
            return HandState(
                np.zeros(loop.model.nq),
                {},
                float("nan"),
                "out_of_range",
                f"{n} = {v:.6g} rad is outside its range [{lo:.6g}, {hi:.6g}] rad",
            )
    path = np.linspace(0.0, 1.0, max(2, int(steps)))[:, None] * x[None, :]
    Q, ok = loop.track(path, q0=np.zeros(loop.model.nq))
    q = Q[-1]
    res = float(np.max(np.abs(loop.residual(q))))
    if not ok[-1]:
        return HandState(
            q, {}, res, "not_converged", f"the closure did not converge (|residual| {res:.3e} m)"
        )
    tips = {d: loop.frame_position(q, f"{d}_tip") for d in DIGITS}
    return HandState(q, tips, res, "ok", "ok")


def closure_status(loop: ClosedLoop, q, tol: float = 1e-9) -> tuple[float, str]:
    """Whether a tree configuration ``q`` of :func:`closed_loop` closes every loop: the largest
    closure gap (m, Pinocchio ``RigidConstraintModel``) and ``"ok"`` or ``"inconsistent"`` (the
    passive joints contradict the drivers: the loops are open by more than ``tol`` m).
    A q of the wrong size or not finite raises :class:`~anthroarm.errors.ParameterError`."""
    try:
        q = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{NAME}: q must be {loop.model.nq} joint values (rad), got {q!r}"
        ) from None
    if q.shape != (loop.model.nq,) or not np.all(np.isfinite(q)):
        raise ParameterError(
            f"{NAME}: q must be {loop.model.nq} finite joint values (rad), got shape {q.shape}"
        )
    gap = loop.residual_pin(q)
    return gap, ("ok" if gap <= tol else "inconsistent")


@dataclass(frozen=True)
class MimicFit:
    """The mimic approximation of every passive tree joint: ``joints`` name -> (driver,
    multiplier, offset, largest joint error (rad) over the driver range); ``tip_error`` digit ->
    largest fingertip distance (m) between the mimic tree and the exact closed loop;
    ``samples`` per driver."""

    joints: dict
    tip_error: dict
    samples: int


@lru_cache(maxsize=8)
def _fit(scale: float, samples: int) -> MimicFit:
    hand = default_hand(scale)
    loop = closed_loop(hand)
    spec = loop.spec
    names = [n for n in loop.model.names[1:]]
    inputs = list(spec.inputs)
    nin = len(inputs)
    joints, tip_err = {}, {}
    for k, n_in in enumerate(inputs):
        d = n_in.split("_")[0]
        lo, hi = hand.driver_range(d)
        t = np.linspace(0.0, 1.0, samples)
        u = (
            lo + (hi - lo) * t if d == "thumb" else hi + (lo - hi) * t
        )  # start at the start pose (0)
        path = np.zeros((samples, nin))
        path[:, k] = u
        Q, ok = loop.track(path, q0=np.zeros(loop.model.nq))
        if not np.all(ok):
            raise RuntimeError(
                f"{NAME}: the {d} loop did not close over its range"
            )  # pragma: no cover
        own = [i for i, n in enumerate(names) if n.startswith(d + "_") and n != n_in]
        A = np.column_stack([u, np.ones_like(u)])
        Qfit = np.zeros_like(Q)
        Qfit[:, loop.joint_q_index(n_in)] = u
        for i in own:
            qi = Q[:, loop.joint_q_index(names[i])]
            (a, b), *_ = np.linalg.lstsq(A, qi, rcond=None)
            a, b = round(float(a), 10), round(float(b), 10)
            Qfit[:, loop.joint_q_index(names[i])] = a * u + b
            joints[names[i]] = (n_in, a, b, float(np.max(np.abs(a * u + b - qi))))
        exact = np.array([loop.frame_position(q, f"{d}_tip") for q in Q])
        approx = np.array([loop.frame_position(q, f"{d}_tip") for q in Qfit])
        tip_err[d] = float(np.max(np.linalg.norm(approx - exact, axis=1)))
    return MimicFit(joints=joints, tip_error=tip_err, samples=samples)


def mimic_fit(scale: float = 1.0, samples: int = 41) -> MimicFit:
    """Least-squares line θ_j ≈ a θ_driver + b of every passive joint of the hand's tree over
    its driver's range (``samples`` exact closed-loop solutions), with the largest joint and
    fingertip errors of the approximation.  Multipliers and offsets are rounded to 1e-10 so
    the URDF text is reproducible."""
    default_hand(scale)  # validates scale
    if (
        isinstance(samples, bool)
        or not isinstance(samples, (int, np.integer))
        or not 3 <= samples <= 10_000
    ):
        raise ParameterError(f"samples must be an integer in 3…10000, got {samples!r}")
    return _fit(float(scale), int(samples))


def tree_table(samples: int = 41) -> dict:
    """What the catalog's plain-URDF model of the hand is made of, at scale 1 (JSON-ready):
    ``inputs`` (the drivers, q order), ``driver_ranges`` digit -> (lo, hi) rad, ``palm_size``
    (breadth, length) m, ``joints`` (name, parent, child, type, 4×4 origin row by row, axis) of
    the spanning tree (:func:`loop_spec`), ``sites`` (name, parent link, 4×4 placement),
    ``fit`` (:func:`mimic_fit`: joint -> (driver, multiplier, offset, largest joint error rad),
    ``tip_error`` digit -> m, ``samples``).  Every length scales with the hand; angles, the
    multipliers and the offsets do not."""
    hand = default_hand(1.0)
    spec = loop_spec(hand)
    fit = mimic_fit(1.0, samples)
    return {
        "scale": 1.0,
        "inputs": list(spec.inputs),
        "driver_ranges": {d: list(hand.driver_range(d)) for d in DIGITS},
        "palm_size": [float(x) for x in hand.palm_size],
        "joints": [
            [j.name, j.parent, j.child, j.type, np.asarray(j.origin, float).ravel().tolist()]
            + [[float(a) for a in j.axis]]
            for j in spec.joints
        ],
        "sites": [[n, p, np.asarray(T, float).ravel().tolist()] for n, p, T in spec.sites],
        "fit": {
            "joints": {k: list(v) for k, v in fit.joints.items()},
            "tip_error": dict(fit.tip_error),
            "samples": fit.samples,
        },
    }


def write_tree_table(path=None) -> Path:
    """Write :func:`tree_table` as JSON to ``path`` (default: the package's
    ``data/models/linkage_hand.json``, which the catalog reads)."""
    p = Path(path) if path is not None else LINKAGE_HAND_TABLE
    atomic_write_text(p, json.dumps(tree_table(), indent=1) + "\n")
    return p
