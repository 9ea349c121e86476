"""Which pairs of a robot's bodies are checked: the automatic filter and SRDF disable lists.

:func:`filter_pairs` follows the approach of MoveIt's setup assistant (the "default
collision matrix", Coleman et al. 2014, *Reducing the barrier to entry of complex robotic
software: a MoveIt! case study*): a pair is not checked when

* both bodies hang on the same joint (``"same body"``: their distance never changes);
* the bodies are kinematic neighbours (one's joint is the nearest ancestor joint carrying a
  body of the other's) and touch at the configuration ``q0`` (``"adjacent"``: they meet at
  their shared joint — closer than ``adjacent_margin``, 5 mm, at ``q0``; neighbours that do
  not touch there, such as the upper arm and the torso, stay checked);
* they are in collision at ``q0``, the robot's default configuration (``"default"``, MoveIt's
  "in collision by default": a start of the robot's own must be collision-free);
* they are in collision in at least ``always_fraction`` (95 %, MoveIt's default) of ``samples``
  random configurations inside the limits (``"always"``);
* they never come closer than ``never_margin`` in those samples (``"never"``; MoveIt uses 0,
  a margin keeps pairs that nearly touch);
* an SRDF's ``<disable_collisions link1= link2=>`` names them (``"srdf"``).

The result is editable: :meth:`CollisionModel.disable <anthroarm.collision.model.CollisionModel.disable>`
and ``enable``.  The active pairs are also written into the ``GeometryModel``'s
``collisionPairs`` (so that Pinocchio's ``computeDistances`` and pink's ``SelfCollisionBarrier``
read the same pairs).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import CollisionError


def geometric_parents(cm) -> dict:
    """joint -> its nearest ancestor joint that carries a body (0: the world)."""
    m = cm.model
    carrying = set(cm.joint.tolist())
    out = {}
    for j in range(m.njoints):
        p = m.parents[j] if j else 0
        while p and p not in carrying:
            p = m.parents[p]
        out[j] = p
    return out


def read_srdf(srdf) -> list[tuple[str, str, str]]:
    """(link1, link2, reason) of every ``<disable_collisions>`` of an SRDF (a path or its
    text).  An unreadable file raises :class:`~anthroarm.errors.CollisionError`."""
    text = srdf
    if isinstance(srdf, Path) or (isinstance(srdf, str) and "<" not in srdf):
        p = Path(srdf)
        if not p.is_file():
            raise CollisionError(f"SRDF {p}: file not found", path=p)
        text = p.read_text(errors="replace")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise CollisionError(f"SRDF is not valid XML: {exc}") from None
    return [
        (e.get("link1", ""), e.get("link2", ""), e.get("reason", ""))
        for e in root.iter("disable_collisions")
    ]


def set_pairs(cm, pairs) -> None:
    """Write ``pairs`` into the GeometryModel's ``collisionPairs``."""
    gm = cm.geometry
    gm.removeAllCollisionPairs()
    for a, b in pairs:
        gm.addCollisionPair(pin.CollisionPair(int(a), int(b)))


def sample_distances(robot, cm, pairs, qs) -> np.ndarray:
    """Distances (len(qs), len(pairs)) of body pairs over configurations, by Pinocchio's
    ``computeDistances`` (coal, every pair)."""
    set_pairs(cm, pairs)
    gd = pin.GeometryData(cm.geometry)
    data = robot.model.createData()
    out = np.empty((len(qs), len(pairs)))
    for k, q in enumerate(qs):
        pin.computeDistances(robot.model, data, cm.geometry, gd, q)
        out[k] = [r.min_distance for r in gd.distanceResults]
    return out


def filter_pairs(
    robot, cm, srdf=None, samples: int = 500, never_margin: float = 0.05, rng=0,
    adjacent_margin: float = 0.005, always_fraction: float = 0.95,
):  # fmt: skip
    """Fill ``cm.pairs`` and ``cm.disabled`` (see the module docstring).  Returns ``cm``."""
    n = cm.n
    parents = geometric_parents(cm)
    disabled = {}
    cand = []
    for i in range(n):
        for j in range(i + 1, n):
            ji, jj = cm.joint[i], cm.joint[j]
            if ji == jj:
                disabled[cm.key(i, j)] = "same body"
            else:
                cand.append((i, j))
    if srdf is not None:
        skip = {frozenset(p[:2]) for p in read_srdf(srdf)}
        keep = []
        for i, j in cand:
            if frozenset((cm.links[i], cm.links[j])) in skip:
                disabled[cm.key(i, j)] = "srdf"
            else:
                keep.append((i, j))
        cand = keep
    chain = robot.chain
    q0 = np.clip(
        robot.neutral(), np.where(np.isfinite(chain.lower), chain.lower, -1e9), chain.upper
    )
    if cand:
        d0 = sample_distances(robot, cm, cand, [q0])[0]
        keep = []
        for (i, j), d in zip(cand, d0):
            ji, jj = cm.joint[i], cm.joint[j]
            if (parents[ji] == jj or parents[jj] == ji) and d <= adjacent_margin:
                disabled[cm.key(i, j)] = "adjacent"
            elif d <= 0.0:
                disabled[cm.key(i, j)] = "default"
            else:
                keep.append((i, j))
        cand = keep
    if cand and samples > 0:
        qs = robot.random_q(int(samples), rng=np.random.default_rng(rng))
        D = sample_distances(robot, cm, cand, qs)
        always = (D <= 0.0).mean(axis=0) >= always_fraction
        never = D.min(axis=0) > never_margin
        keep = []
        for k, (i, j) in enumerate(cand):
            if always[k]:
                disabled[cm.key(i, j)] = "always"
            elif never[k]:
                disabled[cm.key(i, j)] = "never"
            else:
                keep.append((i, j))
        cand = keep
    cm.pairs = np.array(cand, dtype=int).reshape(-1, 2)
    cm.disabled = disabled
    set_pairs(cm, cand)
    return cm


__all__ = ["set_pairs", "filter_pairs", "read_srdf", "sample_distances", "geometric_parents"]
