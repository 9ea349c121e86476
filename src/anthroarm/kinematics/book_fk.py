"""The book's printed closed forms of hand poses, corrected where recomputation proves a
misprint (see ``docs/errata.md``), vectorised over a batch of configurations.

Every function takes joint values ``q`` of shape ``(n,)`` or ``(N, n)`` (rad; m for prismatic
joints) and link lengths in m, and returns the hand pose as a 4×4 homogeneous matrix (or a
batch) in the book's base frame 0.  In the book's notation the hand frame has its x axis
b = (u, v, w), its z axis a = (l, m, n) and its origin at the hand point (x, y, z); y = a × b.

:data:`PRINTED` is the one registry that says which book model each printed form belongs to
(``anthroarm check`` compares them with Pinocchio through :func:`printed_forms`).  This module
is forward kinematics; the closed-form *inverse* kinematics is :mod:`anthroarm.ik.closed_form`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .dh import _as_batch, dh_frames, finite_params


def _pose(x, y, z, l, m, n, u, v, w) -> np.ndarray:
    N = np.shape(x)[0]
    T = np.zeros((N, 4, 4))
    b = np.stack([u, v, w], axis=-1)
    a = np.stack([l, m, n], axis=-1)
    T[:, :3, 0] = b
    T[:, :3, 2] = a
    T[:, :3, 1] = np.cross(a, b)
    T[:, :3, 3] = np.stack([x, y, z], axis=-1)
    T[:, 3, 3] = 1.0
    return T


def sixr_hand_pose(q, s0: float, h2: float, s3: float, P: float) -> np.ndarray:
    """6R arm of Fig. 6-3: hand position Eq. (6-16) and attitude Eq. (6-17).

    (6-16) is printed correctly; in (6-17) the printed u, v, w carry θ5 where θ6 belongs
    (errata): here u = [(C6C5C4 + S6S4)C23 + C6S5S23]C1 + (C6C5S4 − S6C4)S1, etc."""
    q2, single = _as_batch(q, 6)
    s0, h2, s3, P = finite_params(s0=s0, h2=h2, s3=s3, P=P)
    t1, t2, t3, t4, t5, t6 = q2.T
    C1, S1, C2, S2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    C4, S4, C5, S5, C6, S6 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5), np.cos(t6), np.sin(t6)
    C23, S23 = np.cos(t2 + t3), np.sin(t2 + t3)
    r = P * S5 * C4 * C23 + (s3 - P * C5) * S23 + h2 * C2  # Eq. (6-16)
    x = r * C1 + P * S5 * S4 * S1
    y = r * S1 - P * S5 * S4 * C1
    z = P * S5 * C4 * S23 - (s3 - P * C5) * C23 + h2 * S2 + s0
    k = S5 * C4 * C23 - C5 * S23  # Eq. (6-17)
    l = k * C1 + S5 * S4 * S1
    m = k * S1 - S5 * S4 * C1
    n = S5 * C4 * S23 + C5 * C23
    g = (C6 * C5 * C4 + S6 * S4) * C23 + C6 * S5 * S23
    f = C6 * C5 * S4 - S6 * C4
    u = g * C1 + f * S1
    v = g * S1 - f * C1
    w = (C6 * C5 * C4 + S6 * S4) * S23 - C6 * S5 * C23
    T = _pose(x, y, z, l, m, n, u, v, w)
    return T[0] if single else T


def unimate_hand_pose(q, s0: float, h2: float, P: float) -> np.ndarray:
    """R-R-P-R-R arm: the Unimate of Fig. 6-4, Eq. (6-21)–(6-23), which is the same chain
    as the 002 text's RRPRR manipulator, Eq. (4-52)–(4-54).  ``q = (θ1, θ2, s2, θ4, θ5)``.

    Corrected misprints (errata): (6-23) v ends in −C5 S4 C1 (printed S1); (4-52) x has C2
    where the 002 text prints C3; (4-54) v as (6-23)."""
    q2, single = _as_batch(q, 5)
    s0, h2, P = finite_params(s0=s0, h2=h2, P=P)
    t1, t2, s2, t4, t5 = q2.T
    C1, S1, C2, S2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    C4, S4, C5, S5 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    k = S5 * C4 * C2 - C5 * S2
    r = P * k + s2 * S2 + h2 * C2  # Eq. (6-21)
    x = r * C1 + P * S5 * S4 * S1
    y = r * S1 - P * S5 * S4 * C1
    z = P * (S5 * C4 * S2 + C5 * C2) - s2 * C2 + h2 * S2 + s0
    l = k * C1 + S5 * S4 * S1  # Eq. (6-22)
    m = k * S1 - S5 * S4 * C1
    n = S5 * C4 * S2 + C5 * C2
    g = C5 * C4 * C2 + S5 * S2  # Eq. (6-23)
    u = g * C1 + C5 * S4 * S1
    v = g * S1 - C5 * S4 * C1
    w = C5 * C4 * S2 - S5 * C2
    T = _pose(x, y, z, l, m, n, u, v, w)
    return T[0] if single else T


#: the 002 text's (4-52)–(4-54) are the same formulas as (6-21)–(6-23)
rrprr_hand_pose = unimate_hand_pose


def human_arm7_rotations(q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C_E, C_W, C_H of the §6-3 arm, Eq. (6-34)–(6-36), each (N, 3, 3) (or (3, 3)).

    C_E = Cx1 Cy2 (printed elementwise, (6-34)); C_W = Cx1 Cy2 Cz3 Cx4 (6-35); C_H = C_W Cz5
    Cy6 Cx7 written column-wise with the columns W1, W2, W3 of C_W (6-36; the printed h21, h31
    read s6c6 where s5c6 belongs)."""
    q2, single = _as_batch(q, 7)
    c = np.cos(q2)
    s = np.sin(q2)
    c1, c2, c3, c4, c5, c6, c7 = c.T
    s1, s2, s3, s4, s5, s6, s7 = s.T
    N = q2.shape[0]
    CE = np.empty((N, 3, 3))
    CE[:, 0] = np.stack([c2, np.zeros(N), s2], -1)
    CE[:, 1] = np.stack([s1 * s2, c1, -s1 * c2], -1)
    CE[:, 2] = np.stack([-c1 * s2, s1, c1 * c2], -1)
    W1 = np.stack([c2 * c3, s1 * s2 * c3 + c1 * s3, -c1 * s2 * c3 + s1 * s3], -1)
    W2 = np.stack(
        [
            -c2 * s3 * c4 + s2 * s4,
            -s1 * s2 * s3 * c4 + c1 * c3 * c4 - s1 * c2 * s4,
            c1 * s2 * s3 * c4 + s1 * c3 * c4 + c1 * c2 * s4,
        ],
        -1,
    )
    W3 = np.stack(
        [
            c2 * s3 * s4 + s2 * c4,
            s1 * s2 * s3 * s4 - c1 * c3 * s4 - s1 * c2 * c4,
            -c1 * s2 * s3 * s4 - s1 * c3 * s4 + c1 * c2 * c4,
        ],
        -1,
    )
    CW = np.stack([W1, W2, W3], axis=-1)
    H1 = W1 * (c5 * c6)[:, None] + W2 * (s5 * c6)[:, None] - W3 * s6[:, None]
    H2 = (
        W1 * (c5 * s6 * s7 - s5 * c7)[:, None]
        + W2 * (s5 * s6 * s7 + c5 * c7)[:, None]
        + W3 * (c6 * s7)[:, None]
    )
    H3 = (
        W1 * (c5 * s6 * c7 + s5 * s7)[:, None]
        + W2 * (s5 * s6 * c7 - c5 * s7)[:, None]
        + W3 * (c6 * c7)[:, None]
    )
    CH = np.stack([H1, H2, H3], axis=-1)
    if single:
        return CE[0], CW[0], CH[0]
    return CE, CW, CH


