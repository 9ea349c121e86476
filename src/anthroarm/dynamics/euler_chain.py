r"""Ball-jointed chain described by absolute X–Y–X Euler angles, book §8-3, Eqs. (8-41)–(8-96).

Each link k carries its **absolute** orientation e_k = (θ, ψ, φ)_k (not joint angles), with
the book's passive matrices (8-41): body ← fixed = Φ Ψ Θ, i.e. fixed ← body
R = Θᵀ Ψᵀ Φᵀ = R_x(θ) R_y(ψ) R_x(φ) (an intrinsic X–Y′–X″ sequence).  Z points **up**; gravity
is −g Ẑ.  SI units.

Single body (corrected forms, see ``docs/errata.md``):

* ω = Π ė (8-44/45), ω̇ = Π ë + Π₁ ė× (8-46/47), ė× = (ψ̇φ̇, φ̇θ̇, θ̇ψ̇);
* (ω_x², ω_y², ω_z²) = Π₂ ė² + Π₃ ė× (8-53/54), (ω_yω_z, ω_zω_x, ω_xω_y) = Π₄ ė² + Π₅ ė× (8-55/56);
* M = J ω̇ + ω × Jω = JΠë + (J₁Π₂ + J₂Π₄) ė² + (JΠ₁ + J₁Π₃ + J₂Π₅) ė× (8-51), (8-52), (8-57);
  in the fixed frame M⁰ = D ë + E ė² + F ė× (8-59/60);
* l̈⁰ = A Λ ë + B Λ ė² + C Λ ė× with the 3 × 9 matrices A, B, C of (8-68) (8-69).

Chain (simple chain: joint p joins link p and p+1, p = 0 the fixed support; link k carries
l_k from its first joint to joint k; structure matrices e_ip = [i ≥ p+1],
δ_ijp = [p+1 ≤ j ≤ i−1], γ_ij = [i = j]):

* CoM acceleration (8-76), joint moments (8-80)/(8-83) about each joint in the fixed frame,
  stacked as Q = A S̈ + B Ṡ² + C ṠṠ + G (8-91) — ``A`` is **not** symmetric (Q are joint
  moments, not generalized forces);
* forward dynamics (8-92) S̈ = A⁻¹(Q − BṠ² − CṠṠ − G), guarded: sin ψ_k = 0 (gimbal lock,
  det Π = −sin ψ) raises :class:`~anthroarm.errors.EulerSingularityError`;
* the mixed problem (8-93)–(8-96) with the corrected block inverse.

Cross-check: :meth:`EulerChain.pin_model` builds the same chain with spherical joints;
``blkdiag(R_k) · pin.rnea`` equals Q (recipe R2 of the notes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import EulerSingularityError, InertiaError
from ..spatial.euler import euler_xyx, euler_xyx_rate_matrix
from ..spatial.rotations import rot_x, rot_y, skew  # skew = [v]×, Eq. (8-78) corrected

#: |sin ψ| below this is treated as gimbal lock
SINGULAR_TOL = 1e-6


def passive(e):
    """(Θ, Ψ, Φ) of Eq. (8-41) (passive rotations, body ← fixed = Φ Ψ Θ)."""
    th, ps, ph = e
    return rot_x(th).T, rot_y(ps).T, rot_x(ph).T


def rotation(e) -> np.ndarray:
    """Fixed ← body rotation R = Θᵀ Ψᵀ Φᵀ = R_x(θ) R_y(ψ) R_x(φ), Eq. (8-42)."""
    return euler_xyx(*e)


def Pi(e) -> np.ndarray:
    """Π of Eq. (8-45): body angular velocity ω = Π ė; det Π = −sin ψ."""
    _, ps, ph = e
    return euler_xyx_rate_matrix(ps, ph)


def Pi1(e) -> np.ndarray:
    """Π₁ of Eq. (8-47): ω̇ = Π ë + Π₁ (ψ̇φ̇, φ̇θ̇, θ̇ψ̇)."""
    _, ps, ph = e
    sp_, cp, sf, cf = np.sin(ps), np.cos(ps), np.sin(ph), np.cos(ph)
    return np.array([[0, 0, -sp_], [-sf, sp_ * cf, cp * sf], [-cf, -sp_ * sf, cp * cf]])


def Pi2_to_5(e):
    """Π₂, Π₃ (8-54) and Π₄, Π₅ (8-56), all as printed (verified)."""
    _, ps, ph = e
    sp_, cp, sf, cf = np.sin(ps), np.cos(ps), np.sin(ph), np.cos(ph)
    P2 = np.array([[cp**2, 0, 1], [sp_**2 * sf**2, cf**2, 0], [sp_**2 * cf**2, sf**2, 0]])
    P3 = np.array([[0, 2 * cp, 0], [0, 0, 2 * sp_ * sf * cf], [0, 0, -2 * sp_ * sf * cf]])
    P4 = np.array([[sp_**2 * sf * cf, -sf * cf, 0], [sp_ * cp * cf, 0, 0], [sp_ * cp * sf, 0, 0]])
    P5 = np.array(
        [[0, 0, sp_ * (cf**2 - sf**2)], [-sf, sp_ * cf, -cp * sf], [cf, sp_ * sf, cp * cf]]
    )
    return P2, P3, P4, P5


def J1_J2(J) -> tuple[np.ndarray, np.ndarray]:
    """J₁, J₂ of Eq. (8-52), corrected: ω × Jω = J₁(ω_x², ω_y², ω_z²) + J₂(ω_yω_z, ω_zω_x, ω_xω_y).
    ``J`` is the standard inertia tensor (8-49) (off-diagonal = −products of inertia)."""
    J = np.asarray(J, dtype=float)
    # with products P_xy = −J[0,1] etc.
    Pxy, Pxz, Pyz = -J[0, 1], -J[0, 2], -J[1, 2]
    Jxx, Jyy, Jzz = J[0, 0], J[1, 1], J[2, 2]
    J1 = np.array([[0, -Pyz, Pyz], [Pxz, 0, -Pxz], [-Pxy, Pxy, 0]])
    J2 = np.array([[Jzz - Jyy, Pxy, -Pxz], [-Pxy, Jxx - Jzz, Pyz], [Pxz, -Pyz, Jyy - Jxx]])
    return J1, J2


def J1_J2_printed(J):
    """(8-52) as printed (l. 6253–6257), with the printed product vector (ω_xω_y, ω_xω_z,
    ω_yω_z)."""
    J = np.asarray(J, dtype=float)
    Pxy, Pxz, Pyz = -J[0, 1], -J[0, 2], -J[1, 2]
    Jxx, Jyy, Jzz = J[0, 0], J[1, 1], J[2, 2]
    J1 = np.array([[0, -Pxy, Pyz], [Pxy, 0, -Pxz], [-Pyz, Pxz, 0]])
    J2 = np.array([[Jxx - Jyy, Pyz, -Pxz], [-Pyz, Jxx - Jzz, Pxy], [Jzz, -Jyy, Jyy - Jzz]])
    return J1, J2


def body_moment(J, e, ed, edd) -> np.ndarray:
    """Euler moment in the body frame, Eq. (8-57): JΠë + (J₁Π₂+J₂Π₄)ė² + (JΠ₁+J₁Π₃+J₂Π₅)ė×."""
    e, ed, edd = (np.asarray(x, float) for x in (e, ed, edd))
    J = np.asarray(J, float)
    J1, J2 = J1_J2(J)
    P2, P3, P4, P5 = Pi2_to_5(e)
    e2 = ed**2
    ex = np.array([ed[1] * ed[2], ed[2] * ed[0], ed[0] * ed[1]])
    return J @ Pi(e) @ edd + (J1 @ P2 + J2 @ P4) @ e2 + (J @ Pi1(e) + J1 @ P3 + J2 @ P5) @ ex


def DEF(J, e):
    """D, E, F of Eq. (8-60): fixed-frame moment M⁰ = D ë + E ė² + F ė×."""
    R = rotation(e)
    J1, J2 = J1_J2(J)
    P2, P3, P4, P5 = Pi2_to_5(e)
    return R @ J @ Pi(e), R @ (J1 @ P2 + J2 @ P4), R @ (J @ Pi1(e) + J1 @ P3 + J2 @ P5)


def derivative_matrices(e):
    """Θ₁, Θ₂, Ψ₁, Ψ₂, Φ₁, Φ₂ of Eq. (8-65) (first/second derivatives of Θ, Ψ, Φ; the printed
    third rows of Θ₁ and Φ₁ have the wrong sign)."""
    th, ps, ph = e

    def x1(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[0, 0, 0], [0, -s, c], [0, -c, -s]])

    def x2(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[0, 0, 0], [0, -c, -s], [0, s, -c]])

    c, s = np.cos(ps), np.sin(ps)
    Y1 = np.array([[-s, 0, -c], [0, 0, 0], [c, 0, -s]])
    Y2 = np.array([[-c, 0, s], [0, 0, 0], [-s, 0, -c]])
    return x1(th), x2(th), Y1, Y2, x1(ph), x2(ph)


def theta1_printed(theta):
    """Θ₁ as printed (third row (0, cos θ, sin θ)); wrong, for the errata test."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[0, 0, 0], [0, -s, c], [0, c, s]])


