"""The one forward kinematics of :mod:`anthroarm.ik`: a chain as constant rigid transforms in
joint-local frames (:func:`local_frames`, :class:`PathFrames`), one joint's step
(:func:`joint_step`), the pose (:func:`chain_pose`) and the pose with its Jacobian
(:func:`chain_fk_jacobian`), the max-entry pose error (:func:`pose_error`) and Newton steps on
the pose (:func:`newton_pose`, :func:`solve6`).

Every FK of the IK is this one: the FK check and polish of the compiled closed forms and families
(:mod:`.geometric.fk`, :mod:`.families`), the Newton polish of the searches (:mod:`.search`, on
IK-Geo's chain as local frames, :func:`anthroarm.ik.search.geo_frames`), the Jacobian volumes
(:mod:`.geometric.singular`) and the Levenberg–Marquardt kernels of :mod:`anthroarm.ik.solve`.
Units: m, rad; base frame.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .vec3 import add, cross, mm, mv, perpendicular, scale, sub, transpose

#: columns of a frames array after a joint's local frame (:func:`local_frames`, 12): prismatic
#: or not, and the map q_k = a θ[c] + b of the joint's value from the coordinates θ
PRISMATIC, COL, MUL, OFF = 12, 13, 14, 15
#: columns of a frames array
WIDTH = 16


def local_frames(axes, points, M) -> np.ndarray:
    """The forward kinematics of a chain of revolute joints as constant rigid transforms:
    F(q) = A_0 Rz(q1) A_1 Rz(q2) ⋯ Rz(qn) A_n, returned as A (n + 1, :data:`WIDTH`) (each row:
    the rotation row by row, then the translation, base frame, m; then the joint map of
    :class:`PathFrames` for a chain whose coordinates are its joint angles: revolute,
    θ[k] = q_k).

    ``axes`` (n, 3) unit joint axes through ``points`` (n, 3) at q = 0, ``M`` (4×4) the tool
    pose at q = 0 (base frame, m).  Joint i gets a frame F_i whose z axis is its axis, at its
    point; then e^{ξi qi} = F_i Rz(qi) F_i⁻¹, and the product of exponentials
    e^{ξ1 q1} ⋯ e^{ξn qn} M (Lynch & Park, *Modern Robotics*, 2017, §4.1.1) becomes the product
    above with A_0 = F_1, A_i = F_i⁻¹ F_{i+1}, A_n = F_n⁻¹ M.  A joint's rotation then turns
    two columns of the partial product (:func:`joint_step`): about three quarters of the
    arithmetic of a product of exponentials, and the tool pose comes out without a last
    multiplication by M."""
    axes, points, M = (np.asarray(a, dtype=float) for a in (axes, points, M))
    frames = []
    for k, o in zip(axes, points):
        x = np.array(perpendicular(tuple(k)))
        frames.append((np.column_stack([x, np.cross(k, x), k]), o))
    n = len(frames)
    A = np.zeros((n + 1, WIDTH))
    chain = [(np.eye(3), np.zeros(3))] + frames + [(M[:3, :3], M[:3, 3])]
    for i in range(n + 1):
        (Ra, pa), (Rb, pb) = chain[i], chain[i + 1]
        A[i, :9], A[i, 9:12] = (Ra.T @ Rb).ravel(), Ra.T @ (pb - pa)
    A[:n, COL], A[:n, MUL] = np.arange(n), 1.0
    return A


class PathFrames:
    """The path from the base to one frame of ``robot.chain`` as the one array ``F`` (P + 1,
    :data:`WIDTH`) of :func:`chain_fk_jacobian`: row k holds the local frame A_k
    (:func:`local_frames`, from the P joints' placements and axes at θ = 0 and the frame's
    placement: 12 columns); for the k-th joint of the path, row k also holds [``PRISMATIC``] 1
    for a prismatic joint (a translation along its axis), 0 for a revolute or continuous one,
    and the map of its value q_k = a θ[c] + b from the independent coordinates θ
    (``chain.independent`` order): [``COL``] c, [``MUL``] a, [``OFF``] b (a mimic joint reads
    its source's θ, any other joint is its own θ with a = 1, b = 0)."""

    __slots__ = ("F", "P")

    def __init__(self, chain, frame):
        path = chain.path(frame)
        fr = chain.frame(frame)
        v_of = {j: k for k, j in enumerate(chain.independent)}
        R, p = np.eye(3), np.zeros(3)
        axes, points = [], []
        for i in path:  # each joint's placement, at θ = 0 (no joint motion)
            j = chain.joints[i]
            R, p = R @ j.rotation, p + R @ j.translation
            axes.append(R @ np.asarray(j.axis, dtype=float))
            points.append(p)
        M = np.eye(4)
        M[:3, :3], M[:3, 3] = R @ fr.rotation, p + R @ fr.translation
        self.P = len(path)
        self.F = local_frames(np.reshape(axes, (-1, 3)), np.reshape(points, (-1, 3)), M)
        for k, i in enumerate(path):
            j = chain.joints[i]
            self.F[k, PRISMATIC] = float(j.kind == "prismatic")
            self.F[k, COL] = v_of[j.mimic.source if j.is_mimic else i]
            self.F[k, MUL] = j.mimic.multiplier if j.is_mimic else 1.0
            self.F[k, OFF] = j.mimic.offset if j.is_mimic else 0.0


# ----------------------------------------------------------------------------- one joint's step
@kernel
def frame(A, i):
    """Row i of a frames array A (:func:`local_frames`) as (R, t)."""
    return (
        ((A[i, 0], A[i, 1], A[i, 2]), (A[i, 3], A[i, 4], A[i, 5]), (A[i, 6], A[i, 7], A[i, 8])),
        (A[i, 9], A[i, 10], A[i, 11]),
    )


@kernel
def joint_step(R, t, A, i, c, s):
    """(R, t) · Rz(q) · A_i, a partial product of :func:`local_frames` taken one revolute joint
    further, from c = cos q and s = sin q: the first two columns of R turned by q, then A_i."""
    Rq = (
        (R[0][0] * c + R[0][1] * s, R[0][1] * c - R[0][0] * s, R[0][2]),
        (R[1][0] * c + R[1][1] * s, R[1][1] * c - R[1][0] * s, R[1][2]),
        (R[2][0] * c + R[2][1] * s, R[2][1] * c - R[2][0] * s, R[2][2]),
    )
    B, a = frame(A, i)
    return mm(Rq, B), add(mv(Rq, a), t)


@kernel
def _motion(F, k, R, t, th):
    """Joint k of F at the coordinates θ (its value q = a θ[c] + b, :class:`PathFrames`) on the
    partial product (R, t) before it: (cos, sin) of its rotation and the translation after its
    translation — (cos q, sin q, t) for a revolute joint; (1, 0, t + q z) for a prismatic one,
    a translation along its z axis, (R, t) Tz(q) A_{k+1} = (R B, R a + t + q z).  Then
    :func:`joint_step` takes the product past it."""
    q = F[k, MUL] * th[int(F[k, COL])] + F[k, OFF]
    if F[k, PRISMATIC] != 0.0:
        return 1.0, 0.0, add(t, scale((R[0][2], R[1][2], R[2][2]), q))
    return math.cos(q), math.sin(q), t


# ----------------------------------------------------------------------------- the drivers
@kernel
def chain_pose(F, th):
    """The pose (R, t) of the frame of ``F`` (:func:`local_frames`, :class:`PathFrames`) at the
    coordinates θ (rad, m): the product A_0 M_1(q_1) A_1 ⋯ M_P(q_P) A_P of the path's joint
    motions (:func:`_motion`, :func:`joint_step`)."""
    R, t = frame(F, 0)
    for k in range(len(F) - 1):
        cq, sq, t = _motion(F, k, R, t, th)
        R, t = joint_step(R, t, F, k + 1, cq, sq)
    return R, t


@kernel
def chain_fk_jacobian(F, th, J, W, n):
    """The pose (R, t) of the frame of ``F`` (:func:`local_frames`, :class:`PathFrames`) at θ
    (the coordinates, rad or m; :func:`chain_pose`) and its geometric Jacobian into the first n
    columns of J (6, ≥ n), LOCAL_WORLD_ALIGNED as Pinocchio's ``getFrameJacobian``: rows
    (v; ω) of the frame's origin in base axes; column of a revolute joint (z × (t − o); z), of
    a prismatic one (z; 0), with the joint's axis z and point o in the base frame (the z axis
    and origin of the partial product before its motion, see :func:`local_frames`), times a
    for a mimic joint q = a θ + b, summed into its source's column (the chain rule); zero
    columns for the coordinates off the path (Murray, Li & Sastry, *A Mathematical
    Introduction to Robotic Manipulation*, 1994, §3.4 (3.55)).  ``W`` (≥ P, ≥ 6) scratch:
    each joint's z and o."""
    for r in range(6):
        for c in range(n):
            J[r, c] = 0.0
    R, t = frame(F, 0)
    P = len(F) - 1
    for k in range(P):
        W[k, 0], W[k, 1], W[k, 2] = R[0][2], R[1][2], R[2][2]
        W[k, 3], W[k, 4], W[k, 5] = t
        cq, sq, t = _motion(F, k, R, t, th)
        R, t = joint_step(R, t, F, k + 1, cq, sq)
    for k in range(P):
        c, a = int(F[k, COL]), F[k, MUL]
        z = (W[k, 0], W[k, 1], W[k, 2])
        if F[k, PRISMATIC] != 0.0:
            J[0, c] += a * z[0]
            J[1, c] += a * z[1]
            J[2, c] += a * z[2]
        else:
            v = cross(z, sub(t, (W[k, 3], W[k, 4], W[k, 5])))
            J[0, c] += a * v[0]
            J[1, c] += a * v[1]
            J[2, c] += a * v[2]
            J[3, c] += a * z[0]
            J[4, c] += a * z[1]
            J[5, c] += a * z[2]
    return R, t


# ----------------------------------------------------------------------------- Newton on the pose
@kernel
def pose_error(R, t, RT, pT):
    """max |F − T| over the 3×4 entries of the pose F = (R, t) against T = (RT, pT) (row
    tuples, m)."""
    err = 0.0
    for i in range(3):
        err = max(err, abs(t[i] - pT[i]))
        for j in range(3):
            err = max(err, abs(R[i][j] - RT[i][j]))
    return err


@kernel
def solve6(A, b):
    """Solve A x = b (the first six columns of A (6, ≥ 6), in place: ``b`` becomes x) by
    Gaussian elimination with partial pivoting; returns det A (0 when a pivot vanishes, b then
    undefined)."""
    det = 1.0
    for c in range(6):
        piv, big = c, abs(A[c, c])
        for r in range(c + 1, 6):
            if abs(A[r, c]) > big:
                piv, big = r, abs(A[r, c])
        if big == 0.0:
            return 0.0
        if piv != c:
            for k in range(6):
                A[c, k], A[piv, k] = A[piv, k], A[c, k]
            b[c], b[piv] = b[piv], b[c]
            det = -det
        d = A[c, c]
        det *= d
        for r in range(c + 1, 6):
            f = A[r, c] / d
            if f != 0.0:
                for k in range(c, 6):
                    A[r, k] -= f * A[c, k]
                b[r] -= f * b[c]
    for c in range(5, -1, -1):
        s = b[c]
        for k in range(c + 1, 6):
            s -= A[c, k] * b[k]
        b[c] = s / A[c, c]
    return det


@kernel
def newton_pose(F, q, n, RT, pT, steps, stop, J, W, E):
    """Newton steps on the pose equations F(q) = T = (RT, pT) of the first six coordinates of
    ``q`` (n,) (rad; the others held), in place: the step dq solves J dq = (p* − p;
    ½ vee(R* Rᵀ − R R*ᵀ)) with J the first six columns of the Jacobian at the tool point
    (:func:`chain_fk_jacobian`) and the rotation error the vee of the skew part of R* Rᵀ (first
    order in the small rotation R* Rᵀ ≈ I + [δθ]×; Lynch & Park, *Modern Robotics*, 2017,
    §6.2).  At most ``steps`` steps, fewer once the residual (:func:`pose_error`) is
    ≤ ``stop``; a step on a singular Jacobian (|det| ≤ 1e-12) ends it (the same q at every later
    step).  Returns the residual of the q it leaves.  ``J`` (6, ≥ n), ``W`` (≥ P, 6),
    ``E`` (6,) scratch."""
    res = math.inf
    for it in range(steps + 1):
        R, x = chain_fk_jacobian(F, q, J, W, n)
        res = pose_error(R, x, RT, pT)
        if res <= stop or it == steps:
            break
        D = mm(RT, transpose(R))
        E[0], E[1], E[2] = pT[0] - x[0], pT[1] - x[1], pT[2] - x[2]
        E[3] = 0.5 * (D[2][1] - D[1][2])
        E[4] = 0.5 * (D[0][2] - D[2][0])
        E[5] = 0.5 * (D[1][0] - D[0][1])
        if abs(solve6(J, E)) <= 1e-12:
            break
        for i in range(6):
            q[i] += E[i]
    return res
