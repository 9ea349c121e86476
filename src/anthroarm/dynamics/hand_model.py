r"""The prosthetic-hand Lagrange model of book §8-4, Eqs. (8-97)–(8-112).

A chain of N ≤ 6 revolute joints (the book's limit; the algorithm itself has none), joint i
turning about the unit axis ``x_i`` ∈ {i, j, k} of its link frame.  At θ = 0 every link frame
is parallel to the base frame, whose **z axis points vertically down** (gravity = +g ẑ).
Inputs (book l. 6768–6790), SI units:

* ``axes[i]`` ∈ {"i", "j", "k"} (also "x", "y", "z"),
* ``l[0]`` base → joint 1 (base frame); ``l[i]`` joint i → joint i+1 (frame i), i = 1..N
  (``l[N]`` runs to the fingertip and carries no joint),
* ``r[i]`` joint i → CoM of link i (frame i), ``m[i]`` kg, ``J[i]`` scalar moment of inertia
  about the CoM (kg m²; exact only for an isotropic body — a 3×3 tensor is accepted too),
* ``xi`` viscous damping, N m s/rad (scalar or per joint).

Kinematics (8-98): E_{1,i} = E^{x_1θ_1}⋯E^{x_iθ_i} (8-112), r_i = r_{i−1} + E_{1,i−1}(l_{i−1} −
r_{i−1}) + E_{1,i} r_i. Kinetic energy (8-100)–(8-105): T = ½ θ̇ᵀ(U + W)θ̇, U = Σ m_i
(∂r_i/∂θ)ᵀ(∂r_i/∂θ), W = Σ J_i E_iᵀE_i (E_i = angular Jacobian (8-103)).  Potential (8-106): V = −Σ
m_i g k⁰·r_i. Equation of motion (8-109), with the gravity sign corrected (see ``docs/errata.md``):

.. math:: (U+W)\ddot\theta + \partial V/\partial\theta = F - \xi\dot\theta,\qquad
          \partial V/\partial\theta = -\sum_i m_i g\,(\partial r_i/\partial\theta)^T k^0

The book drops the velocity-product (Coriolis/centrifugal) terms; :meth:`HandModel.coriolis`
gives them (from the generated Lagrange code of the same model) and
:func:`coriolis_over_grasp` measures how large they are.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import InertiaError
from ..spatial.rotations import rot
from .lagrange import load
from .profiles import minimum_jerk  # re-exported: aa.dynamics.hand_model.minimum_jerk

#: Δ^x of (8-111): dE^{xθ}/dθ = Δ^x E^{xθ} (skew matrices of the unit axes, corrected Δ^i)
DELTA = {
    "i": np.array([[0.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
    "j": np.array([[0.0, 0, 1], [0, 0, 0], [-1, 0, 0]]),
    "k": np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 0]]),
}
#: Δ^i as printed at l. 6725 (third row zero): wrong, kept for the errata test
DELTA_I_PRINTED = np.array([[0.0, 0, 0], [0, 0, -1], [0, 0, 0]])
UNIT = {"i": np.array([1.0, 0, 0]), "j": np.array([0, 1.0, 0]), "k": np.array([0, 0, 1.0])}
_ALIAS = {"x": "i", "y": "j", "z": "k", "i": "i", "j": "j", "k": "k"}


def elementary_rotation(axis: str, theta: float) -> np.ndarray:
    """E^{xθ} of Eq. (8-99): active rotation about the unit axis i, j or k by θ (rad)."""
    return rot("xyz"["ijk".index(_ALIAS[axis])], theta)


@dataclass
class HandModel:
    """Input data of the §8-4 program (see the module docstring)."""

    axes: list
    l: np.ndarray
    r: np.ndarray
    m: np.ndarray
    J: object
    xi: object = 0.0
    g: float = 9.81
    name: str = "hand"
    _dyn: object = field(default=None, repr=False)

    def __post_init__(self):
        self.axes = [_ALIAS.get(str(a).lower()) for a in self.axes]
        n = len(self.axes)
        if any(a is None for a in self.axes):
            raise ValueError(f"axes must be 'i', 'j' or 'k' (or x, y, z), got {self.axes}")
        if n < 1:
            raise ValueError("the hand needs at least one joint")
        self.l = np.asarray(self.l, dtype=float).reshape(-1, 3)
        self.r = np.asarray(self.r, dtype=float).reshape(-1, 3)
        self.m = np.asarray(self.m, dtype=float).reshape(-1)
        if self.l.shape[0] != n + 1 or self.r.shape[0] != n or self.m.shape[0] != n:
            raise ValueError(
                f"{self.name}: need l (N+1, 3), r (N, 3), m (N,) for N = {n}; got "
                f"{self.l.shape}, {self.r.shape}, {self.m.shape}"
            )
        J = np.asarray(self.J, dtype=float)
        self.J = np.stack([np.eye(3) * j for j in J]) if J.ndim == 1 else J.reshape(n, 3, 3)
        for name, a in (("l", self.l), ("r", self.r), ("m", self.m), ("J", self.J)):
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{self.name}: {name} contains NaN/inf")
        if np.any(self.m < 0) or np.all(self.m == 0):
            raise InertiaError(
                f"{self.name}: masses must be >= 0 and not all zero, got {self.m.tolist()}"
            )
        for i, Ji in enumerate(self.J):
            if np.linalg.eigvalsh(0.5 * (Ji + Ji.T))[0] < -1e-15:
                raise InertiaError(f"{self.name}: J of link {i + 1} is not positive semidefinite")
        self.xi = np.broadcast_to(np.asarray(self.xi, dtype=float), (n,)).copy()
        if not np.all(np.isfinite(self.xi)) or np.any(self.xi < 0):
            raise ValueError(
                f"{self.name}: damping xi must be finite and >= 0, got {self.xi.tolist()}"
            )

    @property
    def n(self) -> int:
        return len(self.axes)

    def _theta(self, th, what="theta"):
        th = np.asarray(th, dtype=float)
        if th.shape != (self.n,):
            raise ValueError(f"{self.name}: {what} must have shape ({self.n},), got {th.shape}")
        if not np.all(np.isfinite(th)):
            raise ValueError(f"{self.name}: {what} contains NaN/inf: {th.tolist()}")
        return th

    # ------------------------------------------------------------------ book recursion
    def terms(self, theta):
        """The book's algorithm (8-110)–(8-112): returns ``(UW, dVdtheta, dr)`` with the
        inertia matrix U + W (8-105), the gravity vector ∂V/∂θ (8-107, corrected sign) and
        ``dr[i]`` = ∂r_i/∂θ (3 × N) for every link."""
        th = self._theta(theta)
        N = self.n
        E = np.eye(3)
        Uprev: list[np.ndarray] = []
        drp = np.zeros((3, N))
        rprev, lprev = np.zeros(3), self.l[0]
        Ew = np.zeros((3, N))
        UW = np.zeros((N, N))
        dV = np.zeros(N)
        k0 = np.array([0.0, 0.0, 1.0])  # base z axis, pointing down
        drs = []
        for i in range(N):
            Ri = elementary_rotation(self.axes[i], th[i])
            Ei = E @ Ri  # (8-112)
            Ucur = [Uk @ Ri for Uk in Uprev] + [E @ DELTA[self.axes[i]] @ Ri]  # (8-111)
            dr = drp.copy()
            if i > 0:
                for k in range(i):
                    dr[:, k] += Uprev[k] @ (lprev - rprev)  # (8-110)
            for k in range(i + 1):
                dr[:, k] += Ucur[k] @ self.r[i]
            Ew[:, i] = Ei @ UNIT[self.axes[i]]  # (8-103): columns accumulate
            Ii = Ei @ self.J[i] @ Ei.T  # = J_i I for the scalar model
            UW += self.m[i] * dr.T @ dr + Ew.T @ Ii @ Ew  # (8-105)
            dV += -self.m[i] * self.g * dr.T @ k0  # (8-107), corrected (8-109) sign
            drs.append(dr.copy())
            drp, E, Uprev, rprev, lprev = dr, Ei, Ucur, self.r[i], self.l[i + 1]
        return UW, dV, drs

    def positions(self, theta) -> np.ndarray:
        """CoM positions r_i⁰ (N × 3, base frame, z down) by Eq. (8-98)."""
        th = self._theta(theta)
        E = np.eye(3)
        p = self.l[0].copy()  # joint 1
        out = []
        for i in range(self.n):
            E = E @ elementary_rotation(self.axes[i], th[i])
            out.append(p + E @ self.r[i])
            p = p + E @ self.l[i + 1]
        return np.array(out)

    def inertia_matrix(self, theta) -> np.ndarray:
        """U + W, Eq. (8-105), kg m²."""
        return self.terms(theta)[0]

    def gravity(self, theta) -> np.ndarray:
        """∂V/∂θ, Eqs. (8-107)/(8-109) with the corrected sign, N m."""
        return self.terms(theta)[1]

    def gravity_printed(self, theta) -> np.ndarray:
        """(8-109) as printed: +Σ m_i g k⁰·∂r_i/∂θ (the wrong sign; for the errata test)."""
        return -self.gravity(theta)

    def inverse(self, theta, thetadot, thetaddot, coriolis: bool = False) -> np.ndarray:
        """Drive torques F = (U+W)θ̈ + ∂V/∂θ + ξθ̇ (8-109); ``coriolis=True`` adds the velocity
        terms C(θ,θ̇)θ̇ the book drops."""
        UW, dV, _ = self.terms(theta)
        thd = self._theta(thetadot, "thetadot")
        F = UW @ self._theta(thetaddot, "thetaddot") + dV + self.xi * thd
        if coriolis:
            F = F + self.coriolis(theta, thd)
        return F

    def forward(self, theta, thetadot, F, coriolis: bool = False) -> np.ndarray:
        """θ̈ = (U+W)⁻¹(F − ξθ̇ − ∂V/∂θ [− Cθ̇]), the program's function (3), rad/s²."""
        UW, dV, _ = self.terms(theta)
        thd = self._theta(thetadot, "thetadot")
        rhs = self._theta(F, "F") - self.xi * thd - dV
        if coriolis:
            rhs = rhs - self.coriolis(theta, thd)
        return np.linalg.solve(UW, rhs)

    # ------------------------------------------------------------------ Pinocchio / Lagrange
    def pin_model(self):
        """The same hand as a ``pin.Model`` (recipe R1 of the notes): joint 1 at l[0], joint
        i+1 at l[i] in frame i, RX/RY/RZ joints, isotropic (or the given) inertia about the CoM,
        gravity +g ẑ (z down)."""
        model = pin.Model()
        model.name = self.name
        model.gravity.linear = np.array([0.0, 0.0, self.g])
        jt = {"i": pin.JointModelRX, "j": pin.JointModelRY, "k": pin.JointModelRZ}
        parent = 0
        for i in range(self.n):
            jid = model.addJoint(
                parent, jt[self.axes[i]](), pin.SE3(np.eye(3), self.l[i].copy()), f"joint{i + 1}"
            )
            model.appendBodyToJoint(
                jid,
                pin.Inertia(float(self.m[i]), self.r[i].copy(), self.J[i].copy()),
                pin.SE3.Identity(),
            )
            parent = jid
        model.addFrame(
            pin.Frame(
                "tip", parent, pin.SE3(np.eye(3), self.l[self.n].copy()), pin.FrameType.OP_FRAME
            )
        )
        return model

    @property
    def lagrange(self):
        """Generated Lagrange code (:mod:`.lagrange`) of :meth:`pin_model`."""
        if self._dyn is None:
            self._dyn = load(self.pin_model(), name=self.name)
        return self._dyn

    def coriolis(self, theta, thetadot) -> np.ndarray:
        """C(θ,θ̇)θ̇ (Christoffel form): the velocity-product terms of (8-107) the book drops."""
        return self.lagrange.coriolis(self._theta(theta), self._theta(thetadot, "thetadot"))