def human_arm7_points(q, l1: float, l2: float, l3: float):
    """Elbow, wrist and hand points P_E, P_W, P_H of the §6-3 arm, Eq. (6-37)–(6-39), in the
    shoulder frame (m), and C_H.  Returns (PE, PW, PH, CH)."""
    l1, l2, l3 = finite_params(l1=l1, l2=l2, l3=l3)
    CE, CW, CH = human_arm7_rotations(q)
    PE = -l1 * CE[..., :, 2]
    PW = PE - l2 * CW[..., :, 2]
    PH = PW - l3 * CH[..., :, 2]
    return PE, PW, PH, CH


def human_arm7_hand_pose(q, l1: float, l2: float, l3: float) -> np.ndarray:
    """Hand pose of the §6-3 arm: orientation C_H (6-36) at the hand point P_H (6-39)."""
    _, _, PH, CH = human_arm7_points(q, l1, l2, l3)
    T = np.zeros(PH.shape[:-1] + (4, 4))
    T[..., :3, :3] = CH
    T[..., :3, 3] = PH
    T[..., 3, 3] = 1.0
    return T


def human_arm7_jacobian(q, l1: float, l2: float, l3: float) -> np.ndarray:
    """Jacobian of the hand point of the §6-3 arm, LOCAL_WORLD_ALIGNED, rows (v; ω), (6, 7).

    Joint axes from the printed rotations: x0; Cx1·y; C_E·z; C_E Cz3·x (= column 1 of C_W);
    C_W·z; C_W Cz5·y; C_W Cz5 Cy6·x (= column 1 of C_H).  Shoulder joints turn about S,
    the elbow about P_E and the wrist joints about P_W; column k is (a_k × (P_H − c_k); a_k)."""
    q2, single = _as_batch(q, 7)
    PE, PW, PH, CH = human_arm7_points(q2, l1, l2, l3)
    CE, CW, _ = human_arm7_rotations(q2)
    N = q2.shape[0]
    c1, s1 = np.cos(q2[:, 0]), np.sin(q2[:, 0])
    c5, s5 = np.cos(q2[:, 4]), np.sin(q2[:, 4])
    axes = np.empty((N, 7, 3))
    axes[:, 0] = [1.0, 0.0, 0.0]
    axes[:, 1] = np.stack([np.zeros(N), c1, s1], -1)  # Cx1 · e_y
    axes[:, 2] = CE[:, :, 2]
    axes[:, 3] = CW[:, :, 0]
    axes[:, 4] = CW[:, :, 2]
    axes[:, 5] = CW[:, :, 0] * (-s5)[:, None] + CW[:, :, 1] * c5[:, None]  # C_W Cz5 · e_y
    axes[:, 6] = CH[:, :, 0]
    centres = np.stack([np.zeros((N, 3))] * 3 + [PE] + [PW] * 3, axis=1)
    J = np.empty((N, 6, 7))
    J[:, :3, :] = np.cross(axes, PH[:, None, :] - centres).transpose(0, 2, 1)
    J[:, 3:, :] = axes.transpose(0, 2, 1)
    return J[0] if single else J


