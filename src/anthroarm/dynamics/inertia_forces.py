r"""Inertia forces and couples of the links, book Eqs. (8-30)–(8-40), joint torques by
d'Alembert's principle, and the oblique joint frame of Eqs. (8-84)–(8-86).

Per link i (mass m, inertia tensor J about the centre of mass in the body frame, Eq. (8-25)):

* inertia force (8-30), fixed frame: ``F = −m a_s`` (a_s: the classical acceleration of the
  centre of mass); in the body frame (8-31): ``F⁽ⁱ⁾ = C_i0 F = Rᵀ F``;
* angular momentum about the centre of mass (8-32)–(8-34): ``H = J ω`` (body frame);
* inertia couple (8-35)–(8-38), body frame: ``M⁽ⁱ⁾ = −(J ε + ω × J ω)`` (ε the angular
  acceleration), component form (8-39) (:func:`inertia_couple_expanded`, printed correctly);
  back in the fixed frame (8-40, corrected: ``M⁽⁰⁾ = C_0i M⁽ⁱ⁾ = R M⁽ⁱ⁾``).

d'Alembert: with the inertia forces and couples added to the applied loads (gravity ``m g``)
the chain is in equilibrium, so the joint torques are

    τ_j = −Σ_{i after j} [ a_jᵀ((c_i − p_j) × (F_i + m_i g)) + a_jᵀ M_i ]   (revolute joint j)
    τ_j = −Σ_{i after j} a_jᵀ (F_i + m_i g)                                 (prismatic joint j)

with a_j, p_j the joint's axis and origin and c_i the centre of mass (fixed frame).  Split by
what drives the accelerations (:func:`torque_terms`): ``q̈`` alone (v = 0, no gravity) is the
inertia term M(q) q̈, ``q̇`` alone (q̈ = 0, no gravity) the Coriolis/centrifugal term C(q, q̇) q̇,
gravity alone g(q) — the three terms of ``pin.rnea`` (tests check each).

The kinematics are a forward recursion over ``robot.chain`` (tree, revolute, continuous,
prismatic and mimic joints), not Pinocchio's.

Oblique joint frame (§8-3, l. 6488–6531): axis p1 fixed in the first link of joint p, p2 in the
second, p3 = p1 × p2 / |p1 × p2| (8-84), (8-85); the frame need not be orthogonal.  The moment
M decomposes as ``M = M1 p1 + M2 p2 + M3 p3``, so ``(M1, M2, M3) = A⁻¹ M`` with the **axes as
the columns** of A (:func:`oblique_components`).  The printed (8-86) ``a_p⁻¹ M`` with a_p built
row-wise from the direction cosines of (8-84) is that decomposition only for orthogonal axes
(``docs/errata.md``; :func:`oblique_components_printed` keeps it for the test).

Frames and units: fixed (world) frame unless said otherwise, SI (N, N·m, m/s², rad/s²).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..chain import PRISMATIC
from ..errors import ParameterError
from ..spatial.rotations import rot_axis
from .euler_chain import passive

__all__ = [
    "inertia_force",
    "inertia_force_body",
    "angular_momentum",
    "inertia_couple",
    "inertia_couple_expanded",
    "inertia_couple_fixed",
    "LinkMotion",
    "link_motion",
    "LinkInertiaLoads",
    "link_inertia_loads",
    "dalembert_torques",
    "torque_terms",
    "joint_frame",
    "joint_frame_from_links",
    "oblique_components",
    "oblique_components_printed",
    "axis_projections",
]


def _vec(x, name: str, shape=(3,)) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be finite numbers of shape {shape}, got {x!r}") from None
    if a.shape != shape or not np.isfinite(a).all():
        raise ParameterError(f"{name} must be finite numbers of shape {shape}, got {x!r}")
    return a


# ------------------------------------------------------------------ one link, (8-30)-(8-40)


def inertia_force(m: float, a_com) -> np.ndarray:
    """Inertia force (N), Eq. (8-30): ``F = −m a_s``, in the frame of ``a_com`` (m/s²)."""
    if not (isinstance(m, (int, float, np.integer, np.floating)) and np.isfinite(m) and m >= 0):
        raise ParameterError(f"mass must be finite and >= 0 (kg), got {m!r}")
    return -float(m) * _vec(a_com, "a_com")


def inertia_force_body(R, F) -> np.ndarray:
    """The inertia force in the body frame, Eq. (8-31): ``F⁽ⁱ⁾ = C_i0 F⁽⁰⁾ = Rᵀ F`` with R the
    body orientation (body → fixed)."""
    return _vec(R, "R", (3, 3)).T @ _vec(F, "F")


def angular_momentum(J, omega) -> np.ndarray:
    """Angular momentum about the centre of mass, Eqs. (8-32)–(8-34): ``H = J ω`` (kg m²/s),
    J the inertia tensor (8-25) and ω the angular velocity, both in the body frame."""
    return _vec(J, "J", (3, 3)) @ _vec(omega, "omega")


def inertia_couple(J, omega, eps) -> np.ndarray:
    """Inertia couple in the body frame (N·m), Eq. (8-38): ``M = −(J ε + ω × J ω)``; J, ω, ε
    (rad/s²) in the body frame."""
    J, w, e = _vec(J, "J", (3, 3)), _vec(omega, "omega"), _vec(eps, "eps")
    return -(J @ e + np.cross(w, J @ w))


def inertia_couple_expanded(J, omega, eps) -> np.ndarray:
    """Eq. (8-39), component by component as printed (l. 6131), with the products of inertia
    J_xy = −J[0, 1] etc. of the tensor convention (8-25)."""
    J, w, e = _vec(J, "J", (3, 3)), _vec(omega, "omega"), _vec(eps, "eps")
    Jx, Jy, Jz = J[0, 0], J[1, 1], J[2, 2]
    Jxy, Jyz, Jzx = -J[0, 1], -J[1, 2], -J[2, 0]
    wx, wy, wz = w
    ex, ey, ez = e
    return np.array(
        [
            -Jx * ex
            + (Jy - Jz) * wy * wz
            + Jxy * (ey - wx * wz)
            + Jzx * (ez + wx * wy)
            + Jyz * (wy**2 - wz**2),
            -Jy * ey
            + (Jz - Jx) * wz * wx
            + Jyz * (ez - wy * wx)
            + Jxy * (ex + wy * wz)
            + Jzx * (wz**2 - wx**2),
            -Jz * ez
            + (Jx - Jy) * wx * wy
            + Jzx * (ex - wz * wy)
            + Jyz * (ey + wz * wx)
            + Jxy * (wx**2 - wy**2),
        ]
    )


def inertia_couple_fixed(R, M_body) -> np.ndarray:
    """The inertia couple in the fixed frame, Eq. (8-40) (corrected): ``M⁽⁰⁾ = C_0i M⁽ⁱ⁾ = R M``."""
    return _vec(R, "R", (3, 3)) @ _vec(M_body, "M_body")


# ------------------------------------------------------------------ a chain


@dataclass(frozen=True)
class LinkMotion:
    """Motion of every joint's body (index = ``robot.chain.joints`` order), fixed frame:
    ``R`` (n, 3, 3) orientation, ``p`` (n, 3) joint origin, ``axis`` (n, 3), ``com`` (n, 3),
    ``omega``/``eps`` (n, 3) angular velocity/acceleration, ``a_com`` (n, 3) classical
    acceleration of the centre of mass."""

    R: np.ndarray
    p: np.ndarray
    axis: np.ndarray
    com: np.ndarray
    omega: np.ndarray
    eps: np.ndarray
    a_com: np.ndarray


def _joint_rates(chain, q, v, a):
    """Positions, velocities and accelerations of every joint (mimic joints included)."""
    th = chain.angles(q)
    n = len(chain.joints)
    thd, thdd = np.zeros(n), np.zeros(n)
    for j in chain.joints:
        if not j.is_mimic:
            thd[j.index], thdd[j.index] = v[j.idx_v], a[j.idx_v]
    for j in chain.joints:
        if j.is_mimic:
            thd[j.index] = j.mimic.multiplier * thd[j.mimic.source]
            thdd[j.index] = j.mimic.multiplier * thdd[j.mimic.source]
    return th, thd, thdd


def link_motion(robot, q, v, a) -> LinkMotion:
    """Forward recursion over ``robot.chain`` (book §6-2 velocity/acceleration composition):
    ω_j = ω_p + a_j θ̇, ε_j = ε_p + a_j θ̈ + ω_p × a_j θ̇ (revolute); origin acceleration
    a_o = a_p + ε_p × r + ω_p × (ω_p × r) (+ a_j s̈ + 2 ω_p × a_j ṡ for a prismatic joint);
    centre of mass a_s = a_o + ε × d + ω × (ω × d).  Fixed frame, SI."""
    chain = robot.chain
    q = robot.check_q(q)
    v = _vec(v, "v", (robot.nv,))
    a = _vec(a, "a", (robot.nv,))
    th, thd, thdd = _joint_rates(chain, q, v, a)
    n = len(chain.joints)
    R, p, ax, com = np.zeros((n, 3, 3)), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    w, e, ao, ac = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    vo = np.zeros((n, 3))
    for j in chain.joints:
        i = j.index
        if j.parent < 0:
            Rp, pp, wp, ep, vp, ap = (
                np.eye(3),
                np.zeros(3),
                np.zeros(3),
                np.zeros(3),
                np.zeros(3),
                np.zeros(3),
            )
        else:
            k = j.parent
            Rp, pp, wp, ep, vp, ap = R[k], p[k], w[k], e[k], vo[k], ao[k]
        R0 = Rp @ j.rotation
        u = R0 @ j.axis
        r = Rp @ j.translation
        if j.kind == PRISMATIC:
            R[i] = R0
            r = r + u * th[i]
            w[i], e[i] = wp, ep
            vo[i] = vp + np.cross(wp, r) + u * thd[i]
            ao[i] = (
                ap
                + np.cross(ep, r)
                + np.cross(wp, np.cross(wp, r))
                + u * thdd[i]
                + 2 * np.cross(wp, u * thd[i])
            )
        else:
            R[i] = R0 @ rot_axis(j.axis, th[i])
            w[i] = wp + u * thd[i]
            e[i] = ep + u * thdd[i] + np.cross(wp, u * thd[i])
            vo[i] = vp + np.cross(wp, r)
            ao[i] = ap + np.cross(ep, r) + np.cross(wp, np.cross(wp, r))
        p[i] = pp + r
        ax[i] = u
        d = R[i] @ j.com
        com[i] = p[i] + d
        ac[i] = ao[i] + np.cross(e[i], d) + np.cross(w[i], np.cross(w[i], d))
    return LinkMotion(R, p, ax, com, w, e, ac)


@dataclass(frozen=True)
class LinkInertiaLoads:
    """Inertia force ``F`` (n, 3) N, Eq. (8-30), and inertia couple ``M`` (n, 3) N·m,
    Eqs. (8-38)/(8-40), of every joint's body at its centre of mass, fixed frame; ``motion``
    the :class:`LinkMotion` they come from."""

    F: np.ndarray
    M: np.ndarray
    motion: LinkMotion


def link_inertia_loads(robot, q, v, a) -> LinkInertiaLoads:
    """Inertia forces and couples of every link (Eqs. (8-30), (8-38), (8-40)), fixed frame."""
    mo = link_motion(robot, q, v, a)
    F, M = np.zeros_like(mo.p), np.zeros_like(mo.p)
    for j in robot.chain.joints:
        i = j.index
        F[i] = inertia_force(j.mass, mo.a_com[i])
        Rt = mo.R[i].T
        M[i] = inertia_couple_fixed(
            mo.R[i], inertia_couple(j.inertia, Rt @ mo.omega[i], Rt @ mo.eps[i])
        )
    return LinkInertiaLoads(F, M, mo)


def dalembert_torques(robot, q, v, a, gravity: bool = True) -> np.ndarray:
    """Joint torques/forces (nv,) by d'Alembert's principle from the inertia loads of
    :func:`link_inertia_loads` and gravity ``m g`` (``robot.chain.gravity``, m/s²): equal to
    inverse dynamics τ = M q̈ + C q̇ + g (with ``gravity=False``: without g)."""
    chain = robot.chain
    loads = link_inertia_loads(robot, q, v, a)
    mo = loads.motion
    g = chain.gravity if gravity else np.zeros(3)
    n = len(chain.joints)
    # wrench of each subtree about the world origin: force f and moment m = Σ c × f + M
    f = loads.F + np.array([j.mass * g for j in chain.joints])
    mom = np.cross(mo.com, f) + loads.M
    fs, ms = f.copy(), mom.copy()
    for j in reversed(chain.joints):  # children come after their parents
        if j.parent >= 0:
            fs[j.parent] += fs[j.index]
            ms[j.parent] += ms[j.index]
    raw = np.zeros(n)
    for j in chain.joints:
        i = j.index
        u = mo.axis[i]
        if j.kind == PRISMATIC:
            raw[i] = -u @ fs[i]
        else:  # moment about the joint origin: m − p × f
            raw[i] = -u @ (ms[i] - np.cross(mo.p[i], fs[i]))
    tau = np.zeros(robot.nv)
    for j in chain.joints:
        src = chain.joints[j.mimic.source] if j.is_mimic else j
        k = j.mimic.multiplier if j.is_mimic else 1.0
        tau[src.idx_v] += k * raw[j.index]
    return tau


def torque_terms(robot, q, v, a) -> dict[str, np.ndarray]:
    """The three terms of inverse dynamics from the inertia loads (d'Alembert):
    ``"M_qdd"`` = M(q) q̈ (q̇ = 0, no gravity), ``"C_qd"`` = C(q, q̇) q̇ (q̈ = 0, no gravity),
    ``"g"`` = g(q) (at rest), and their sum ``"tau"``.  (nv,) each, N·m or N."""
    z = np.zeros(robot.nv)
    Mq = dalembert_torques(robot, q, z, a, gravity=False)
    Cq = dalembert_torques(robot, q, v, z, gravity=False)
    gq = dalembert_torques(robot, q, z, z, gravity=True)
    return {"M_qdd": Mq, "C_qd": Cq, "g": gq, "tau": Mq + Cq + gq}


# ------------------------------------------------------------------ oblique joint frame


def joint_frame(p1, p2) -> np.ndarray:
    """The joint coordinate system of §8-3, Eqs. (8-84), (8-85): 3×3 matrix whose **columns**
    are p1, p2 (normalised; fixed-frame directions of the two joint axes) and
    p3 = p1 × p2 / |p1 × p2|.  Not orthogonal unless p1 ⊥ p2.  ValueError if p1 ∥ p2."""
    u1, u2 = _vec(p1, "p1"), _vec(p2, "p2")
    n1, n2 = np.linalg.norm(u1), np.linalg.norm(u2)
    if not (n1 > 0 and n2 > 0):
        raise ParameterError("joint axes p1 and p2 must be non-zero")
    u1, u2 = u1 / n1, u2 / n2
    c = np.cross(u1, u2)
    s = np.linalg.norm(c)
    if s < 1e-9:
        raise ParameterError(
            f"joint axes p1 and p2 are parallel (|p1 × p2| = {s:.3g}): (8-85) has no third axis"
        )
    return np.column_stack([u1, u2, c / s])


def joint_frame_from_links(l1, e1, l2, e2) -> np.ndarray:
    """The joint frame of Eq. (8-84) from the book's data: the direction cosines ``l1`` of axis
    1 in the frame of link β(p, 1), whose X–Y–X Euler angles are ``e1`` = (θ, ψ, φ), and ``l2``
    of axis 2 in link β(p, 2) with ``e2``.  As printed, each fixed-frame axis is the row vector
    ``(l, m, n)(Φ Ψ Θ)`` with the passive matrices of Eq. (8-41)
    (:func:`anthroarm.dynamics.euler_chain.passive`); then :func:`joint_frame` adds p3 (8-85)."""
    rows = []
    for name, lmn, e in (("l1", l1, e1), ("l2", l2, e2)):
        Th, Ps, Ph = passive(_vec(e, f"Euler angles of {name}'s link"))
        rows.append(_vec(lmn, name) @ (Ph @ Ps @ Th))
    return joint_frame(rows[0], rows[1])


def _check_axes(axes) -> np.ndarray:
    """``axes`` (3, 3) with three independent columns (a :func:`joint_frame`), else
    ParameterError."""
    A = _vec(axes, "axes", (3, 3))
    if abs(np.linalg.det(A)) < 1e-12 * max(1.0, float(np.abs(A).max()) ** 3):
        raise ParameterError(
            f"axes are not independent (det = {np.linalg.det(A):.3g}): no decomposition of M "
            "along them; build them with joint_frame(p1, p2)"
        )
    return A


def oblique_components(M, axes) -> np.ndarray:
    """(M1, M2, M3) with ``M = M1 p1 + M2 p2 + M3 p3``, Eq. (8-86) corrected: ``A⁻¹ M`` with A
    the :func:`joint_frame` (axes as columns).  M in the fixed frame (N·m)."""
    A = _check_axes(axes)
    return np.linalg.solve(A, _vec(M, "M"))


def oblique_components_printed(M, axes) -> np.ndarray:
    """Eq. (8-86) as printed: ``a_p⁻¹ M`` with a_p = [a_ij] holding the direction cosines of
    axis i in **row** i (8-84).  Kept to show where it fails (oblique axes)."""
    A = _check_axes(axes)
    return np.linalg.solve(A.T, _vec(M, "M"))


def axis_projections(M, axes) -> np.ndarray:
    """``(p1·M, p2·M, p3·M)``: the torque about each axis (what a revolute actuator on that
    axis carries, and what ``pin.rnea`` returns for revolute joints); equals
    :func:`oblique_components` only for orthonormal axes."""
    A = _vec(axes, "axes", (3, 3))
    return A.T @ _vec(M, "M")
