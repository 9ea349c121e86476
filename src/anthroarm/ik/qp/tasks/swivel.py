"""Elbow swivel angle of a 7-DOF anthropomorphic arm and a task that holds it.

With the hand pose fixed, a 7-DOF arm (3 shoulder, 1 elbow, 3 wrist joints) keeps one degree of
freedom: the elbow E can turn on a circle about the shoulder–wrist axis S→W.  The *swivel angle*
φ (Kreutz-Delgado, Long & Seraji, "Kinematic analysis of 7-DOF manipulators", IJRR 11(5), 1992)
measures where E sits on that circle.  We define it, in the world frame, as the signed angle about
u = (W − S)/|W − S| from the reference direction r (projected onto the plane ⟂ u) to the elbow
offset p = E − S (projected too):

    a = u · (r × p),   b = r · p − (r · u)(u · p),   φ = atan2(a, b).

φ = 0: the elbow is as close to r as it can be (default r = −z, "elbow down", the relaxed human
posture of :mod:`anthroarm.models.human`); φ > 0 turns it counter-clockwise about S→W.
The gradient is analytic (tested against finite differences):

    ∂a/∂p = u × r,     ∂b/∂p = r − (r·u) u,
    ∂a/∂u = r × p,     ∂b/∂u = −(u·p) r − (r·u) p,     ∂u/∂d = (I − u uᵀ)/|d|,  d = W − S,
    ∂φ = (b ∂a − a ∂b)/(a² + b²).

Units: rad; Jacobian 1 × nv (rad per rad).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ....chain import REVOLUTE
from ..configuration import IKConfiguration
from .base import Task

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _joint_origins(chain) -> dict:
    """World position (m) of every joint origin at θ = 0, from the chain's placements."""
    T = {-1: np.eye(4)}
    for j in chain.joints:  # parents come first (Pinocchio's order)
        T[j.index] = T[j.parent] @ j.placement
    return {i: M[:3, 3] for i, M in T.items() if i >= 0}


def human_layout(chain, frame=None) -> tuple[str, str, str] | None:
    """(shoulder, elbow, wrist) joint frames of a human-like arm, read from the geometry of
    ``chain`` (no names): the revolute joints on the path to ``frame`` (default the tool)
    whose origins coincide form exactly three groups, the first of three joints (a spherical
    shoulder), then the elbow, then the wrist; each group is named by its first joint.
    ``None`` for any other layout (an offset elbow or wrist, six joints on a line ...)."""
    origins = _joint_origins(chain)
    path = [chain.joints[i] for i in chain.path(frame)]
    if any(j.kind != REVOLUTE or j.is_mimic for j in path):
        return None
    scale = 1.0 + max((float(np.linalg.norm(p)) for p in origins.values()), default=0.0)
    groups: list[list] = []
    for j in path:
        if (
            groups
            and np.linalg.norm(origins[j.index] - origins[groups[-1][0].index]) <= 1e-9 * scale
        ):
            groups[-1].append(j)
        else:
            groups.append([j])
    if len(groups) != 3 or len(groups[0]) != 3:
        return None
    names = tuple(g[0].name for g in groups)
    if not all(chain.frame(n).joint == g[0].index for n, g in zip(names, groups)):
        return None  # a joint frame named differently from its joint
    return names


def swivel_frames(robot, frames=None) -> tuple[str, str, str]:
    """(shoulder, elbow, wrist) frame names: ``frames`` if given, else the human-like layout
    found in ``robot.chain`` (:func:`human_layout`).

    Raises ``ValueError`` for a robot without such a layout (pass ``frames=``)."""
    if frames is not None:
        if len(frames) != 3:
            raise ValueError(f"swivel frames must be (shoulder, elbow, wrist), got {frames!r}")
        for f in frames:
            robot.frame_id(f)  # UnknownFrameError lists the valid ones
        return tuple(frames)
    names = human_layout(robot.chain)
    if names is None:
        raise ValueError(
            f"{robot.name}: no human-like (shoulder, elbow, wrist) layout on the path to "
            f"{robot.chain.tool!r} (three co-located shoulder joints, then elbow and wrist joints "
            "with common origins); pass frames=(shoulder, elbow, wrist) from "
            f"{', '.join(robot.frame_names)}"
        )
    return names


def swivel_from_points(S, E, W, ref=(0.0, 0.0, -1.0)):
    """Swivel angle φ (rad) and its gradients (dφ/dS, dφ/dE, dφ/dW), each (3,), world frame.

    Raises ``ValueError`` when it is undefined: S = W, or the elbow (or ``ref``) lies on the
    shoulder–wrist axis (straight arm)."""
    S, E, W, r = (np.asarray(x, dtype=float) for x in (S, E, W, ref))
    d = W - S
    nd = float(np.linalg.norm(d))
    if nd < 1e-12:
        raise ValueError("swivel angle undefined: wrist coincides with shoulder")
    u = d / nd
    p = E - S
    a = float(u @ np.cross(r, p))
    b = float(r @ p - (r @ u) * (u @ p))
    n2 = a * a + b * b
    if n2 < 1e-24:
        raise ValueError(
            "swivel angle undefined: the elbow (or the reference direction) lies on the "
            "shoulder-wrist axis (straight arm)"
        )
    phi = float(np.arctan2(a, b))
    da_dp = np.cross(u, r)
    db_dp = r - (r @ u) * u
    da_du = np.cross(r, p)
    db_du = -(u @ p) * r - (r @ u) * p
    g_p = (b * da_dp - a * db_dp) / n2
    g_u = (b * da_du - a * db_du) / n2
    g_d = (g_u - (g_u @ u) * u) / nd
    return phi, (-g_p - g_d, g_p, g_d)


