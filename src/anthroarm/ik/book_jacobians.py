"""Jacobians the book's way (Ch. 7 §7-5 二 and §7-7), built from the robot's parameter table.

* :func:`trace_jacobian` — the trace formula (7-58)–(7-63): with the projection matrices Θ_k of
  (7-59) and δ_j = ½ (j = 1…3), 1 (j = 4…6),
  ``J_ji = δ_j tr(∂T/∂q_i · T⁻¹ · Θ_jᵀ)``.  Rows are the book's external variables
  ṙ⁰ = (ω_x, ω_y, ω_z, ẋ⁰, ẏ⁰, ż⁰): the *spatial* (world-frame) twist, angular part first,
  the linear part being the velocity of the body point at the world origin.  It equals
  Pinocchio's ``WORLD`` Jacobian with its (v; ω) blocks swapped.
* :func:`trace_jacobian_derivative` — K = J̇ = Σ_k ∂J/∂q_k q̇_k from the same formula with the
  true second derivatives ∂²T/∂q_i∂q_k.  ``variant="book"`` uses the book's identity
  ∂²T/∂q_k∂q_i = ∂T/∂q_i T⁻¹ ∂T/∂q_k (7-64), which makes K ≡ 0 (7-65).  That identity holds
  only for i < k, so the book's K ≡ 0 is false (docs/errata.md).
* :func:`hand_frame_jacobian` — (7-90)–(7-94): columns (u_j × b_j7; u_j) rotated into the hand
  frame by blockdiag(C17ᵀ, C17ᵀ) (the book prints a bare C17ᵀ); (v; ω) order.  It equals
  Pinocchio's ``LOCAL`` frame Jacobian.

The derivatives of T come from the chain product of the parameter table
(``robot.spec.joints``: joint origins, axes; the tool origin), not from Pinocchio.
Units: m, rad; T is the 4×4 tool pose in the base frame.
"""

from __future__ import annotations

import numpy as np

#: Θ_1 … Θ_6 of Eq. (7-59) (4×4; rows/cols 1-based in the book)
THETA = np.zeros((6, 4, 4))
THETA[0, 1, 2], THETA[0, 2, 1] = -1.0, 1.0
THETA[1, 0, 2], THETA[1, 2, 0] = 1.0, -1.0
THETA[2, 0, 1], THETA[2, 1, 0] = -1.0, 1.0
THETA[3, 0, 3] = 1.0
THETA[4, 1, 3] = 1.0
THETA[5, 2, 3] = 1.0
#: the factors δ_j of Eq. (7-60), j = 1…6: tr(Θ_j Θ_kᵀ) = δ_jk / δ_j
DELTA = np.array([0.5, 0.5, 0.5, 1.0, 1.0, 1.0])


