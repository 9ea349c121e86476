"""3-vectors and 3×3 rotations as tuples, for compiled scalar kernels (:mod:`anthroarm.jit`).

A vector is a tuple ``(x, y, z)`` of floats, a matrix a tuple of its three rows.  Tuples live
in registers inside a compiled kernel (no allocation), which makes the closed-form IK kernels
several times faster than small numpy arrays would.  Units are the caller's; every function is
exact algebra (no tolerance) except where it says so.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel

#: the largest |angle| (rad) :func:`wrap` reduces by turns (a double's spacing there is ~1e-4 rad)
WRAP_MAX = 1e12


@kernel
def vec(a):
    """The tuple of a length-3 array (or sequence)."""
    return (float(a[0]), float(a[1]), float(a[2]))


@kernel
def rows6(A):
    """The six rows of a (6, 3) array as tuples (:func:`vec`): the axes h of a 6R arm."""
    return (vec(A[0]), vec(A[1]), vec(A[2]), vec(A[3]), vec(A[4]), vec(A[5]))


@kernel
def rows7(A):
    """The seven rows of a (7, 3) array as tuples (:func:`vec`): the offsets P of a 6R arm, the
    axes h of a 7R arm."""
    return (vec(A[0]), vec(A[1]), vec(A[2]), vec(A[3]), vec(A[4]), vec(A[5]), vec(A[6]))


@kernel
def mat(a):
    """The row tuples of a 3×3 array."""
    return (
        (float(a[0, 0]), float(a[0, 1]), float(a[0, 2])),
        (float(a[1, 0]), float(a[1, 1]), float(a[1, 2])),
        (float(a[2, 0]), float(a[2, 1]), float(a[2, 2])),
    )


@kernel
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@kernel
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@kernel
def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@kernel
def neg(a):
    return (-a[0], -a[1], -a[2])


@kernel
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@kernel
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@kernel
def norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@kernel
def perpendicular(k):
    """A unit vector ⟂ k (k a unit axis): k × e_i for the axis e_i least aligned with k."""
    ax, ay, az = abs(k[0]), abs(k[1]), abs(k[2])
    if ax <= ay and ax <= az:
        v = (0.0, k[2], -k[1])  # k × e_x
    elif ay <= az:
        v = (-k[2], 0.0, k[0])  # k × e_y
    else:
        v = (k[1], -k[0], 0.0)  # k × e_z
    return scale(v, 1.0 / norm(v))


@kernel
def rotate_cs(k, c, s, p):
    """rot(k, θ) p from c = cos θ, s = sin θ (Rodrigues; k a unit axis)."""
    kxp = cross(k, p)
    w = dot(k, p) * (1.0 - c)
    return (
        p[0] * c + kxp[0] * s + k[0] * w,
        p[1] * c + kxp[1] * s + k[1] * w,
        p[2] * c + kxp[2] * s + k[2] * w,
    )


@kernel
def rotate(k, theta, p):
    """rot(k, θ) p (θ in rad, k a unit axis)."""
    return rotate_cs(k, math.cos(theta), math.sin(theta), p)


@kernel
def angle_cs(theta):
    """The pair (cos θ, sin θ) in which the closed-form kernels carry an angle θ (rad): its
    rotation (:func:`anthroarm.ik.subproblems.unit_cs`)."""
    return math.cos(theta), math.sin(theta)


@kernel
def rot_cs(k, c, s):
    """The matrix rot(k, θ) = I + s [k]× + (1 − c) [k]×² from c = cos θ, s = sin θ."""
    v = 1.0 - c
    x, y, z = k
    return (
        (c + x * x * v, x * y * v - z * s, x * z * v + y * s),
        (x * y * v + z * s, c + y * y * v, y * z * v - x * s),
        (x * z * v - y * s, y * z * v + x * s, c + z * z * v),
    )


@kernel
def rot(k, theta):
    return rot_cs(k, math.cos(theta), math.sin(theta))


@kernel
def mv(R, v):
    """R v."""
    return (dot(R[0], v), dot(R[1], v), dot(R[2], v))


@kernel
def mtv(R, v):
    """Rᵀ v."""
    return (
        R[0][0] * v[0] + R[1][0] * v[1] + R[2][0] * v[2],
        R[0][1] * v[0] + R[1][1] * v[1] + R[2][1] * v[2],
        R[0][2] * v[0] + R[1][2] * v[1] + R[2][2] * v[2],
    )


@kernel
def transpose(R):
    return ((R[0][0], R[1][0], R[2][0]), (R[0][1], R[1][1], R[2][1]), (R[0][2], R[1][2], R[2][2]))


@kernel
def mm(A, B):
    """A B."""
    Bt = transpose(B)
    return (
        (dot(A[0], Bt[0]), dot(A[0], Bt[1]), dot(A[0], Bt[2])),
        (dot(A[1], Bt[0]), dot(A[1], Bt[1]), dot(A[1], Bt[2])),
        (dot(A[2], Bt[0]), dot(A[2], Bt[1]), dot(A[2], Bt[2])),
    )


@kernel
def mtm(A, B):
    """Aᵀ B."""
    return mm(transpose(A), B)


@kernel
def wrap(x):
    """x wrapped into (−π, π]; NaN for x not finite or |x| ≥ :data:`WRAP_MAX` (its digits below
    a turn are lost: not an angle to wrap)."""
    if -math.pi < x <= math.pi:
        return x
    if not abs(x) < WRAP_MAX:
        return math.nan
    y = x - 2.0 * math.pi * math.floor((x + math.pi) / (2.0 * math.pi))  # in [−π, π)
    return math.pi if y <= -math.pi else y


# Cephes atan (S. L. Moshier, *Methods and Programs for Mathematical Functions*, 1989; the
# Cephes Math Library, atan.c): atan(u) = u + u z P(z) / Q(z), z = u², |u| ≤ 0.66
_ATAN_P = (
    -8.750608600031904122785e-01,
    -1.615753718733365076637e01,
    -7.500855792314704667340e01,
    -1.228866684490136173410e02,
    -6.485021904942025371773e01,
)
_ATAN_Q = (
    2.485846490142306297962e01,
    1.650270098316988542046e02,
    4.328810604912902668951e02,
    4.853903996359136964868e02,
    1.945506571482613964425e02,
)
#: π/4 as the nearest double and the rest: k π/4 = k HI + k LO (k = 0…4; k HI rounds to the
#: double nearest 3π/4 at k = 3)
_QUARTER_PI_HI = 0.7853981633974483
_QUARTER_PI_LO = 3.061616997868383e-17


@kernel
def atan2(y, x):
    """atan2(y, x) (rad, in [−π, π]) as ``math.atan2`` — its values at zeros of either sign,
    infinities and NaN included — within 2 units in the last place, in branch-free arithmetic
    that a compiled kernel inlines and vectorises (the C library's atan2 is a call of ~20 ns
    here, and the closed-form IK reads 48 angles a pose,
    :func:`anthroarm.ik.classes.branches.angles`).
    Cephes' method: the ratio of the smaller to the larger of |x|, |y| in [0, 1], reduced to
    |u| ≤ 0.42 by u = (t − 1)/(t + 1) above 0.66 (atan t = π/4 + atan u), Cephes' rational
    approximation of atan on it, then the octant: |atan2| = k π/4 ± r (k = 0 … 4, the
    constant's low bits added to r first) and the sign of y."""
    ax, ay = abs(x), abs(y)
    swap = ay > ax
    num, den = (ax, ay) if swap else (ay, ax)
    ratio = num / den
    t = ratio if den != 0.0 else num * 0.0  # 0 at (0, 0); NaN stays NaN
    t = 1.0 if ax == ay == math.inf else t
    big = t > 0.66
    reduced = (t - 1.0) / (t + 1.0)
    u = reduced if big else t
    z = u * u
    p = (((_ATAN_P[0] * z + _ATAN_P[1]) * z + _ATAN_P[2]) * z + _ATAN_P[3]) * z + _ATAN_P[4]
    q = ((((z + _ATAN_Q[0]) * z + _ATAN_Q[1]) * z + _ATAN_Q[2]) * z + _ATAN_Q[3]) * z + _ATAN_Q[4]
    r = u + u * (z * p / q)
    # |atan2| = k π/4 + sign r by octant: k = kb (+ 2 where |y| > |x|; 4 − … where x < 0)
    neg = math.copysign(1.0, x) < 0.0
    kb = 1.0 if big else 0.0
    sign = 1.0 if swap == neg else -1.0
    k = (2.0 if swap else (4.0 if neg else 0.0)) + sign * kb
    a = k * _QUARTER_PI_HI + (k * _QUARTER_PI_LO + sign * r)
    return math.copysign(a, y)


def as_array(t) -> np.ndarray:
    """A tuple vector or matrix as a numpy array (for tests and Python callers)."""
    return np.array(t, dtype=float)


__all__ = [
    "add",
    "angle_cs",
    "as_array",
    "atan2",
    "cross",
    "dot",
    "mat",
    "mm",
    "mtm",
    "mtv",
    "mv",
    "neg",
    "norm",
    "perpendicular",
    "rot",
    "rot_cs",
    "rotate",
    "rotate_cs",
    "scale",
    "sub",
    "transpose",
    "vec",
    "wrap",
]
