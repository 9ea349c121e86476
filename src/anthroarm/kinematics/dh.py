"""The book's H-D chain, Eq. (6-12)–(6-14) and (6-24)–(6-29), vectorised over configurations.

``A_ij = Rz(θ_j) Tz(s_i) Tx(h_j) Rx(α_ij)`` (classic, distal DH).  Frame 0 is the book's fixed
base frame; the hand pose is ``A_01 A_12 … A_{n−1,n} · T_tool`` (Eq. (6-13), with the hand point
at (0, 0, P) in the last frame).  All functions take ``q`` of shape ``(n,)`` or ``(N, n)`` and
return arrays with the same leading shape.  Units: m, rad.
"""

from __future__ import annotations

import numpy as np

# the checks of joint values and parameters, shared with the printed forms of the catalog
from ..models.spec import as_batch as _as_batch
from ..models.spec import finite_params as finite_params


def dh_transform(theta, s, h, alpha) -> np.ndarray:
    """Eq. (6-12): the 4×4 matrix A(s, h, θ, α), broadcast over array arguments (rad, m).

    Returns shape ``broadcast(theta, s, h, alpha).shape + (4, 4)``; ``ValueError`` naming the
    argument that holds a NaN/inf."""
    args = {"theta": theta, "s": s, "h": h, "alpha": alpha}
    for name, x in args.items():
        if not np.all(np.isfinite(np.asarray(x, float))):
            raise ValueError(f"dh_transform: {name} must be finite, got {np.asarray(x).tolist()}")
    return _dh_transform(theta, s, h, alpha)


def _dh_transform(theta, s, h, alpha) -> np.ndarray:
    theta, s, h, alpha = np.broadcast_arrays(*(np.asarray(x, float) for x in (theta, s, h, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    A = np.zeros(theta.shape + (4, 4))
    A[..., 0, 0] = ct
    A[..., 0, 1] = -st * ca
    A[..., 0, 2] = st * sa
    A[..., 0, 3] = h * ct
    A[..., 1, 0] = st
    A[..., 1, 1] = ct * ca
    A[..., 1, 2] = -ct * sa
    A[..., 1, 3] = h * st
    A[..., 2, 1] = sa
    A[..., 2, 2] = ca
    A[..., 2, 3] = s
    A[..., 3, 3] = 1.0
    return A


_ROW_FIELDS = ("alpha", "s", "h", "theta", "offset")


def _check_rows(rows) -> None:
    """``ValueError`` naming the first DH row parameter that is NaN/inf (one vector test)."""
    vals = np.array([[getattr(r, k) for k in _ROW_FIELDS] for r in rows], dtype=float)
    if not np.isfinite(vals).all():
        j, k = np.argwhere(~np.isfinite(vals))[0]
        raise ValueError(f"row {j + 1} {_ROW_FIELDS[k]} must be finite, got {vals[j, k]}")


def _row_values(rows, q2: np.ndarray, j: int):
    r = rows[j]
    if r.kind == "R":
        return q2[:, j] + r.offset, np.full(q2.shape[0], r.s)
    return np.full(q2.shape[0], r.theta), q2[:, j] + r.offset


def dh_frames(rows, q, tool=None) -> np.ndarray:
    """All frames of the chain: ``F[..., k]`` is the pose of DH frame k in frame 0
    (k = 0 … n; frame 0 is the identity), and ``F[..., n+1]`` the tool if ``tool`` is given.

    Eq. (6-14): ``T_0k = A_01 A_12 … A_{k−1,k}``.  Shape ``(N, n+1[+1], 4, 4)``."""
    n = len(rows)
    q2, single = _as_batch(q, n)
    _check_rows(rows)
    N = q2.shape[0]
    F = np.empty((N, n + 1 + (tool is not None), 4, 4))
    F[:, 0] = np.eye(4)
    for j, r in enumerate(rows):
        theta, s = _row_values(rows, q2, j)
        A = _dh_transform(theta, s, r.h, r.alpha)
        F[:, j + 1] = F[:, j] @ A
    if tool is not None:
        tool = np.asarray(tool, float)
        if tool.shape != (4, 4) or not np.all(np.isfinite(tool)):
            raise ValueError(f"tool must be a finite 4x4 matrix, got {tool.tolist()}")
        F[:, n + 1] = F[:, n] @ tool
    return F[0] if single else F


def dh_fk(rows, q, tool=None) -> np.ndarray:
    """Hand pose ``T_0n · tool`` (Eq. (6-13)), shape (4, 4) or (N, 4, 4)."""
    F = dh_frames(rows, q, tool if tool is not None else np.eye(4))
    return F[..., -1, :, :]


def dh_jacobian(rows, q, tool=None) -> np.ndarray:
    """Geometric Jacobian of the hand point, Eq. (6-24)–(6-29) in vector form.

    Joint j moves about / along ``z_{j−1}`` through ``o_{j−1}`` (the book's convention):
    column j is ``(z_{j−1} × (p − o_{j−1}); z_{j−1})`` for a revolute joint and ``(z_{j−1}; 0)``
    for a prismatic one.  Frame: LOCAL_WORLD_ALIGNED (velocity of the hand point and angular
    velocity, both in base axes).  Shape (6, n) or (N, 6, n)."""
    F = dh_frames(rows, q, tool if tool is not None else np.eye(4))
    single = F.ndim == 3
    if single:
        F = F[None]
    n = len(rows)
    p = F[:, -1, :3, 3]
    z = F[:, :n, :3, 2]  # z_{j-1}, j = 1..n
    o = F[:, :n, :3, 3]
    J = np.zeros((F.shape[0], 6, n))
    revolute = np.array([r.kind == "R" for r in rows])
    lin = np.cross(z, p[:, None, :] - o)
    J[:, :3, :] = np.where(revolute[None, None, :], lin.transpose(0, 2, 1), z.transpose(0, 2, 1))
    J[:, 3:, :] = np.where(revolute[None, None, :], z.transpose(0, 2, 1), 0.0)
    return J[0] if single else J
