"""The Python entries of the geometric IK over a batch of poses: every branch of a class solver
(:func:`solve_class`, :func:`solve`), the verified branches of a closed class in one compiled
call (:func:`solve_verified`) and the solutions of one pose nearest a reference
(:func:`solve_nearest`)."""

from __future__ import annotations

import numpy as np

from ...threads import run_rows
from ..classify import SPHERICAL_TWO_PARALLEL, Kinematics
from ..search.driver import solve_search
from .closed import CLOSED, _closed_loop
from .plan import GeoPlan, ik_geo_P
from .verify import BadPoseError, _verified, _verified_one, held_poses


def solve_class(cls: str, H, P, R06, p, frames=None):
    """Every branch of the class solver ``cls`` in IK-Geo's form (``H`` (6, 3), ``P`` (7, 3),
    ``R06`` (N, 3, 3) = R · R_tool(0)ᵀ, ``p`` (N, 3) the tool positions, base frame, m).
    Returns q (N, B, 6) rad in (−π, π] (NaN on a branch that does not exist), valid (N, B),
    exact (N, B) (False: least squares, out of reach; for a search class also a root whose
    error is above :data:`SEARCH_TOL`), B = :func:`n_branches` (8; 16 for a search class).
    ``frames``: a search class's arm for its Newton polish (``GeoPlan.search_frames``; made from
    H, P if None)."""
    n = len(p)
    H, P = np.ascontiguousarray(H, dtype=float), np.ascontiguousarray(P, dtype=float)
    R06, p = np.ascontiguousarray(R06, dtype=float), np.ascontiguousarray(p, dtype=float)
    if cls in CLOSED:
        q, valid, exact = np.empty((n, 8, 6)), np.empty((n, 8), bool), np.empty((n, 8), bool)
        _closed_loop(CLOSED.index(cls), H, P, R06, p, q, valid, exact)
        return q, valid, exact & valid
    return solve_search(cls, H, P, R06, p, frames=frames)


def class_pose(plan: GeoPlan, T, param=None):
    """The pose the class solver of ``plan`` solves for tool poses ``T`` (N, 4, 4): (R06
    (N, 3, 3), p (N, 3)) in IK-Geo's form — of the reversed chain (T⁻¹) for a reversed class,
    of the first six joints (T · M⁻¹ e^{−ξ7 v} M, ``param`` = v (N,)) for a 7-joint arm."""
    if plan.param_joint is not None:  # T · M⁻¹ e^{−ξ7 v} M (:func:`held_poses`)
        v = np.ascontiguousarray(np.broadcast_to(np.asarray(param, dtype=float), (len(T),)))
        out = np.empty((len(T), 4, 4))
        held_poses(
            np.ascontiguousarray(T, dtype=float),
            np.ascontiguousarray(plan.M, dtype=float),
            np.ascontiguousarray(plan.param_axis, dtype=float),
            np.ascontiguousarray(plan.param_point, dtype=float),
            v,
            out,
        )
        T = out
    R, p = T[:, :3, :3], T[:, :3, 3]
    if plan.reversed:
        R, p = np.swapaxes(R, 1, 2), -np.einsum("nji,nj->ni", R, p)
    return R @ plan.R_tool.T, p


def solve(plan: GeoPlan, T, param=None):
    """Every branch for poses ``T`` (N, 4, 4) of the tool (base frame, m; valid rotations):
    θ (N, B, n) in the order of ``robot.chain.independent`` (rad, (−π, π]), valid, exact
    (B = :func:`n_branches` of the class).

    A 7-joint arm (``plan.param_joint``): ``param`` (N,) the value of its last joint (rad) for
    each pose.  With the last joint's twist ξ7 and M the tool pose at q = 0,
    T = F6(q1…q6) e^{ξ7 v} M, so the first six joints solve the 6R arm (tool M) for the pose
    T · M⁻¹ e^{−ξ7 v} M."""
    T = np.asarray(T, dtype=float)
    R06, p = class_pose(plan, T, param)
    frames = plan.search_frames if plan.cls not in CLOSED else None
    q, valid, exact = solve_class(plan.cls, plan.H, plan.P, R06, p, frames)
    if plan.param_joint is not None:
        v = np.broadcast_to(np.asarray(param, dtype=float), (len(T),))
    if plan.reversed:
        q = q[..., ::-1]
    if plan.param_joint is not None:
        q = np.concatenate(
            [q, np.broadcast_to(np.angle(np.exp(1j * v))[:, None, None], q.shape[:2] + (1,))], -1
        )
    return q[..., plan.order], valid, exact


_ZERO1 = np.zeros(1)


