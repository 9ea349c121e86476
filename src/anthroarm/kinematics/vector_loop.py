r"""The rotation-tensor (vector-loop) method of pose analysis, book §6-4, Eqs. (6-48)–(6-65).

An **orthogonal manipulator** (正交系机械手) has, in its initial state, every joint axis and
slide direction parallel to one of the ground axes i, j, k (k up, i forward).  Its grip point is
a vector loop (6-48) ``P = R₁ + R₂ + … + G*``, written as the nested **characteristic
equation** (6-50)/(6-59)

    P = C₁ + E^{w₁θ₁}(C₂ + E^{w₂θ₂}( … (C_m + E^{w_mθ_m}(G*)) … )),

with constant vectors C, variable-length (prismatic) vectors L = s·u, and the rotation tensors
E^{wθ} of §5-5 (:func:`anthroarm.spatial.rotation_tensor.rotation_tensor`) about the
*initial-state* axes w.  An attitude vector a* (6-49) turns with the hand: ``a = E(a₀)`` (6-53);
the pose is the product of 4×4 matrices ``M_i = [[E^{w_iθ_i}, C_i], [0, 1]]`` applied to
``[[G, a₀, b₀], [1, 0, 0]]`` (6-57), (6-60), (6-61).

A loop is a tuple of items, base to tip:

* ``("C", v)`` — a constant vector v (m), initial-state ground frame;
* ``("R", w)`` — a revolute joint: E^{wθ} acts on everything after it;
* ``("L", u)`` — a prismatic joint: the variable vector s·u (s the joint value, m);

then the grip vector G and the attitude vectors a₀, b₀ (unit).  :func:`nested_pose` evaluates
(6-59) from the inside out; :func:`product_pose` the matrix product (6-60); :func:`loop_spec`
writes the same arm as a :class:`~anthroarm.models.spec.ChainSpec` (joint origins = the
accumulated C vectors, axes = w, rpy = 0) for Pinocchio.  The two arms of the book are in
:mod:`anthroarm.models.templates` (``unimate2600_loop``, ``tensor6r_loop``).

Frames and units: the ground frame, m and rad; joint values in loop order.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..models.spec import ChainSpec, JointSpec, rod_link
from ..models.vector_loop import I, J, K, VectorLoop
from ..spatial.rotation_tensor import rotation_tensor
from ..spatial.rotations import homogeneous

__all__ = ["VectorLoop", "nested_pose", "product_pose", "pose_matrices", "loop_spec", "I", "J", "K"]


def _q(loop: VectorLoop, q) -> np.ndarray:
    try:
        q = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{loop.name}: q must be {loop.nq} finite joint values, got {q!r}"
        ) from None
    if q.shape != (loop.nq,) or not np.isfinite(q).all():
        raise ParameterError(f"{loop.name}: q must be {loop.nq} finite joint values, got {q!r}")
    return q


def nested_pose(loop: VectorLoop, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grip point P and attitude vectors a, b by the nested characteristic equation (6-59)
    (Unimate form (6-50), (6-52), (6-53)), evaluated from the tip inwards:
    ``v ← C + v``, ``v ← s u + v`` or ``v ← E^{wθ}(v)`` for P; a and b only turn."""
    q = _q(loop, q)
    P, a, b = loop.G.copy(), loop.a0.copy(), loop.b0.copy()
    k = loop.nq
    for kind, v in reversed(loop.items):
        if kind == "C":
            P = v + P
        elif kind == "L":
            k -= 1
            P = q[k] * v + P
        else:
            k -= 1
            E = rotation_tensor(v, q[k])
            P, a, b = E @ P, E @ a, E @ b
    return P, a, b


def pose_matrices(loop: VectorLoop, q) -> list[np.ndarray]:
    """The 4×4 matrices M_i = [[E^{w_iθ_i}, ΔP_i], [0, 1]] of (6-55)/(6-60), one per joint,
    ΔP_i the constant vectors (and the slide s·u of a prismatic joint) before joint i; the last
    matrix carries the vectors after the last joint (rotation I)."""
    q = _q(loop, q)
    out, acc, k = [], np.zeros(3), 0
    for kind, v in loop.items:
        if kind == "C":
            acc = acc + v
        elif kind == "L":
            acc = acc + q[k] * v
            k += 1
        else:
            M = np.eye(4)
            M[:3, :3], M[:3, 3] = rotation_tensor(v, q[k]), acc
            out.append(M)
            acc, k = np.zeros(3), k + 1
    M = np.eye(4)
    M[:3, 3] = acc
    out.append(M)
    return out


def product_pose(loop: VectorLoop, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P, a, b by the matrix product (6-60)/(6-61): ``[[P, a, b], [1, 0, 0]] = M₁ M₂ ⋯ M_m
    [[G, a₀, b₀], [1, 0, 0]]``."""
    T = np.eye(4)
    for M in pose_matrices(loop, q):
        T = T @ M
    X = np.zeros((4, 3))
    X[:3, 0], X[3, 0] = loop.G, 1.0
    X[:3, 1], X[:3, 2] = loop.a0, loop.b0
    Y = T @ X
    return Y[:3, 0], Y[:3, 1], Y[:3, 2]


def loop_spec(loop: VectorLoop, limits=None):
    """The loop as a :class:`~anthroarm.models.spec.ChainSpec` (URDF for Pinocchio): joint n
    sits at the sum of the constant vectors since joint n−1, rpy = 0, axis w (or u for a
    slide); the tool frame ``grip`` at G with the ground axes (so a = R_tool a₀).  ``limits``:
    optional (lower, upper) per joint (default ±π, slides 0–1 m)."""
    if loop.nq == 0:
        raise ParameterError(
            f"{loop.name}: the loop has no joint ('R' or 'L' item): nothing to build"
        )
    joints, acc, n = [], np.zeros(3), 0
    lim = list(limits) if limits is not None else None
    if lim is not None and len(lim) != loop.nq:
        raise ParameterError(
            f"{loop.name}: limits needs one (lower, upper) per joint ({loop.nq}), got {len(lim)}"
        )
    for kind, v in loop.items:
        if kind == "C":
            acc = acc + v
            continue
        lo, hi = lim[n] if lim is not None else ((-np.pi, np.pi) if kind == "R" else (0.0, 1.0))
        if joints:
            joints[-1].link = rod_link(joints[-1].link.name, acc)
        joints.append(
            JointSpec(
                f"joint{n + 1}",
                "revolute" if kind == "R" else "prismatic",
                homogeneous(r=acc),
                axis=tuple(v),
                lower=lo,
                upper=hi,
                link=rod_link(f"link{n + 1}", np.zeros(3)),
            )
        )
        acc, n = np.zeros(3), n + 1
    tool = acc + loop.G
    joints[-1].link = rod_link(joints[-1].link.name, tool)
    return ChainSpec(
        name=loop.name,
        description=f"{loop.name}: orthogonal manipulator in vector-loop form (book §6-4)",
        joints=joints,
        tool_name="grip",
        tool_origin=homogeneous(r=tool),
        source="book 000 l.4047-4209 (§6-4, Eqs. (6-48)-(6-65))",
        inertia_source="not printed: default rods (models.spec.rod_link)",
    )
