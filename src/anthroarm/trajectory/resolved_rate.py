"""Velocity control / resolved rate (book §7-7), Eqs. (7-87)–(7-96).

The hand velocity ṡ = (v; ω) is expressed in the hand frame (7-87), ṡ = J(θ) θ̇ (7-88) with the
hand-frame Jacobian (7-94) (:func:`anthroarm.ik.book_jacobians.hand_frame_jacobian`), and
θ̇ = J⁻¹ ṡ (7-89) (pseudo-inverse for a redundant arm).  A move from the current pose to a target
pose in time T uses the constant base-frame velocity (b17(θf) − b17(θi))/T rotated into the hand
frame, v = C17(θ)ᵀ [b17(θf) − b17(θi)] / T (7-95), and θ = θi + ∫ θ̇ dt (7-96; the book prints
θ1 for θi).  The book gives no ω law; we complete it with the constant base-frame angular
velocity log(C_f C_iᵀ)/T, rotated likewise (the geodesic rotation).

``closed_loop=False`` integrates open loop exactly as the book (Euler steps): integration drift
is not corrected.  ``closed_loop=True`` adds a proportional correction towards the reference
pose on the straight line, gain ``k`` (1/s).  Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .. import input_checks as _check
from ..errors import ControlError
from ..ik.book_jacobians import hand_frame_jacobian


@dataclass
class LineMotionResult:
    """``t`` (K,), ``q`` (K, n), ``p`` (K, 3) hand positions; ``line_deviation`` max distance (m)
    of the hand from the straight segment; ``final_pos_err`` (m) / ``final_rot_err`` (rad) at t = T;
    ``pos_err`` (K,) distance from the reference point on the line at each time."""

    t: np.ndarray
    q: np.ndarray
    p: np.ndarray
    pos_err: np.ndarray
    line_deviation: float
    final_pos_err: float
    final_rot_err: float


def straight_line_move(
    robot,
    q_start,
    T_goal,
    duration: float,
    dt: float,
    *,
    closed_loop: bool = False,
    k: float = 20.0,
    jacobian: str = "book",
) -> LineMotionResult:
    """Move the tool on a straight line to ``T_goal`` in ``duration`` s by resolved rate
    (7-89)/(7-95)/(7-96).

    ``jacobian="book"`` uses the hand-frame Jacobian (7-94) built from joint axes and lever arms;
    ``"pinocchio"`` uses Pinocchio's LOCAL frame Jacobian (they are equal; tested).

    Raises :class:`~anthroarm.errors.ControlError` (a ``ValueError``) for a bad pose,
    ``duration``, ``dt``, ``k`` or ``jacobian``, for a move of more Euler steps than the step
    budget (``duration / dt`` > :data:`anthroarm.input_checks.MAX_STEPS`), and when the
    Jacobian is singular on the way (7-89 needs its inverse)."""
    q = robot.check_q(q_start, "q_start").copy()
    Tg = _check.array(T_goal, "T_goal")
    if Tg.shape != (4, 4):
        raise ControlError(f"T_goal must be a finite 4x4 pose, got shape {Tg.shape}")
    duration = _check.positive(duration, "duration (s)")
    dt = _check.positive(dt, "dt (s)")
    if dt > duration:
        raise ControlError(f"need 0 < dt <= duration, got dt={dt}, duration={duration}")
    k = _check.nonnegative(k, "k (1/s)")
    if jacobian not in ("book", "pinocchio"):
        raise ControlError(f"jacobian must be 'book' or 'pinocchio', got {jacobian!r}")
    n = _check.steps(
        round(duration / dt),
        f"straight_line_move(duration={duration:g} s, dt={dt:g} s)",
        "give a larger dt",
    )
    Ti = robot.fk(q)
    pi, pf = Ti[:3, 3].copy(), Tg[:3, 3]
    Ri, Rf = Ti[:3, :3].copy(), Tg[:3, :3]
    v_w = (pf - pi) / duration  # base-frame, constant (7-95)
    w_w = pin.log3(Rf @ Ri.T) / duration  # base-frame geodesic rate
    ts, Q, P, E = [0.0], [q.copy()], [pi.copy()], [0.0]
    for i in range(n):
        t = i * dt
        T = robot.fk(q)
        C17 = T[:3, :3]
        v, w = v_w, w_w
        if closed_loop:
            s = t / duration
            p_ref = pi + s * (pf - pi)
            R_ref = Ri @ pin.exp3(s * pin.log3(Ri.T @ Rf))
            v = v + k * (p_ref - T[:3, 3])
            w = w + k * pin.log3(R_ref @ C17.T)
        sdot = np.concatenate([C17.T @ v, C17.T @ w])  # hand-frame twist (7-87)
        J = (
            hand_frame_jacobian(robot, q)
            if jacobian == "book"
            else robot.jacobian(q, reference="LOCAL")
        )
        try:
            qd = (
                np.linalg.solve(J, sdot) if J.shape[0] == J.shape[1] else np.linalg.pinv(J) @ sdot
            )  # (7-89)
        except np.linalg.LinAlgError:
            raise ControlError(
                f"the Jacobian is singular at t = {t:g} s (q = {q.tolist()}): resolved rate "
                "(7-89) needs its inverse; plan the line away from the singularity"
            ) from None
        if not np.all(np.isfinite(qd)):
            raise ControlError(
                f"the joint rates left the floating-point range at t = {t:g} s (near a singularity)"
            )
        q = q + qd * dt  # (7-96), Euler
        tn = (i + 1) * dt
        pn = robot.fk(q)[:3, 3]
        ts.append(tn)
        Q.append(q.copy())
        P.append(pn)
        E.append(float(np.linalg.norm(pn - (pi + min(tn / duration, 1.0) * (pf - pi)))))
    P = np.array(P)
    u = (pf - pi) / max(np.linalg.norm(pf - pi), 1e-300)
    rel = P - pi
    dev = np.linalg.norm(rel - np.outer(rel @ u, u), axis=1).max()
    Tend = robot.fk(q)
    return LineMotionResult(
        np.array(ts),
        np.array(Q),
        P,
        np.array(E),
        float(dev),
        float(np.linalg.norm(Tend[:3, 3] - pf)),
        float(np.linalg.norm(pin.log3(Rf @ Tend[:3, :3].T))),
    )