def default_hand(xi: float = 0.002) -> HandModel:
    """A 3-joint prosthetic finger hanging down the base z axis (z down): MCP abduction about
    j, MCP and PIP flexion about i.  Segment lengths 45/25/20 mm, masses 30/15/10 g, uniform
    rods (J = m L²/12).  The book prints no numbers (Fig. 8-4 is lost); these are typical
    adult index-finger values."""
    L = np.array([0.045, 0.025, 0.020])
    m = np.array([0.030, 0.015, 0.010])
    l = np.vstack([np.zeros(3), np.column_stack([np.zeros(3), np.zeros(3), L])])
    r = np.column_stack([np.zeros(3), np.zeros(3), L / 2])
    return HandModel(axes=["j", "i", "i"], l=l, r=r, m=m, J=m * L**2 / 12, xi=xi, name="finger3")


def coriolis_over_grasp(
    hand: HandModel | None = None, closed=(0.2, 1.2, 1.4), duration: float = 0.3, samples: int = 61
):
    """How large are the terms the book drops?  Along a minimum-jerk grasp from θ = 0 to
    ``closed`` (rad) in ``duration`` s, returns a dict of time, the book's torque
    (U+W)θ̈ + ∂V/∂θ + ξθ̇, the full torque (plus Cθ̇), the Coriolis term and the ratio
    max|Cθ̇| / max|F_full| per joint."""
    hand = hand or default_hand()
    t = np.linspace(0.0, duration, samples)
    th, thd, thdd = minimum_jerk(np.zeros(hand.n), closed, duration, t)
    F_book = np.array([hand.inverse(a, b, c) for a, b, c in zip(th, thd, thdd)])
    C = np.array([hand.coriolis(a, b) for a, b in zip(th, thd)])
    F_full = F_book + C
    ratio = np.max(np.abs(C), axis=0) / np.maximum(np.max(np.abs(F_full), axis=0), 1e-300)
    return dict(t=t, theta=th, thetadot=thd, F_book=F_book, F_full=F_full, coriolis=C, ratio=ratio)


def plot_coriolis_over_grasp(result: dict | None = None, ax=None):
    """Plot the dropped Coriolis torques against the full torque along the grasp."""
    import matplotlib.pyplot as plt

    res = result or coriolis_over_grasp()
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 3.5))
    for j in range(res["F_full"].shape[1]):
        (line,) = ax.plot(res["t"], res["F_full"][:, j] * 1e3, label=f"joint {j + 1}: full τ")
        ax.plot(
            res["t"],
            res["coriolis"][:, j] * 1e3,
            "--",
            color=line.get_color(),
            label=f"joint {j + 1}: Cθ̇ ({100 * res['ratio'][j]:.0f} % of max|τ|)",
        )
    ax.set_xlabel("t [s]")
    ax.set_ylabel("torque [mN m]")
    ax.set_title("§8-4 hand: velocity terms the book drops, along a grasp")
    ax.legend(fontsize=7)
    return ax
