"""Spanning trees + closure lists of the mechanisms,
for :class:`~anthroarm.mechanisms.closed_loop.ClosedLoop`.

Each builder returns a :class:`LoopSpec`; ``ClosedLoop(spec)`` loads its URDF in Pinocchio.
Joint names give the book's variables:

* four-bar: ``crank`` = theta2 (absolute), ``coupler`` = theta3 - theta2, ``rocker`` = theta4;
  closure B (coupler end) = B (rocker end), planar (x, y);
* RSSR: ``crank`` = alpha, ball ``ball_a`` at a, ``rocker`` = beta; closure at b;
* RRSS: ``r1`` = theta1, ``r2`` = theta2 (about u_a), S-S bar as ball ``ball_b0`` at b0; closure at
  b.

The reference configuration q = 0 of the spatial trees is the mechanism's initial pose (a1, b1),
which closes the loop, so the Pinocchio solution is found by continuation from q = 0 —
independently of the closed forms.
"""

from __future__ import annotations

import numpy as np

from .closed_loop import Closure, LoopSpec, TreeJoint, origin

__all__ = ["fourbar_spec", "rssr_spec", "rrss_spec", "frame_with_z"]


def frame_with_z(z) -> np.ndarray:
    """A rotation matrix whose third column is the unit vector ``z`` (any completion)."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    t = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(t, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def fourbar_spec(r1, r2, r3, r4) -> LoopSpec:
    """Planar four-bar of Fig. 5-1 as a tree about z: ground -crank- A -coupler- B; ground -rocker-
    B."""
    return LoopSpec(
        name="fourbar",
        joints=(
            TreeJoint("crank", "ground", "crank"),
            TreeJoint("coupler", "crank", "coupler_link", origin=origin((r2, 0, 0))),
            TreeJoint("rocker", "ground", "rocker_link", origin=origin((r1, 0, 0))),
        ),
        closures=(Closure("B_coupler", "B_rocker", components=(0, 1)),),
        inputs=("crank",),
        sites=(
            ("B_coupler", "coupler_link", origin((r3, 0, 0))),
            ("B_rocker", "rocker_link", origin((r4, 0, 0))),
        ),
        length_scale=float(r1 + r2 + r3 + r4),
    )


def _axis_frame(u):
    """Joint frame rotation whose z axis is u (the URDF joint then turns about its z)."""
    return frame_with_z(u)


def rssr_spec(geom) -> LoopSpec:
    """RSSR (002 §4-2) tree: ground -R(ua at a0)- crank -ball(a1)- coupler; ground -R(ub at b0)-
    rocker."""
    Ra, Rb = _axis_frame(geom.ua), _axis_frame(geom.ub)
    Rball = frame_with_z(geom.ua)  # the coupler turns mostly about ua relative to the crank
    return LoopSpec(
        name="rssr",
        joints=(
            TreeJoint("crank", "ground", "crank_link", origin=origin(geom.a0, Ra)),
            TreeJoint(
                "ball_a",
                "crank_link",
                "coupler_link",
                "ball",
                origin=origin(Ra.T @ (geom.a1 - geom.a0), Ra.T @ Rball),
            ),
            TreeJoint("rocker", "ground", "rocker_link", origin=origin(geom.b0, Rb)),
        ),
        closures=(Closure("b_coupler", "b_rocker"),),
        inputs=("crank",),
        sites=(
            ("b_coupler", "coupler_link", origin(Rball.T @ (geom.b1 - geom.a1))),
            ("b_rocker", "rocker_link", origin(Rb.T @ (geom.b1 - geom.b0))),
        ),
        length_scale=geom.length_scale,
    )


def rrss_spec(geom) -> LoopSpec:
    """RRSS tree: ground -R(u0 at a0)- R1 -R(u1 at a1)- R2; ground -ball(b0)- S-S bar; closure at
    b."""
    R0, R1 = _axis_frame(geom.u0), _axis_frame(geom.u1)
    Rbar = frame_with_z(geom.b1 - geom.b0)  # the bar's passive spin is about its own line
    return LoopSpec(
        name="rrss",
        joints=(
            TreeJoint("r1", "ground", "R1", origin=origin(geom.a0, R0)),
            TreeJoint("r2", "R1", "R2", origin=origin(R0.T @ (geom.a1 - geom.a0), R0.T @ R1)),
            TreeJoint("ball_b0", "ground", "bar", "ball", origin=origin(geom.b0, Rbar)),
        ),
        closures=(Closure("b_R2", "b_bar"),),
        inputs=("r1",),
        sites=(
            ("b_R2", "R2", origin(R1.T @ (geom.b1 - geom.a1))),
            ("b_bar", "bar", origin(Rbar.T @ (geom.b1 - geom.b0))),
        ),
        length_scale=geom.length_scale,
    )