def swivel_basis(n, ref=(0.0, 0.0, -1.0)):
    """Unit vectors (u, v) ⊥ the shoulder–wrist axis n (..., 3): u = ``ref`` projected onto the
    plane ⊥ n (φ = 0), falling back to −y where n is parallel to ``ref`` (a vertical arm with
    the default ``ref``); v = n × u.  The closed form (:mod:`anthroarm.ik.closed_form`) places
    the elbow at d = cos φ u + sin φ v, so it and :func:`swivel_angle` share one definition."""
    n = np.asarray(n, dtype=float)
    r = np.broadcast_to(np.asarray(ref, dtype=float), n.shape)
    u = r - np.einsum("...i,...i->...", r, n)[..., None] * n
    nu = np.linalg.norm(u, axis=-1)
    vert = nu < 1e-9
    if np.any(vert):
        r2 = np.array([0.0, -1.0, 0.0])
        u2 = r2 - np.einsum("...i,i->...", n, r2)[..., None] * n
        u = np.where(vert[..., None], u2, u)
        nu = np.linalg.norm(u, axis=-1)
    u = u / nu[..., None]
    return u, np.cross(n, u)


def swivel_angle(robot, q, frames=None, ref=(0.0, 0.0, -1.0)):
    """Swivel angle φ (rad) of ``robot`` at ``q`` (nq,) -> float or (N, nq) -> (N,): the angle of
    the elbow offset d about the shoulder–wrist axis n, from u towards v (:func:`swivel_basis`;
    φ = atan2(d·v, d·u), the definition of the module docstring).  d is the elbow's offset from
    the axis, E − S projected ⊥ n; for a straight elbow (E on the axis) d = n × a_E with a_E
    the elbow joint's axis, so that φ stays defined (the closed form's convention).
    ``frames`` = (shoulder, elbow, wrist),
    default :func:`~anthroarm.ik.qp.tasks.swivel.swivel_frames`."""
    names = swivel_frames(robot, frames)
    q = robot.check_q(q)
    Q = np.atleast_2d(q)
    T = [robot.fk(Q, f) if len(Q) > 1 else robot.fk(Q[0], f)[None] for f in names]
    S, E, W = (t[:, :3, 3] for t in T)
    n = W - S
    n = n / np.linalg.norm(n, axis=1)[:, None]
    p = E - S
    d = p - np.einsum("ni,ni->n", p, n)[:, None] * n
    straight = np.linalg.norm(d, axis=1) <= 1e-9 * (1.0 + np.linalg.norm(p, axis=1))
    if np.any(straight):
        axis = robot.chain.joints[robot.chain.frame(names[1]).joint].axis
        aE = np.einsum("nij,j->ni", T[1][:, :3, :3], axis)
        d = np.where(straight[:, None], np.cross(n, aE), d)
    u, v = swivel_basis(n, ref)
    phi = np.arctan2(np.einsum("ni,ni->n", d, v), np.einsum("ni,ni->n", d, u))
    return phi if q.ndim == 2 else float(phi[0])


class SwivelTask(Task):
    """Hold the elbow swivel angle at ``target`` (rad).

    Residual e = wrap(φ(q) − φ*) (1,), Jacobian ∂φ/∂q = Σ_X (∂φ/∂X) J_X(q) over the position
    Jacobians (LOCAL_WORLD_ALIGNED, linear rows) of the shoulder, elbow and wrist frames:
    ``frames=(shoulder, elbow, wrist)``, by default the human-like layout found in
    ``robot.chain`` (:func:`~anthroarm.ik.qp.tasks.swivel.swivel_frames`)."""

    def __init__(
        self,
        robot,
        target: float = 0.0,
        cost: float = 1.0,
        frames=None,
        ref=(0.0, 0.0, -1.0),
        gain: float = 1.0,
        lm_damping: float = 0.0,
    ):
        super().__init__(cost=cost, gain=gain, lm_damping=lm_damping)
        names = swivel_frames(robot, frames)
        self.frame_ids = tuple(robot.frame_id(f) for f in names)
        self.ref = np.asarray(ref, dtype=float)
        self.set_target(target)

    def set_target(self, target: float) -> None:
        target = float(target)
        if not np.isfinite(target):
            raise ValueError(f"swivel target must be finite, got {target}")
        self.target = target

    def _geometry(self, conf: IKConfiguration):
        pts = [conf.frame_placement(f).translation for f in self.frame_ids]
        return swivel_from_points(*pts, ref=self.ref)

    def compute_error(self, conf: IKConfiguration) -> np.ndarray:
        phi, _ = self._geometry(conf)
        return np.array([np.arctan2(np.sin(phi - self.target), np.cos(phi - self.target))])

    def compute_jacobian(self, conf: IKConfiguration) -> np.ndarray:
        _, grads = self._geometry(conf)
        J = np.zeros((1, conf.nv))
        for g, f in zip(grads, self.frame_ids):
            J[0] += g @ conf.frame_jacobian(f, LWA)[:3]
        return J
