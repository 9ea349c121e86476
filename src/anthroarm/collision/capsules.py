"""Capsule–capsule distances of many pairs at once (numpy), the fast path of
:mod:`anthroarm.collision.distance`.

A capsule is the set of points within r of a segment [p, q]; the distance of two capsules is
the distance of their segments' closest points c₁, c₂ minus r₁ + r₂, with witness points
c₁ + r₁ n, c₂ − r₂ n and the normal n = (c₂ − c₁)/|c₂ − c₁|.  The closest points of two
segments follow Ericson, *Real-Time Collision Detection* (2005) §5.1.9 (ClosestPtSegmentSegment),
vectorised over the pairs.  Pairs whose segments (nearly) intersect have no defined normal
here (|c₂ − c₁| < 1e-9 m): :func:`segment_pairs` flags them and the caller asks coal.
tests/collision checks every output against ``coal.distance`` on the same shapes and poses.
"""

from __future__ import annotations

import numpy as np


def joint_poses(data, joints) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (J, 3, 3) and translations (J, 3) of ``data.oMi`` for the joint indices
    ``joints`` (J,)."""
    oMi = data.oMi
    R = np.empty((len(joints), 3, 3))
    t = np.empty((len(joints), 3))
    for k, j in enumerate(joints):
        M = oMi[int(j)]
        R[k] = M.rotation
        t[k] = M.translation
    return R, t


def segment_pairs(p1, q1, p2, q2):
    """Closest points (c1, c2), each (K, 3), of the segments [p1, q1] and [p2, q2] (K, 3)
    (Ericson 2005, §5.1.9; every segment of positive length)."""
    d1 = q1 - p1
    d2 = q2 - p2
    r = p1 - p2
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = np.einsum("ij,ij->i", d1, r)
    b = np.einsum("ij,ij->i", d1, d2)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-12 * a * e, np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = (b * s + f) / e
        lo = t < 0.0
        hi = t > 1.0
        s = np.where(lo, np.clip(-c / a, 0.0, 1.0), np.where(hi, np.clip((b - c) / a, 0.0, 1.0), s))
        t = np.clip(t, 0.0, 1.0)
    c1 = p1 + d1 * s[:, None]
    c2 = p2 + d2 * t[:, None]
    return c1, c2


def capsule_pairs(A1, B1, r1, A2, B2, r2):
    """Signed distances (K,), witness points (K, 3) × 2, normals (K, 3) and a mask (K,) of the
    pairs whose axes (nearly) meet, of capsules with axis segments [A1, B1], [A2, B2] and radii
    r1, r2."""
    c1, c2 = segment_pairs(A1, B1, A2, B2)
    diff = c2 - c1
    L = np.sqrt(np.einsum("ij,ij->i", diff, diff))
    bad = L < 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):
        n = diff / np.where(bad, 1.0, L)[:, None]
    d = L - r1 - r2
    pa = c1 + r1[:, None] * n
    pb = c2 - r2[:, None] * n
    return d, pa, pb, n, bad


__all__ = ["joint_poses", "segment_pairs", "capsule_pairs"]
