"""The spatial RCCC four-link mechanism by dual-number matrices (book §5-6 四, Fig. 5-15).

Joint A (axis ŝ₁) is revolute, B, C, D are cylindrical.  Dual angles, Eq. (5-151)
(reconstructed; the OCR writes ε s₁₂ …):

* links  α̂ᵢⱼ = αᵢⱼ + ε aᵢⱼ  (twist + length of the common perpendicular, m);
* joints θ̂ⱼ = θⱼ + ε sⱼ    (rotation + slide along the joint axis, m); s₁ is constant.

Loop equation (5-152) with passive basic screw matrices (Z about k for θ̂ⱼ, X about i for α̂ᵢⱼ):

    θ̂₂ α̂₂₃ θ̂₃ α̂₃₄ θ̂₄ α̂₄₁ θ̂₁ α̂₁₂ = I   ⇔   Ĉ = α̂₁₂ θ̂₁ α̂₄₁ θ̂₄ α̂₃₄ = (θ̂₃ α̂₂₃ θ̂₂)ᵀ = D̂
    (5-153)

Equivalent active SE(3) loop: X(α̂₁₂) Z(θ̂₁) X(α̂₄₁) Z(θ̂₄) X(α̂₃₄) Z(θ̂₃) X(α̂₂₃) Z(θ̂₂) = I with
X(α̂) = R_x(α) T_x(a), Z(θ̂) = R_z(θ) T_z(s).

Solution (book procedure with the recomputed elements, see docs/errata.md — six of the nine
printed c-elements and four d-elements are wrong, including c₃₃ which drives the output):

1. ĉ₃₃(θ̂₁, θ̂₄) = d̂₃₃ = cos α̂₂₃: A cos θ̂₄ + B sin θ̂₄ = cos α̂₂₃ − C.  The real part is the
   spherical four-bar equation (two branches θ₄); the dual part is linear in s₄.
2. θ̂₂ = atan2(ĉ₁₃, −ĉ₂₃) (after dividing by sin α̂₂₃), from d̂₁₃ = sα̂₂₃ sθ̂₂, d̂₂₃ = −sα̂₂₃ cθ̂₂.
3. θ̂₃ = atan2(ĉ₃₁, ĉ₃₂) from d̂₃₁ = sα̂₂₃ sθ̂₃ and d̂₃₂ = sα̂₂₃ cθ̂₃ (the book says c₂₁ = d₂₁;
   it must be c₃₂ = d₃₂).

Velocities and accelerations follow from the loop closure Σ Jⱼ q̇ⱼ = 0 of the joint screws in
the base frame (Pinocchio order (v; ω)) and its derivative Σ Jⱼ q̈ⱼ + Σ [Vⱼ, Jⱼ] q̇ⱼ = 0.
Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..spatial import dual as D
from ..spatial.dual import Dual
from ..spatial.rotations import as_scalar

#: tolerance below which the discriminant / Jacobian counts as a dead point
DEAD_TOL = 1e-9


# ----------------------------------------------------------------------------- inputs
def _dual(x, name: str) -> Dual:
    if isinstance(x, Dual):
        d = x
    else:
        try:
            a, b = x
        except (TypeError, ValueError):
            raise ValueError(
                f"{name} must be a Dual or an (angle, length) pair, got {x!r}"
            ) from None
        d = Dual(float(a), float(b))
    if np.shape(d.real) != () or not (np.isfinite(d.real) and np.isfinite(d.dual)):
        raise ValueError(f"{name} must be a finite scalar dual angle, got {d!r}")
    return Dual(float(d.real), float(d.dual))


@dataclass(frozen=True)
class RCCCGeometry:
    """Constant dimensions: the four link dual angles α̂ᵢⱼ = αᵢⱼ + ε aᵢⱼ (rad, m) and the
    constant offset s₁ of the revolute joint A (m)."""

    alpha12: Dual
    alpha23: Dual
    alpha34: Dual
    alpha41: Dual
    s1: float = 0.0

    def __post_init__(self):
        for n in ("alpha12", "alpha23", "alpha34", "alpha41"):
            object.__setattr__(self, n, _dual(getattr(self, n), n))
        s1 = float(self.s1)
        if not np.isfinite(s1):
            raise ValueError(f"s1 must be finite, got {self.s1!r}")
        object.__setattr__(self, "s1", s1)

    @property
    def scale(self) -> float:
        """Link size (m) for relative tolerances: the largest of |aᵢⱼ|, |s₁| and 1e-3."""
        return max(
            abs(self.alpha12.dual),
            abs(self.alpha23.dual),
            abs(self.alpha34.dual),
            abs(self.alpha41.dual),
            abs(self.s1),
            1e-3,
        )


@dataclass
class RCCCSolution:
    """One assembly branch: dual joint angles θ̂ⱼ = θⱼ + ε sⱼ (rad, m)."""

    branch: int
    theta1: Dual
    theta2: Dual
    theta3: Dual
    theta4: Dual
    closure_residual: float = float("nan")

    @property
    def q(self) -> np.ndarray:
        """Joint vector of :func:`pinocchio_chain`: (θ₁, θ₄, s₄, θ₃, s₃, θ₂, s₂)."""
        return np.array(
            [
                self.theta1.real,
                self.theta4.real,
                self.theta4.dual,
                self.theta3.real,
                self.theta3.dual,
                self.theta2.real,
                self.theta2.dual,
            ]
        )


@dataclass
class RCCCResult:
    """Position analysis: ``status`` is "ok" (two branches), "dead point" (the two branches
    meet; s₄ is not determined by the dual equation), "cannot assemble" (no real θ₄) or
    "degenerate" (sin α₃₄ sin(…) = 0 or sin α₂₃ = 0: the equations do not fix θ₄/θ₂/θ₃)."""

    status: str
    solutions: list[RCCCSolution] = field(default_factory=list)
    message: str = ""

    @property
    def ok(self) -> bool:
        return self.status == "ok"


# ----------------------------------------------------------------------------- matrices
def loop_matrices(g: RCCCGeometry, th1: Dual, th2: Dual, th3: Dual, th4: Dual) -> tuple[Dual, Dual]:
    """(Ĉ, D̂) of Eq. (5-153) as dual matrix products (passive basic matrices (5-146)/(5-149))."""
    C = (
        D.screw_x(g.alpha12)
        @ D.screw_z(th1)
        @ D.screw_x(g.alpha41)
        @ D.screw_z(th4)
        @ D.screw_x(g.alpha34)
    )
    Dm = (D.screw_z(th3) @ D.screw_x(g.alpha23) @ D.screw_z(th2)).T
    return C, Dm


def c_elements(alpha12, alpha41, alpha34, theta1, theta4) -> Dual:
    """The nine elements of Ĉ = α̂₁₂ θ̂₁ α̂₄₁ θ̂₄ α̂₃₄ in closed form, recomputed (book §5-6 lists
    them after (5-153); c₁₂, c₂₂, c₂₃, c₃₁, c₃₂, c₃₃ are misprinted there).  Dual arguments."""
    a12, a41, a34, t1, t4 = (D.Dual.lift(x) for x in (alpha12, alpha41, alpha34, theta1, theta4))
    c12, s12, c41, s41, c34, s34 = (
        D.cos(a12),
        D.sin(a12),
        D.cos(a41),
        D.sin(a41),
        D.cos(a34),
        D.sin(a34),
    )
    ct1, st1, ct4, st4 = D.cos(t1), D.sin(t1), D.cos(t4), D.sin(t4)
    u = ct1 * st4 + c41 * st1 * ct4
    v = ct4 * (c12 * c41 * ct1 - s12 * s41) - c12 * st1 * st4
    w = c41 * s12 + s41 * c12 * ct1
    x = s12 * st1 * st4 - ct4 * (s41 * c12 + c41 * s12 * ct1)
    y = c41 * c12 - s41 * s12 * ct1
    e = [
        [ct1 * ct4 - c41 * st1 * st4, c34 * u - s34 * s41 * st1, s34 * u + c34 * s41 * st1],
        [
            -c12 * st1 * ct4 + st4 * (s41 * s12 - c41 * c12 * ct1),
            c34 * v - s34 * w,
            s34 * v + c34 * w,
        ],
        [
            s12 * st1 * ct4 + st4 * (s41 * c12 + c41 * s12 * ct1),
            c34 * x - s34 * y,
            s34 * x + c34 * y,
        ],
    ]
    return Dual(
        np.array([[float(z.real) for z in r] for r in e]),
        np.array([[float(z.dual) for z in r] for r in e]),
    )


def d_elements(alpha23, theta2, theta3) -> Dual:
    """The nine elements of D̂ = (θ̂₃ α̂₂₃ θ̂₂)ᵀ in closed form (book prints d₁₂, d₁₃, d₂₂, d₃₂
    wrongly).  Dual arguments."""
    a23, t2, t3 = (D.Dual.lift(x) for x in (alpha23, theta2, theta3))
    ca, sa, c2, s2, c3, s3 = D.cos(a23), D.sin(a23), D.cos(t2), D.sin(t2), D.cos(t3), D.sin(t3)
    e = [
        [c2 * c3 - ca * s2 * s3, -c2 * s3 - ca * s2 * c3, sa * s2],
        [s2 * c3 + ca * c2 * s3, -s2 * s3 + ca * c2 * c3, -sa * c2],
        [sa * s3, sa * c3, ca],
    ]
    return Dual(
        np.array([[float(z.real) for z in r] for r in e]),
        np.array([[float(z.dual) for z in r] for r in e]),
    )


def _X(a: Dual) -> pin.SE3:
    """Active screw along x: R_x(α) T_x(a) = exp6((a, 0, 0; α, 0, 0))."""
    return pin.exp6(pin.Motion(np.array([a.dual, 0.0, 0.0]), np.array([a.real, 0.0, 0.0])))


def _Z(t: Dual) -> pin.SE3:
    return pin.exp6(pin.Motion(np.array([0.0, 0.0, t.dual]), np.array([0.0, 0.0, t.real])))


def loop_se3(g: RCCCGeometry, sol: RCCCSolution) -> pin.SE3:
    """The active loop product X(α̂₁₂)Z(θ̂₁)X(α̂₄₁)Z(θ̂₄)X(α̂₃₄)Z(θ̂₃)X(α̂₂₃)Z(θ̂₂) (= I when
    closed)."""
    M = pin.SE3.Identity()
    for f in (
        _X(g.alpha12),
        _Z(sol.theta1),
        _X(g.alpha41),
        _Z(sol.theta4),
        _X(g.alpha34),
        _Z(sol.theta3),
        _X(g.alpha23),
        _Z(sol.theta2),
    ):
        M = M * f
    return M


def closure_residual(g: RCCCGeometry, sol: RCCCSolution) -> float:
    """|log6(loop)| with the translation part divided by the link size (dimensionless)."""
    err = pin.log6(loop_se3(g, sol)).vector
    return float(max(np.abs(err[:3]).max() / g.scale, np.abs(err[3:]).max()))


# ----------------------------------------------------------------------------- position
def rccc_position(g: RCCCGeometry, theta1: float, tol: float = DEAD_TOL) -> RCCCResult:
    """Both assembly branches of the RCCC mechanism at input angle θ₁ (rad), book §5-6 四.

    Returns an :class:`RCCCResult` whose status says "cannot assemble" / "dead point" /
    "degenerate" instead of raising or returning NaN."""
    th1_real = as_scalar(theta1, "theta1")
    th1 = Dual(th1_real, g.s1)
    a12, a23, a34, a41 = g.alpha12, g.alpha23, g.alpha34, g.alpha41
    # c33 = A cos θ4 + B sin θ4 + C  (corrected element, dual)
    s12, c12, s41, c41, s34, c34 = (
        D.sin(a12),
        D.cos(a12),
        D.sin(a41),
        D.cos(a41),
        D.sin(a34),
        D.cos(a34),
    )
    ct1, st1 = D.cos(th1), D.sin(th1)
    A = -s34 * (s41 * c12 + c41 * s12 * ct1)
    B = s34 * s12 * st1
    C = c34 * (c41 * c12 - s41 * s12 * ct1)
    Dd = D.cos(a23) - C
    a, b, d = float(A.real), float(B.real), float(Dd.real)
    rho = float(np.hypot(a, b))
    if rho < tol:
        return RCCCResult(
            "degenerate",
            [],
            f"the input-output equation does not depend on θ4 at θ1 = {th1_real:.6g} "
            f"(|A|, |B| = {abs(a):.2e}, {abs(b):.2e}; sin α34 or sin α12 ≈ 0)",
        )
    if abs(float(np.sin(a23.real))) < tol:
        return RCCCResult(
            "degenerate", [], f"sin α23 = {np.sin(a23.real):.2e}: θ2 and θ3 are not determined"
        )
    ratio = d / rho
    if abs(ratio) > 1.0 + tol:
        return RCCCResult(
            "cannot assemble",
            [],
            f"no real θ4 at θ1 = {th1_real:.6g}: |cos α23 − C| / √(A² + B²) = {abs(ratio):.6g} > 1",
        )
    phi0 = float(np.arctan2(b, a))
    delta = float(np.arccos(np.clip(ratio, -1.0, 1.0)))
    dead = abs(abs(ratio) - 1.0) <= tol or delta < 1e-7 or np.pi - delta < 1e-7
    sols = []
    for branch, sgn in ((0, 1.0), (1, -1.0)):
        t4 = float(np.angle(np.exp(1j * (phi0 + sgn * delta))))
        c4, s4 = np.cos(t4), np.sin(t4)
        den = b * c4 - a * s4
        if dead or abs(den) < tol * max(1.0, rho):
            return RCCCResult(
                "dead point",
                [],
                f"θ1 = {th1_real:.6g} is a dead point: the two branches meet at θ4 = {t4:.6g} "
                f"and the slide s4 is not determined (∂c33/∂θ4 = {den:.2e})",
            )
        s4_ = (float(Dd.dual) - float(A.dual) * c4 - float(B.dual) * s4) / den
        th4 = Dual(t4, s4_)
        Cm = c_elements(a12, a41, a34, th1, th4)
        sa = D.sin(a23)
        th2 = D.atan2(Cm[0, 2] / sa, -Cm[1, 2] / sa)
        th3 = D.atan2(Cm[2, 0] / sa, Cm[2, 1] / sa)
        sol = RCCCSolution(
            branch,
            th1,
            Dual(float(th2.real), float(th2.dual)),
            Dual(float(th3.real), float(th3.dual)),
            th4,
        )
        sol.closure_residual = closure_residual(g, sol)
        sols.append(sol)
    return RCCCResult("ok", sols, "")


# ----------------------------------------------------------------------------- velocity,
# acceleration
def _joint_screws(g: RCCCGeometry, sol: RCCCSolution) -> list[np.ndarray]:
    """Unit joint twists (v; ω) in the base frame, in the order of :attr:`RCCCSolution.q`:
    (θ₁, θ₄, s₄, θ₃, s₃, θ₂, s₂)."""
    rz = np.array([0.0, 0, 0, 0, 0, 1.0])
    pz = np.array([0.0, 0, 1.0, 0, 0, 0])
    M = _X(g.alpha12) * _Z(sol.theta1)
    out = [M.action @ rz]
    for link, th in ((g.alpha41, sol.theta4), (g.alpha34, sol.theta3), (g.alpha23, sol.theta2)):
        M = M * _X(link) * _Z(th)
        out += [M.action @ rz, M.action @ pz]
    return out


@dataclass
class RCCCRates:
    """Joint rates of one branch in the order (θ₁, θ₄, s₄, θ₃, s₃, θ₂, s₂) (rad/s, m/s, or
    rad/s², m/s²).  ``status`` is "ok" or "dead point" (the 6×6 closure Jacobian is singular)."""

    status: str
    rates: np.ndarray
    message: str = ""

    def __getitem__(self, name: str) -> float:
        return float(self.rates[_NAMES.index(name)])


_NAMES = ["theta1", "theta4", "s4", "theta3", "s3", "theta2", "s2"]


def _solve(J: np.ndarray, rhs: np.ndarray, tol: float) -> tuple[str, np.ndarray, str]:
    sv = np.linalg.svd(J, compute_uv=False)
    if sv[-1] < tol * sv[0]:
        return (
            "dead point",
            np.zeros(6),
            f"closure Jacobian is singular (σ_min/σ_max = {sv[-1] / sv[0]:.2e})",
        )
    return "ok", np.linalg.solve(J, rhs), ""


def rccc_velocity(
    g: RCCCGeometry, sol: RCCCSolution, theta1_dot: float, tol: float = DEAD_TOL, _screws=None
) -> RCCCRates:
    """Joint rates from Σ Jⱼ q̇ⱼ = 0 (loop closure differentiated once), input θ̇₁ (rad/s)."""
    w1 = as_scalar(theta1_dot, "theta1_dot")
    S = _joint_screws(g, sol) if _screws is None else _screws
    J = np.column_stack(S[1:])
    st, x, msg = _solve(J, -S[0] * w1, tol)
    return RCCCRates(st, np.concatenate([[w1], x]), msg)


def rccc_acceleration(
    g: RCCCGeometry,
    sol: RCCCSolution,
    theta1_dot: float,
    theta1_ddot: float,
    velocity: RCCCRates | None = None,
    tol: float = DEAD_TOL,
) -> RCCCRates:
    """Joint accelerations from Σ Jⱼ q̈ⱼ + Σⱼ [Vⱼ₋, Jⱼ] q̇ⱼ = 0, where Vⱼ₋ is the base-frame
    twist of the link carrying joint j (sum of the upstream Jᵢ q̇ᵢ)."""
    a1 = as_scalar(theta1_ddot, "theta1_ddot")
    S = _joint_screws(g, sol)
    vel = velocity or rccc_velocity(g, sol, theta1_dot, tol, _screws=S)
    if vel.status != "ok":
        return RCCCRates(vel.status, np.zeros(7), vel.message)
    qd = vel.rates
    bias = np.zeros(6)
    V = np.zeros(6)
    for Sj, qdj in zip(S, qd):
        bias += pin.Motion(V).cross(pin.Motion(Sj)).vector * qdj
        V = V + Sj * qdj
    J = np.column_stack(S[1:])
    st, x, msg = _solve(J, -bias - S[0] * a1, tol)
    return RCCCRates(st, np.concatenate([[a1], x]), msg)


# ----------------------------------------------------------------------------- Pinocchio model
def pinocchio_chain(g: RCCCGeometry) -> tuple[pin.Model, int]:
    """The RCCC loop cut at the base, as a Pinocchio open chain: joints
    RZ θ₁ | RZ θ₄, PZ s₄ | RZ θ₃, PZ s₃ | RZ θ₂, PZ s₂ with placements X(α̂₁₂), T_z(s₁)X(α̂₄₁),
    X(α̂₃₄), X(α̂₂₃).  Returns (model, frame id of the cut end).  When the loop is closed the
    end frame sits at the identity with zero velocity and zero classical acceleration."""
    model = pin.Model()
    placements = [
        _X(g.alpha12),
        pin.SE3(np.eye(3), np.array([0.0, 0.0, g.s1])) * _X(g.alpha41),
        _X(g.alpha34),
        _X(g.alpha23),
    ]
    parent = 0
    inertia = pin.Inertia.FromSphere(1.0, 0.05)
    for k, M in enumerate(placements):
        parent = model.addJoint(parent, pin.JointModelRZ(), M, f"rot{k}")
        model.appendBodyToJoint(parent, inertia, pin.SE3.Identity())
        if k > 0:
            parent = model.addJoint(parent, pin.JointModelPZ(), pin.SE3.Identity(), f"slide{k}")
            model.appendBodyToJoint(parent, inertia, pin.SE3.Identity())
    fid = model.addFrame(pin.Frame("cut", parent, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return model, fid