def ABC(e):
    """A, B, C (3 × 9) of Eq. (8-68): l̈⁰ = AΛë + BΛė² + CΛė×, Λ = blkdiag(l, l, l) (8-69)."""
    Th, Ps, Ph = passive(e)
    T1, T2, P1, P2, F1, F2 = derivative_matrices(e)
    A = np.hstack([T1.T @ Ps.T @ Ph.T, Th.T @ P1.T @ Ph.T, Th.T @ Ps.T @ F1.T])
    B = np.hstack([T2.T @ Ps.T @ Ph.T, Th.T @ P2.T @ Ph.T, Th.T @ Ps.T @ F2.T])
    C = np.hstack([2 * Th.T @ P1.T @ F1.T, 2 * T1.T @ Ps.T @ F1.T, 2 * T1.T @ P1.T @ Ph.T])
    return A, B, C


def Lam(l) -> np.ndarray:
    """Λ = blkdiag(l, l, l) (9 × 3), Eq. (8-69)."""
    l = np.asarray(l, float).reshape(3, 1)
    out = np.zeros((9, 3))
    for k in range(3):
        out[3 * k : 3 * k + 3, k : k + 1] = l
    return out


@dataclass
class EulerChain:
    """A simple open chain of n rigid links on ball joints (§8-3 definitions).

    ``m[k]`` kg; ``J[k]`` 3 × 3 inertia tensor about the CoM, body axes (8-49); ``d[k]`` first
    joint → CoM (body frame); ``l[k]`` first joint → the next joint (body frame; the last
    link's is unused); ``g`` m/s² with Z up."""

    m: np.ndarray
    J: np.ndarray
    d: np.ndarray
    l: np.ndarray
    g: float = 9.81

    def __post_init__(self):
        self.m = np.asarray(self.m, float).reshape(-1)
        n = self.m.size
        self.J = np.asarray(self.J, float).reshape(n, 3, 3)
        self.d = np.asarray(self.d, float).reshape(n, 3)
        self.l = np.asarray(self.l, float).reshape(n, 3)
        for name, a in (("m", self.m), ("J", self.J), ("d", self.d), ("l", self.l)):
            if not np.all(np.isfinite(a)):
                raise ValueError(f"EulerChain: {name} contains NaN/inf")
        if np.any(self.m <= 0):
            raise InertiaError(
                f"EulerChain: every link needs a positive mass, got {self.m.tolist()}"
            )
        for k, Jk in enumerate(self.J):
            if np.max(np.abs(Jk - Jk.T)) > 1e-12 or np.linalg.eigvalsh(Jk)[0] <= 0:
                raise InertiaError(
                    f"EulerChain: J of link {k + 1} must be symmetric positive definite"
                )

    @property
    def n(self) -> int:
        return self.m.size

    # structure matrices of a simple chain (links i, j = 1..n, joints p = 0..n-1)
    @staticmethod
    def e_ip(i, p):
        return 1.0 if i >= p + 1 else 0.0

    @staticmethod
    def delta(i, j, p):
        return 1.0 if p + 1 <= j <= i - 1 else 0.0

    def _state(self, S, what):
        S = np.asarray(S, float)
        if S.shape != (self.n, 3):
            S = S.reshape(-1)
            if S.size != 3 * self.n:
                raise ValueError(
                    f"{what} must have shape ({self.n}, 3) (θ, ψ, φ per link), got {np.shape(S)}"
                )
            S = S.reshape(self.n, 3)
        if not np.all(np.isfinite(S)):
            raise ValueError(f"{what} contains NaN/inf")
        return S

    def matrices(self, S):
        """The stacked A, B, C (3n × 3n) and G (3n) of Eq. (8-91) in the fixed frame,
        assembled from the blocks of (8-83)/(8-87) (a_p = I)."""
        S = self._state(S, "S")
        n = self.n
        R = [rotation(e) for e in S]
        dW = [R[k] @ self.d[k] for k in range(n)]
        lW = [R[k] @ self.l[k] for k in range(n)]
        abc = [ABC(e) for e in S]
        defs = [DEF(self.J[k], S[k]) for k in range(n)]
        A = np.zeros((3 * n, 3 * n))
        B = np.zeros_like(A)
        C = np.zeros_like(A)
        G = np.zeros(3 * n)
        grav = np.array([0.0, 0.0, self.g])
        for p in range(n):  # joint p (0 = fixed support)
            # lever arms X_ip (8-77/78), i = 1..n (0-based k = i-1)
            X = [
                skew(
                    self.e_ip(i, p) * dW[i - 1]
                    + sum((self.delta(i, j, p) * lW[j - 1] for j in range(1, n + 1)), np.zeros(3))
                )
                for i in range(1, n + 1)
            ]
            # S_jp = Σ_i δ_ij0 m_i X_ip (8-82)
            Sj = [
                sum(
                    (self.delta(i, j, 0) * self.m[i - 1] * X[i - 1] for i in range(1, n + 1)),
                    np.zeros((3, 3)),
                )
                for j in range(1, n + 1)
            ]
            for k in range(1, n + 1):  # link k
                Ak, Bk, Ck = abc[k - 1]
                Dk, Ek, Fk = defs[k - 1]
                Delta_k = Lam(self.d[k - 1])
                Lam_k = Lam(self.l[k - 1])  # γ_kj = [k = j]
                ek = self.e_ip(k, p)
                blk = np.s_[3 * p : 3 * p + 3, 3 * (k - 1) : 3 * k]
                A[blk] = self.m[k - 1] * X[k - 1] @ Ak @ Delta_k + Sj[k - 1] @ Ak @ Lam_k + ek * Dk
                B[blk] = self.m[k - 1] * X[k - 1] @ Bk @ Delta_k + Sj[k - 1] @ Bk @ Lam_k + ek * Ek
                C[blk] = self.m[k - 1] * X[k - 1] @ Ck @ Delta_k + Sj[k - 1] @ Ck @ Lam_k + ek * Fk
            G[3 * p : 3 * p + 3] = sum(self.m[i - 1] * X[i - 1] @ grav for i in range(1, n + 1))
        return A, B, C, G

    @staticmethod
    def _products(Sd):
        Sd2 = (Sd**2).reshape(-1)
        Sx = np.column_stack(
            [Sd[:, 1] * Sd[:, 2], Sd[:, 2] * Sd[:, 0], Sd[:, 0] * Sd[:, 1]]
        ).reshape(-1)
        return Sd2, Sx

    def inverse(self, S, Sd, Sdd) -> np.ndarray:
        """Joint moments Q (n × 3, fixed frame, N m) of Eq. (8-91): row p is the moment that
        joint p (0 = fixed support) exerts on link p+1, about the joint centre."""
        S, Sd, Sdd = self._state(S, "S"), self._state(Sd, "Sd"), self._state(Sdd, "Sdd")
        A, B, C, G = self.matrices(S)
        Sd2, Sx = self._products(Sd)
        return (A @ Sdd.reshape(-1) + B @ Sd2 + C @ Sx + G).reshape(self.n, 3)

    def inverse_direct(self, S, Sd, Sdd) -> np.ndarray:
        """The same moments by the direct sums (8-76) and (8-80), without the A, B, C blocks."""
        S, Sd, Sdd = self._state(S, "S"), self._state(Sd, "Sd"), self._state(Sdd, "Sdd")
        n = self.n
        R = [rotation(e) for e in S]
        Mrot = []
        acc_d, acc_l = [], []
        for k in range(n):
            D, E, F = DEF(self.J[k], S[k])
            e2 = Sd[k] ** 2
            ex = np.array([Sd[k, 1] * Sd[k, 2], Sd[k, 2] * Sd[k, 0], Sd[k, 0] * Sd[k, 1]])
            Mrot.append(D @ Sdd[k] + E @ e2 + F @ ex)
            A, B, C = ABC(S[k])
            acc_d.append(
                A @ Lam(self.d[k]) @ Sdd[k] + B @ Lam(self.d[k]) @ e2 + C @ Lam(self.d[k]) @ ex
            )
            acc_l.append(
                A @ Lam(self.l[k]) @ Sdd[k] + B @ Lam(self.l[k]) @ e2 + C @ Lam(self.l[k]) @ ex
            )
        Xdd = [
            acc_d[i - 1]
            + sum((self.delta(i, j, 0) * acc_l[j - 1] for j in range(1, n + 1)), np.zeros(3))
            for i in range(1, n + 1)
        ]  # (8-76)
        grav = np.array([0.0, 0.0, self.g])
        Q = np.zeros((n, 3))
        for p in range(n):
            for i in range(1, n + 1):
                arm = self.e_ip(i, p) * R[i - 1] @ self.d[i - 1] + sum(
                    (self.delta(i, j, p) * R[j - 1] @ self.l[j - 1] for j in range(1, n + 1)),
                    np.zeros(3),
                )
                Q[p] += (
                    self.m[i - 1] * np.cross(arm, Xdd[i - 1] + grav) + self.e_ip(i, p) * Mrot[i - 1]
                )  # (8-80)
        return Q

    def check_regular(self, S) -> None:
        """Raise :class:`EulerSingularityError` at gimbal lock (|sin ψ_k| < SINGULAR_TOL)."""
        S = self._state(S, "S")
        bad = np.flatnonzero(np.abs(np.sin(S[:, 1])) < SINGULAR_TOL)
        if bad.size:
            k = int(bad[0])
            raise EulerSingularityError(
                f"link {k + 1}: sin ψ = {np.sin(S[k, 1]):.2e}; the X–Y–X angles are singular at ψ "
                "= 0, π (det Π = −sin ψ): choose another reference posture or body axes"
            )

    def forward(self, S, Sd, Q) -> np.ndarray:
        """S̈ = A⁻¹(Q − BṠ² − CṠṠ − G), Eq. (8-92) (rad/s², n × 3), guarded at gimbal lock."""
        S, Sd = self._state(S, "S"), self._state(Sd, "Sd")
        Q = self._state(Q, "Q")
        self.check_regular(S)
        A, B, C, G = self.matrices(S)
        Sd2, Sx = self._products(Sd)
        return np.linalg.solve(A, Q.reshape(-1) - B @ Sd2 - C @ Sx - G).reshape(self.n, 3)

    # ------------------------------------------------------------------ Pinocchio
    def pin_model(self):
        """The same chain with ``JointModelSpherical`` joints (recipe R2): joint k frame = link
        k's body axes at its first joint; joint k+1 at l_k; gravity (0, 0, −g)."""
        model = pin.Model()
        model.gravity.linear = np.array([0.0, 0.0, -self.g])
        parent = 0
        for k in range(self.n):
            pl = pin.SE3(np.eye(3), np.zeros(3) if k == 0 else self.l[k - 1].copy())
            jid = model.addJoint(parent, pin.JointModelSpherical(), pl, f"ball{k}")
            model.appendBodyToJoint(
                jid,
                pin.Inertia(float(self.m[k]), self.d[k].copy(), self.J[k].copy()),
                pin.SE3.Identity(),
            )
            parent = jid
        return model

    def to_pin_state(self, S, Sd, Sdd):
        """Map absolute Euler angles and rates to Pinocchio (q, v, a) of :meth:`pin_model`."""
        S, Sd, Sdd = self._state(S, "S"), self._state(Sd, "Sd"), self._state(Sdd, "Sdd")
        q, v, a = [], [], []
        Rp, wp, wdp = np.eye(3), np.zeros(3), np.zeros(3)
        for k in range(self.n):
            R = rotation(S[k])
            w = Pi(S[k]) @ Sd[k]
            ex = np.array([Sd[k, 1] * Sd[k, 2], Sd[k, 2] * Sd[k, 0], Sd[k, 0] * Sd[k, 1]])
            wd = Pi(S[k]) @ Sdd[k] + Pi1(S[k]) @ ex
            Rrel = Rp.T @ R
            vk = w - Rrel.T @ wp
            ak = wd - Rrel.T @ wdp + np.cross(vk, Rrel.T @ wp)
            q.append(pin.Quaternion(Rrel).coeffs())
            v.append(vk)
            a.append(ak)
            Rp, wp, wdp = R, w, wd
        return np.concatenate(q), np.concatenate(v), np.concatenate(a)