def _hat(axis):
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    H = np.zeros((4, 4))
    H[:3, :3] = [[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]
    return H


def _rot(axis, q):
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    K = _hat(a)[:3, :3]
    R = np.eye(4)
    R[:3, :3] = np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * (K @ K)
    return R


def _factors(robot, q):
    """Per joint j: (G_j, dG_j, d2G_j) with G_j = origin_j · Rot(axis_j, q_j) and its first and
    second derivatives in q_j (revolute joints; prismatic: Tz-type translation)."""
    spec = robot.spec
    if spec is None:
        raise ValueError(f"{robot.name}: the book's Jacobians need a parameter table (robot.spec)")
    q = robot.check_q(q)
    out = []
    for j, js in enumerate(spec.joints):
        O = np.asarray(js.origin, float)
        if js.type == "prismatic":
            a = np.asarray(js.axis, float) / np.linalg.norm(js.axis)
            G = np.eye(4)
            G[:3, 3] = a * q[j]
            dG = np.zeros((4, 4))
            dG[:3, 3] = a
            out.append((O @ G, O @ dG, np.zeros((4, 4))))
        else:
            Rq = _rot(js.axis, q[j])
            H = _hat(js.axis)
            out.append((O @ Rq, O @ Rq @ H, O @ Rq @ H @ H))
    return out, np.asarray(spec.tool_origin, float)


def _product(mats):
    T = np.eye(4)
    for M in mats:
        T = T @ M
    return T


def chain_derivatives(robot, q, second: bool = False):
    """T (4×4), ∂T/∂q_i (n, 4, 4) and, if ``second``, ∂²T/∂q_i∂q_k (n, n, 4, 4), by the product
    rule on the chain G_1 ⋯ G_n · tool."""
    F, tool = _factors(robot, q)
    n = len(F)
    G = [f[0] for f in F]
    T = _product(G) @ tool
    dT = np.empty((n, 4, 4))
    for i in range(n):
        dT[i] = _product(G[:i] + [F[i][1]] + G[i + 1 :]) @ tool
    if not second:
        return T, dT
    d2T = np.empty((n, n, 4, 4))
    for i in range(n):
        for k in range(n):
            if i == k:
                d2T[i, k] = _product(G[:i] + [F[i][2]] + G[i + 1 :]) @ tool
            else:
                mats = list(G)
                mats[i], mats[k] = F[i][1], F[k][1]
                d2T[i, k] = _product(mats) @ tool
    return T, dT, d2T


def _trace_rows(A):
    """δ_j tr(A Θ_jᵀ) for j = 1…6 (A a 4×4, or a stack (..., 4, 4))."""
    return DELTA * np.einsum("...ab,jab->...j", A, THETA)


def trace_jacobian(robot, q) -> np.ndarray:
    """Eq. (7-63): J (6, n), rows (ω; v⁰) in world axes (the book's ṙ⁰ order)."""
    T, dT = chain_derivatives(robot, q)
    Tinv = np.linalg.inv(T)
    return _trace_rows(dT @ Tinv).T


def trace_jacobian_derivative(robot, q, qd, variant: str = "exact") -> np.ndarray:
    """K = J̇ = Σ_k (∂J/∂q_k) q̇_k (6, n) of the trace-formula Jacobian (7-63).

    ``variant="exact"``: ∂J_ji/∂q_k = δ_j tr((∂²T/∂q_i∂q_k T⁻¹ − ∂T/∂q_i T⁻¹ ∂T/∂q_k T⁻¹) Θ_jᵀ).
    ``variant="book"``: the book substitutes ∂²T/∂q_k∂q_i = ∂T/∂q_i T⁻¹ ∂T/∂q_k (7-64) for all
    i, k, which cancels every term: K ≡ 0 (7-65).  Kept to show that it is wrong."""
    if variant not in ("exact", "book"):
        raise ValueError(f"variant must be 'exact' or 'book', got {variant!r}")
    qd = np.asarray(qd, float)
    T, dT, d2T = chain_derivatives(robot, q, second=True)
    if qd.shape != (dT.shape[0],) or not np.isfinite(qd).all():
        raise ValueError(f"qd must be finite with shape ({dT.shape[0]},), got {qd!r}")
    Ti = np.linalg.inv(T)
    n = dT.shape[0]
    if variant == "book":
        d2T = np.einsum("iab,bc,kcd->ikad", dT, Ti, dT)  # (7-64) for all i, k
    dJ = np.empty((n, n, 6))  # [i, k, j] = ∂J_ji/∂q_k
    for i in range(n):
        for k in range(n):
            A = d2T[i, k] @ Ti - dT[i] @ Ti @ dT[k] @ Ti
            dJ[i, k] = _trace_rows(A)
    return np.einsum("ikj,k->ji", dJ, qd)


def hand_frame_jacobian(robot, q) -> np.ndarray:
    """Eqs. (7-90)–(7-94): J (6, n) in the hand frame, rows (v; ω).

    Column j is (u_j × b_j7; u_j) with u_j the joint axis and b_j7 the vector from the joint
    origin O_j to the hand origin O_7 (base coordinates), rotated by blockdiag(C17ᵀ, C17ᵀ).
    Prismatic joints contribute (u_j; 0)."""
    spec = robot.spec
    F, tool = _factors(robot, q)
    T = np.eye(4)
    axes, origins, kinds = [], [], []
    for js, (G, _, _) in zip(spec.joints, F):
        Fj = T @ np.asarray(js.origin, float)  # joint frame before its own motion
        a = np.asarray(js.axis, float) / np.linalg.norm(js.axis)
        axes.append(Fj[:3, :3] @ a)
        origins.append(Fj[:3, 3])
        kinds.append(js.type)
        T = T @ G
    T = T @ tool
    C17, O7 = T[:3, :3], T[:3, 3]
    cols = []
    for u, O, kind in zip(axes, origins, kinds):
        if kind == "prismatic":
            cols.append(np.concatenate([u, np.zeros(3)]))
        else:
            cols.append(np.concatenate([np.cross(u, O7 - O), u]))  # (7-90), (7-91)
    Jw = np.array(cols).T
    B = np.zeros((6, 6))
    B[:3, :3] = B[3:, 3:] = C17.T  # (7-94), block-diagonal
    return B @ Jw