def human_arm7_length_jacobian(q) -> np.ndarray:
    """The book's Eq. (6-119) for the §6-3 arm: the 3 × 3 matrix [−e_{·3}, −w_{·3}, −h_{·3}]
    mapping (Δl₁, Δl₂, Δl₃) to (Δx_H, Δy_H, Δz_H), with C_E, C_W, C_H of (6-34)–(6-36).
    (:mod:`.error_propagation` computes the same coefficients for any robot.)"""
    CE, CW, CH = human_arm7_rotations(np.asarray(q, float))
    return -np.stack([CE[..., :, 2], CW[..., :, 2], CH[..., :, 2]], axis=-1)


def planar2r_tip(q, l1: float = 1.0, l2: float = 1.0) -> np.ndarray:
    """Fig. 7-14: tip (y, z) = (l1 cos θ1 + l2 cos(θ1+θ2), l1 sin θ1 + l2 sin(θ1+θ2)), shape (N, 2)."""
    q2, single = _as_batch(q, 2)
    l1, l2 = finite_params(l1=l1, l2=l2)
    t1, t12 = q2[:, 0], q2[:, 0] + q2[:, 1]
    yz = np.stack([l1 * np.cos(t1) + l2 * np.cos(t12), l1 * np.sin(t1) + l2 * np.sin(t12)], -1)
    return yz[0] if single else yz