def mixed(A, h, q_rows, Q0, s_cols, Sdd0):
    """Mixed problem (8-93)–(8-96), corrected: some moments Q_0 (rows ``q_rows``) and some
    accelerations S̈_0 (columns ``s_cols``) are known; returns the unknown moments Q_z (the
    other rows) and accelerations S̈_z (the other columns) of Q = A S̈ + h.  Needs
    dim S̈_z = dim Q_0.

        (Q_z; S̈_z) = [[0, −A_0z], [I, −A_zz]]⁻¹ ([[−I, A_00], [0, A_z0]] (Q_0; S̈_0) + (P_0; P_z)
        h)
    """
    A = np.asarray(A, float)
    h = np.asarray(h, float)
    N = A.shape[0]
    r0 = np.asarray(q_rows, int)
    rz = np.setdiff1d(np.arange(N), r0)
    c0 = np.asarray(s_cols, int)
    cz = np.setdiff1d(np.arange(N), c0)
    if r0.size != cz.size:
        raise ValueError(
            f"the mixed problem needs as many known moments as unknown accelerations "
            f"({r0.size} != {cz.size})"
        )
    A00, A0z, Az0, Azz = A[np.ix_(r0, c0)], A[np.ix_(r0, cz)], A[np.ix_(rz, c0)], A[np.ix_(rz, cz)]
    nz, n0 = rz.size, r0.size
    K = np.block([[np.zeros((n0, nz)), -A0z], [np.eye(nz), -Azz]])
    L = np.block([[-np.eye(n0), A00], [np.zeros((nz, n0)), Az0]])
    rhs = L @ np.concatenate([Q0, Sdd0]) + np.concatenate([h[r0], h[rz]])
    sol = np.linalg.solve(K, rhs)
    return sol[:nz], sol[nz:]


def mixed_printed(A, h, q_rows, Q0, s_cols, Sdd0):
    """(8-96) with the printed sign pattern −[[0, −A_0z], [−I, A_zz]]⁻¹[...] (wrong)."""
    A = np.asarray(A, float)
    h = np.asarray(h, float)
    N = A.shape[0]
    r0 = np.asarray(q_rows, int)
    rz = np.setdiff1d(np.arange(N), r0)
    c0 = np.asarray(s_cols, int)
    cz = np.setdiff1d(np.arange(N), c0)
    A00, A0z, Az0, Azz = A[np.ix_(r0, c0)], A[np.ix_(r0, cz)], A[np.ix_(rz, c0)], A[np.ix_(rz, cz)]
    nz, n0 = rz.size, r0.size
    K = np.block([[np.zeros((n0, nz)), -A0z], [-np.eye(nz), Azz]])
    L = np.block([[-np.eye(n0), A00], [np.zeros((nz, n0)), Az0]])
    sol = -np.linalg.solve(K, L @ np.concatenate([Q0, Sdd0]) + np.concatenate([h[r0], h[rz]]))
    return sol[:nz], sol[nz:]