def solve_verified(plan: GeoPlan, T, param=None, tol: float = 1e-9, tol_orthonormal: float = 1e-6):
    """Every branch of a closed class (:data:`CLOSED`) for poses ``T`` (N, 4, 4), in one
    compiled call per batch: the class solver (:func:`solve`), each branch wrapped by 2π into
    the joint limits and checked by the chain's FK (product of exponentials of the joints as
    read from ``robot.chain``, the model Pinocchio holds; :func:`anthroarm.ik.fk.local_frames`).  ``param``
    (N,) the held joint of a 7-joint arm.  Returns θ (N, 8, n) (independent-joint order, rad),
    solution (N, 8), candidate (N, 8), exact (N, 8), inside (N, 8), FK residual (N, 8) (max
    entry of the 3×4 pose; inf where there is no candidate or an exact one outside the limits,
    :func:`_verified`) and the chain's configuration q (N, 8, nq) of each solution (θ itself
    where there is no continuous joint; NaN rows where there is no solution).  Raises
    ``ValueError`` naming the first malformed pose (not finite, last row, not a rotation) —
    ``anthroarm.ik.closed_form`` checks before it calls."""
    T = np.ascontiguousarray(T, dtype=float)
    N, n = len(T), len(plan.fk_axes)
    pv = (
        _ZERO1
        if param is None
        else np.ascontiguousarray(np.broadcast_to(np.asarray(param, float), (N,)))
    )
    if param is None and N > 1:
        pv = np.zeros(N)
    Q, V, E = np.empty((N, 8, n)), np.empty((N, 8), bool), np.empty((N, 8), bool)
    IN, RES, OK = np.empty((N, 8), bool), np.empty((N, 8)), np.empty((N, 8), bool)
    CONF = np.empty((N, 8, 0 if plan.plain else plan.chain.nq))
    cf, ci = plan.packed
    first_bad = []

    def rows(a, b):
        k = _verified(
            cf,
            ci,
            T[a:b],
            pv[a:b],
            tol,
            tol_orthonormal,
            Q[a:b],
            V[a:b],
            E[a:b],
            IN[a:b],
            RES[a:b],
            OK[a:b],
            CONF[a:b],
        )
        if k >= 0:
            first_bad.append(a + k)

    run_rows(rows, N)
    bad = min(first_bad) if first_bad else -1
    if bad >= 0:
        raise BadPoseError(
            bad,
            f"T[{bad}] is not a valid pose (finite, last row [0, 0, 0, 1], rotation part a "
            f"rotation to {tol_orthonormal:g})",
        )
    if not plan.order_is_path:
        Q = Q[..., plan.order]
    return Q, OK, V, E & V, IN, RES, (Q if plan.plain else CONF)


def solve_nearest(cf, ci, T, ref, param: float):
    """The solutions θ (K, n) (independent-joint order, rad) of one pose ``T`` (4, 4) of a
    closed class (``cf``, ``ci``: ``GeoPlan.packed``; default tolerances; ``param`` the held
    7th joint) with the one nearest ``ref`` (n,) first, and that one's position and rotation
    errors (m, rad; :func:`_target_errors`; None, None without a reference: an empty ``ref``)
    — or None where the pose has no solution, is malformed or has a candidate to polish.  The
    seeds of :func:`anthroarm.ik.solve`, one compiled call."""
    n = ci[2]
    out = np.empty((8, n + 4))
    mask = _verified_one.fn(cf, ci, T, param, 1e-9, 1e-6, ref, out)  # .fn: no Python frame
    if mask <= 0:
        return None
    K = mask.bit_count()
    if len(ref) != n:
        return out[:K, :n], None, None
    return out[:K, :n], float(out[0, n + 2]), float(out[0, n + 3])


# ----------------------------------------------------------------------------- the first class solver (from classify, kept for its callers)
def _spherical_wrist_P(kin: Kinematics) -> np.ndarray:
    """IK-Geo's offsets ``P`` (7, 3) of a 6R arm with a spherical wrist, joints 4, 5, 6 slid
    along their axes to the wrist centre (p_45 = p_56 = 0; base frame, m, q = 0)."""
    return ik_geo_P(SPHERICAL_TWO_PARALLEL, kin.H, kin.points, kin.p_tool)


def _solve_spherical_two_parallel(kin: Kinematics, T) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every IK branch of a ``spherical_two_parallel`` 6R arm in the joint order of ``kin``
    (the class solver of :mod:`anthroarm.ik.geometric`, kept for its callers).

    ``T``: (4, 4) or (N, 4, 4) pose of the tool in the base frame (m).  Returns q (N, 8, 6)
    joint angles in (−π, π], ``valid`` (N, 8) and ``exact`` (N, 8) (False: a least-squares
    branch, the pose is out of reach).  No limit filtering and no FK check here."""
    T = np.asarray(T, dtype=float)
    single = T.ndim == 2
    T = T[None] if single else T
    q, valid, exact = solve_class(
        SPHERICAL_TWO_PARALLEL,
        kin.H,
        _spherical_wrist_P(kin),
        T[:, :3, :3] @ kin.R_tool.T,
        T[:, :3, 3],
    )
    if single:
        return q[0], valid[0], exact[0]
    return q, valid, exact
