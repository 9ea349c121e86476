"""MarkerTask: drive body-fixed points (skin markers) to measured positions (world frame, m).

For markers k = 1 … M, each fixed in the frame of joint j(k) at l_k (m)::

    e_k(q) = p_k(q) − m_k,   p_k = ⁰R_j l_k + ⁰o_j,
    J_k(q) = J_v,j + J_ω,j × (p_k − ⁰o_j)     (LOCAL_WORLD_ALIGNED: the point's velocity in
                                               world axes; computed as the WORLD-frame columns
                                               v_O + ω × p_k of the joints above the body)

and the cost of marker k's three rows is √w_k, so that the task's objective is the marker-IK
residual ½ Σ w_k ‖J_k Δq + e_k‖² (OpenSim's IK tool minimises the same weighted sum of squared
marker errors, Delp et al. 2007, IEEE TBME 54(11), 1940–1950).  A marker that is missing in a
frame gets weight 0 (its rows drop out), which is how gaps are handled.

Unlike :class:`~anthroarm.ik.qp.tasks.PositionTask` (the origin of one frame), this task takes
any number of points at offsets in their bodies and evaluates them in one pass over the bodies
that carry them and one read of the world-frame joint Jacobian (``data.J``).
"""

from __future__ import annotations

import numpy as np

from .base import Task


def moved_by(chain, joints) -> np.ndarray:
    """(M, nv) bool: ``[k, v]`` is True when velocity v moves the body of joint ``joints[k]``
    (index in ``chain.joints``, −1: the base, moved by none): v's joint is on the path from the
    base to that body; a mimic joint counts as its source's velocity."""
    out = np.zeros((len(joints), chain.nv), dtype=bool)
    for k, j in enumerate(joints):
        i = int(j)
        while i >= 0:
            jt = chain.joints[i]
            src = chain.joints[jt.mimic.source] if jt.is_mimic else jt
            out[k, src.idx_v : src.idx_v + src.nv] = True
            i = jt.parent
    return out


class MarkerTask(Task):
    """Position task on M body-fixed points.

    Parameters
    ----------
    robot : anthroarm.Robot
    joints : (M,) int
        Index in ``robot.chain.joints`` of the joint whose body carries each marker (−1: fixed
        to the base; such a marker has a zero Jacobian).
    local : (M, 3)
        Marker positions in those joint frames, m.
    weights : (M,) optional
        w_k ≥ 0 (default 1); the rows of marker k get cost √w_k.
    """

    def __init__(
        self, robot, joints, local, weights=None, gain: float = 1.0, lm_damping: float = 0.0
    ):
        joints = np.asarray(joints, dtype=int)
        local = np.asarray(local, dtype=float)
        M = joints.shape[0]
        if local.shape != (M, 3) or not np.isfinite(local).all():
            raise ValueError(f"local must be a finite ({M}, 3) array (m), got shape {local.shape}")
        w = np.ones(M) if weights is None else np.asarray(weights, dtype=float)
        if w.shape != (M,) or not np.isfinite(w).all() or np.any(w < 0):
            raise ValueError(f"weights must be {M} finite numbers >= 0")
        super().__init__(cost=np.repeat(np.sqrt(w), 3), gain=gain, lm_damping=lm_damping)
        self.model = robot.model
        self.nv = robot.nv
        self.joints = joints
        self.local = local
        self.base_weights = w
        self.target = np.zeros((M, 3))
        self.visible = np.ones(M, dtype=bool)
        self._bodies = [int(b) for b in np.unique(joints) if b >= 0]
        self._gidx = np.array(
            [self._bodies.index(int(j)) if j >= 0 else 0 for j in joints], dtype=int
        )
        self._fixed = np.flatnonzero(joints < 0)
        self._mask = moved_by(robot.chain, joints).astype(float)
        self._R = np.zeros(
            (max(len(self._bodies), 1), 3, 3)
        )  # one slot when every marker is on the base
        self._o = np.zeros((max(len(self._bodies), 1), 3))
        self._p = np.zeros((M, 3))
        self._J = np.zeros((M, 3, robot.model.nv))  # Pinocchio's velocities (× G: coordinates)
        self._for = (None, b"")  # (configuration, its q's bytes) the cache below was computed for

    def set_target(self, positions, visible=None) -> None:
        """Measured positions (M, 3), m, world frame.  Rows that are NaN, or False in
        ``visible``, are missing: weight 0 in this frame."""
        P = np.asarray(positions, dtype=float)
        if P.shape != self.target.shape:
            raise ValueError(f"marker targets must have shape {self.target.shape}, got {P.shape}")
        vis = np.isfinite(P).all(axis=1)
        if visible is not None:
            vis &= np.asarray(visible, dtype=bool)
        self.visible = vis
        self.target = np.where(vis[:, None], P, 0.0)
        self.cost = np.repeat(np.sqrt(self.base_weights * vis), 3)

    def _update(self, conf) -> None:
        # one pass: the bodies' placements, then every marker at once from the world-frame joint
        # Jacobian of computeJointJacobians (data.J: column v = (v_O; ω) of joint v's motion, v_O
        # the velocity of the point at the world origin), J_k = mask_k · (v_O + ω × p_k)
        key = conf.q.tobytes()  # by value: a q changed in place and update() must not hit the cache
        if self._for[0] is conf and self._for[1] == key:
            return
        data = conf.data
        R, o = self._R, self._o
        for i, b in enumerate(self._bodies):
            Mi = data.oMi[b + 1]
            R[i] = Mi.rotation
            o[i] = Mi.translation
        g = self._gidx
        p = np.einsum("mij,mj->mi", R[g], self.local) + o[g]
        Jw = data.J
        lin, ang = Jw[:3], Jw[3:]
        px, py, pz = p[:, 0:1], p[:, 1:2], p[:, 2:3]
        J, mask = self._J, self._mask
        np.multiply(lin[0] + ang[1] * pz - ang[2] * py, mask, out=J[:, 0])
        np.multiply(lin[1] + ang[2] * px - ang[0] * pz, mask, out=J[:, 1])
        np.multiply(lin[2] + ang[0] * py - ang[1] * px, mask, out=J[:, 2])
        if self._fixed.size:
            p[self._fixed] = self.local[self._fixed]
        self._p = p
        self._for = (conf, key)

    def positions(self, conf) -> np.ndarray:
        """(M, 3) world positions of the markers at ``conf`` (m)."""
        self._update(conf)
        return self._p.copy()

    def compute_error(self, conf) -> np.ndarray:
        """(3M,) p(q) − m, m (zero rows where a marker is missing)."""
        self._update(conf)
        return np.where(self.visible[:, None], self._p - self.target, 0.0).ravel()

    def compute_jacobian(self, conf) -> np.ndarray:
        """(3M, nv), LOCAL_WORLD_ALIGNED point Jacobians stacked marker by marker (J G in the
        coordinates of a model with a coupling, G = dφ/dq)."""
        self._update(conf)
        J = self._J.reshape(-1, self._J.shape[2])
        G = getattr(conf, "G", None)
        return J if G is None else J @ G
