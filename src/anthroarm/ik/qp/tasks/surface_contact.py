"""SurfaceContactTask: a frame's origin on a smooth surface, an axis of the frame against the
surface normal there (a fingertip that may slide on the object).

The surface is given by its signed distance φ(p) (m, positive outside), its outward unit normal
m(p) = ∇φ(p) and the normal's derivative N(p) = ∂m/∂p (1/m), e.g. a sphere or a cylinder of
:mod:`anthroarm.hand.objects`.  With p(q) the frame's origin and a the pad axis in the frame
(unit), the residual (4 rows: m, then unitless) and its Jacobian are::

    e(q) = [ φ(p) ; R a + m(p) ],     J(q) = [ m(p)ᵀ ⁰J_v ; −[R a]ₓ ⁰J_ω + N(p) ⁰J_v ]

(⁰J_v, ⁰J_ω: linear and angular rows of the LOCAL_WORLD_ALIGNED frame Jacobian).  The first
row is the exact gradient of the distance; the second block is
:class:`~anthroarm.ik.qp.tasks.contact_normal.ContactNormalTask` with a target −m(p) that
moves with the contact point (its derivative included), so the contact point is free on the
surface: the task only asks for *a* contact, not a given point.  ``cost`` is
(distance_cost, normal_cost, normal_cost, normal_cost).  For a sphere of centre c and radius r:
φ = ‖p − c‖ − r, m = (p − c)/ρ, N = (I − m mᵀ)/ρ with ρ = ‖p − c‖; for a cylinder of axis
(c, u): the same in the plane normal to u, N = (I − u uᵀ − m mᵀ)/ρ.
"""

from __future__ import annotations

import numpy as np

from ..configuration import LWA
from .base import Task
from .contact_normal import cross_matrix, unit_vector


class SurfaceContactTask(Task):
    """Contact of ``frame`` (origin and pad ``axis``) with ``surface`` (see the module
    docstring).

    Parameters
    ----------
    robot : anthroarm.Robot
    frame : str or int
        The contact frame (a fingertip).
    surface : object
        Has ``distance(p)`` (float, m), ``normal(p)`` (3,) and ``normal_jacobian(p)`` (3, 3),
        p in world coordinates (m).
    axis : array (3,)
        Pad normal in the frame's axes (normalised).
    distance_cost : float
        Weight of the distance row ([cost]/m).
    normal_cost : float
        Weight of the three normal rows ([cost] per unit).
    """

    def __init__(
        self,
        robot,
        frame,
        surface,
        axis=(0.0, 0.0, 1.0),
        distance_cost: float = 1.0,
        normal_cost: float = 0.1,
        gain: float = 1.0,
        lm_damping: float = 0.0,
    ):
        super().__init__(
            cost=np.array([distance_cost, normal_cost, normal_cost, normal_cost], dtype=float),
            gain=gain,
            lm_damping=lm_damping,
        )
        for attr in ("distance", "normal", "normal_jacobian"):
            if not callable(getattr(surface, attr, None)):
                raise TypeError(
                    f"SurfaceContactTask: surface must have a {attr}(p) method, got {surface!r}"
                )
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.chain.frame(self.frame_id).name
        self.surface = surface
        self.axis = unit_vector(axis, "SurfaceContactTask axis")

    def __repr__(self) -> str:
        return f"SurfaceContactTask({self.frame!r}, {self.surface!r}, cost={self.cost.tolist()})"

    def compute_error(self, conf) -> np.ndarray:
        M = conf.frame_placement(self.frame_id)
        p = M.translation
        out = np.empty(4)
        out[0] = self.surface.distance(p)
        out[1:] = M.rotation @ self.axis + self.surface.normal(p)
        return out

    def compute_jacobian(self, conf) -> np.ndarray:
        M = conf.frame_placement(self.frame_id)
        p = M.translation
        J6 = conf.frame_jacobian(self.frame_id, LWA)
        Jv, Jw = J6[:3], J6[3:]
        out = np.empty((4, conf.nv))
        out[0] = self.surface.normal(p) @ Jv
        out[1:] = -cross_matrix(M.rotation @ self.axis) @ Jw + self.surface.normal_jacobian(p) @ Jv
        return out