def prosthetic_arm_points(q, L1: float, L2: float, L3: float):
    """Elbow E, wrist W and palm centre C of the Ch. 7 prosthetic arm (m, base frame 0).

    E = L1 (c1 s2, s1 s2, −c2) (Eq. (7-17)); W = E + L2 z4; C = W + L3 z6 (Fig. 7-2), with the
    frames of Table 7.1 / Eq. (7-16), θ3 carrying the printed A23's hidden +90°."""
    from ..models.book import prosthetic_arm

    L1, L2, L3 = finite_params(L1=L1, L2=L2, L3=L3)
    rows = prosthetic_arm(L1, L2, L3).dh
    F = dh_frames(rows, q)
    E = F[..., 3, :3, 3]
    W = F[..., 5, :3, 3]
    C = W + L3 * F[..., 6, :3, 2]
    return E, W, C


def planar2r_tip_pose(q, l1: float = 1.0, l2: float = 1.0) -> np.ndarray:
    """Fig. 7-14 as a pose, (N, 4, 4): the printed tip (y, z) of :func:`planar2r_tip`; both
    hinges turn about x, so the tip frame is Rx(θ1 + θ2)."""
    q2, _ = _as_batch(q, 2)
    yz = np.atleast_2d(planar2r_tip(q2, l1, l2))
    t = q2.sum(axis=-1)
    T = np.zeros(t.shape + (4, 4))
    T[:, 0, 0] = T[:, 3, 3] = 1.0
    T[:, 1, 1] = T[:, 2, 2] = np.cos(t)
    T[:, 2, 1], T[:, 1, 2] = np.sin(t), -np.sin(t)
    T[:, 1, 3], T[:, 2, 3] = yz[:, 0], yz[:, 1]
    return T


@dataclass(frozen=True)
class PrintedForm:
    """One printed closed form of a book model: ``pose(q, params)`` → (N, 4, 4) of the tool,
    ``jacobian(q, params)`` → (N, 6, n) LOCAL_WORLD_ALIGNED or None, ``length_jacobian(q,
    params)`` → (N, 3, 3) the §6-6 coefficients ∂P/∂l or None; ``params`` is the model's
    ``spec.params`` (SI units)."""

    equations: str
    pose: Callable
    jacobian: Callable | None = None
    length_jacobian: Callable | None = None


#: book model name -> its printed forms (functions are looked up when called)
PRINTED: dict[str, tuple[PrintedForm, ...]] = {
    "sixr_arm": (
        PrintedForm(
            "(6-16)/(6-17)", lambda q, p: sixr_hand_pose(q, p["s0"], p["h2"], p["s3"], p["P"])
        ),
    ),
    "unimate5": (
        PrintedForm("(6-21)-(6-23)", lambda q, p: unimate_hand_pose(q, p["s0"], p["h2"], p["P"])),
    ),
    "rrprr5": (
        PrintedForm("002 (4-52)-(4-54)", lambda q, p: rrprr_hand_pose(q, p["s0"], p["h2"], p["p"])),
    ),
    "human_arm7": (
        PrintedForm(
            "(6-34)-(6-39)",
            lambda q, p: human_arm7_hand_pose(q, p["l1"], p["l2"], p["l3"]),
            lambda q, p: human_arm7_jacobian(q, p["l1"], p["l2"], p["l3"]),
            lambda q, p: human_arm7_length_jacobian(q),
        ),
    ),
    "planar2r": (
        PrintedForm("Fig. 7-14 (y, z)", lambda q, p: planar2r_tip_pose(q, p["l1"], p["l2"])),
    ),
}


def book_spec(robot):
    """The parameter table of ``robot`` when it is a book model as generated (any parameters),
    with its own tool frame and every joint (the chain the closed forms describe); else None."""
    spec = getattr(robot, "spec", None)
    if spec is None or robot.tool != spec.tool_name or robot.locked or robot.nq != spec.nq:
        return None
    return spec


def printed_forms(robot) -> tuple[PrintedForm, ...]:
    """The printed forms that apply to ``robot`` (see :func:`book_spec`); call them with
    ``book_spec(robot).params``."""
    spec = book_spec(robot)
    return PRINTED.get(spec.name, ()) if spec is not None else ()
