"""The muscle rows of ``anthroarm check model.osim`` (issue 34 item 6), for a model with muscles:

* against mathematics (always): the exact moment arms r = −∂l/∂q of
  :func:`~anthroarm.muscles.moment_arms` equal central differences of our own
  :func:`~anthroarm.muscles.lengths` (h = 1e-6 rad).  Muscles whose paths cross an active wrap
  object get their own row with a looser tolerance: OpenSim's tangent points on a wrap cylinder
  are not exactly those of the shortest path, and its moment arm (which ours reproduces, with the
  tangent points fixed in the wrap body) differs from the derivative of the length by up to
  ~1.5e-4 m (docs/guide/muscles.md);
* against OpenSim (when ``opensim`` imports): lengths equal ``Muscle.getLength`` and moment arms
  ``Muscle.computeMomentArm`` about every independent coordinate, on a few random states.
  About an independent coordinate OpenSim's number is the chain rule through its coordinate
  couplers, our −∂l/∂q in q; the states are set by :class:`anthroarm.osim.checks.OpenSimModel`.
  Tolerance 1e-6 m, 1e-4 m for lengths where a path crosses a wrap ellipsoid (the issue's
  bounds).  Over an ellipsoid OpenSim's ``computeMomentArm`` holds the tangent points fixed in
  the body, which is not the derivative of its own length there: those muscles' moment arms are
  compared with central differences of OpenSim's lengths instead (their own row).

A path that cannot be evaluated (an unsupported wrap object) gives ``unsupported`` rows that
name the reason.  These rows live here, not in :mod:`anthroarm.osim.checks`, because the model
layer does not import the algorithms; ``anthroarm check`` adds them after the osim rows.
"""

from __future__ import annotations

import numpy as np

from ..check_rows import CheckRow
from ..errors import MuscleError
from ..osim.checks import OpenSimModel
from .paths import lengths, lengths_and_moment_arms
from .reader import read_muscles

#: central-difference step of our lengths (rad or m)
H = 1e-6
#: central-difference step of OpenSim's lengths over an ellipsoid (its tangent points stop at a
#: squared residual of 1e-8, so a smaller step differentiates noise)
H_OPENSIM = 1e-4


def _wrapped(ms) -> np.ndarray:
    """Per muscle: does its path cross an active wrap object?"""
    return np.array(
        [
            any(ms.wrap_objects[w.wrap].active for w in m.wraps if w.wrap in ms.wrap_objects)
            for m in ms.muscles
        ],
        dtype=bool,
    )


def _over_ellipsoid(ms) -> np.ndarray:
    """Per muscle: does its path cross an active wrap ellipsoid?"""
    return np.array(
        [
            any(
                ms.wrap_objects[w.wrap].active and ms.wrap_objects[w.wrap].kind == "WrapEllipsoid"
                for w in m.wraps
                if w.wrap in ms.wrap_objects
            )
            for m in ms.muscles
        ],
        dtype=bool,
    )


def rows(robot, samples: int, rng) -> list[CheckRow]:
    """The muscle rows (module docstring) of an imported OpenSim model with muscles; ``[]`` for
    any other robot."""
    osim = getattr(robot, "osim", None)
    if osim is None:
        return []
    ms = read_muscles(osim.path)
    if len(ms) == 0:
        return []
    out = math_rows(robot, ms, samples, rng)
    if any(r.status == "unsupported" for r in out):
        return out
    try:
        import opensim  # noqa: F401  (optional: the oracle)
    except ImportError:
        return out
    return out + opensim_rows(robot, ms, samples, rng)


def math_rows(robot, ms, samples: int, rng) -> list[CheckRow]:
    """Moment arms against central differences of the lengths."""
    name, n = robot.name, max(1, min(int(samples), 10))
    Q = robot.random_q(n, rng)
    quantity = "muscle r = -dl/dq (central diff.)"
    try:
        _, R = lengths_and_moment_arms(robot, ms, Q)
        fd = np.empty_like(R)
        for k, e in enumerate(np.eye(robot.nq)):
            fd[:, :, k] = -(lengths(robot, ms, Q + H * e) - lengths(robot, ms, Q - H * e)) / (2 * H)
    except MuscleError as exc:
        return [CheckRow.unsupported(name, quantity, str(exc))]
    err = np.abs(R - fd).max(axis=(0, 2))
    wrapped = _wrapped(ms)
    out = []
    if (~wrapped).any():
        out.append(CheckRow(name, quantity, float(err[~wrapped].max()), 1e-6, n, "mathematics"))
    if wrapped.any():
        out.append(
            CheckRow(
                name,
                "muscle r = -dl/dq, wrapped paths (central diff.)",
                float(err[wrapped].max()),
                5e-4,
                n,
                "mathematics",
                note="OpenSim's wrap tangent points: r is not exactly -dl/dq there",
            )
        )
    return out


def opensim_rows(robot, ms, samples: int, rng) -> list[CheckRow]:
    """Lengths on up to 20 random states, every moment arm on up to 3, against OpenSim (module
    docstring); over an ellipsoid, moment arms against central differences of OpenSim's lengths
    (step :data:`H_OPENSIM`)."""
    o = OpenSimModel(robot.osim.path, robot.joint_names)
    theirs = [m.getName() for m in o.muscles]
    order = [theirs.index(nm) for nm in ms.names]
    n = max(1, min(int(samples), 20))
    n_arm = min(n, 3)
    Q = robot.random_q(n, rng)
    L, R = lengths_and_moment_arms(robot, ms, Q)
    ell = _over_ellipsoid(ms)

    def opensim_lengths(q):
        o.set_state(q)
        return o.lengths()[order]

    e_len = e_arm = e_ell = 0.0
    for i, q in enumerate(Q):
        e_len = max(e_len, float(np.abs(opensim_lengths(q) - L[i]).max()))
        if i >= n_arm:
            continue
        o.set_state(q)
        ro = o.moment_arms()[order]
        if (~ell).any():
            e_arm = max(e_arm, float(np.abs(ro - R[i])[~ell].max()))
        if ell.any():
            fd = np.column_stack(
                [
                    -(opensim_lengths(q + H_OPENSIM * e) - opensim_lengths(q - H_OPENSIM * e))
                    / (2 * H_OPENSIM)
                    for e in np.eye(robot.nq)
                ]
            )
            e_ell = max(e_ell, float(np.abs(fd - R[i])[ell].max()))
    name, src = robot.name, "opensim"
    out = [
        CheckRow(
            name, "muscle lengths = OpenSim getLength", e_len, 1e-4 if ell.any() else 1e-6, n, src
        )
    ]
    if (~ell).any():
        out.append(CheckRow(name, "muscle r = OpenSim computeMomentArm", e_arm, 1e-6, n_arm, src))
    if ell.any():
        out.append(
            CheckRow(
                name,
                "muscle r over ellipsoids = -d(OpenSim getLength)/dq",
                e_ell,
                2e-3,
                n_arm,
                src,
                note="central differences, h = 1e-4: OpenSim's tangent points converge to 1e-8",
            )
        )
    return out
