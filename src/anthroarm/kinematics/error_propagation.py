"""First-order error propagation and Monte Carlo tolerance analysis (book §6-6, Eq.
(6-117)–(6-119)).

The hand position is x = F(q₁…qₙ, L₁…L_k) (6-117); to first order (6-118)

    Δx = J_q Δq + J_L ΔL,    J_q = ∂F/∂q (the frame Jacobian),  J_L = ∂F/∂L,

the "error transfer coefficients" (误差的传递系数).  Δq are joint-variable errors (rad or m),
ΔL manufacturing errors of the link dimensions (m).

Link parameters of any robot: every constant translation of the kinematic tree on the path
from the base to the frame — the joint placements of ``robot.chain`` and the frame placement —
is a *link*; its parameters are

* ``mode="length"``: its length L = |t| along its own direction t/|t| (the book's ΔL), or
* ``mode="components"``: its three components along the parent joint's axes (x, y, z), which
  also covers lateral manufacturing errors.

A change δ of parameter k along unit direction d (in the parent joint's frame) moves every
downstream point by R_parent d δ without rotating anything, so the book's coefficient is

    ∂x/∂L_k = R_parent(k) d_k    (world axes),

which for the §6-3 arm is (6-119): ∂P_H/∂l₁ = −e_{·3}, ∂P_H/∂l₂ = −w_{·3}, ∂P_H/∂l₃ = −h_{·3}
(:func:`~anthroarm.models.human.human_arm7_length_jacobian`, the arm's printed form, declared
in its spec).
:func:`length_jacobian_fd` checks it by central finite differences over copies of the
Pinocchio model with perturbed placements.

Errors are reported as 6-vectors (Δp; Δφ) in world axes (LOCAL_WORLD_ALIGNED): Δp the frame
origin displacement (m), Δφ the small rotation vector (rad); ΔL does not rotate anything.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from tqdm.auto import tqdm

from ..spatial.rotations import rot_axis


# ----------------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class LinkParameter:
    """One dimension of the arm.  ``kind`` "joint": the placement of joint ``index`` in its
    parent joint; "frame": the placement of frame ``index`` in its parent joint.  ``direction``
    is the unit direction (parent-joint frame) along which the parameter moves the placement;
    ``nominal`` its nominal value (m)."""

    name: str
    kind: str
    index: int
    direction: np.ndarray
    nominal: float


def link_parameters(
    robot, frame=None, mode: str = "length", tol: float = 1e-12
) -> list[LinkParameter]:
    """The link dimensions that move ``frame`` (default: the tool), in base-to-tip order, read
    from ``robot.chain``: the placement of every joint on the path (mimic joints included) and
    the frame's placement in its joint.

    ``mode="length"``: one parameter per nonzero placement translation (its length);
    ``mode="components"``: three per placement on the path (x, y, z in the parent frame),
    including zero ones.  ``LinkParameter.index`` is the Pinocchio joint id (chain index + 1)
    or frame id."""
    if mode not in ("length", "components"):
        raise ValueError(f"mode must be 'length' or 'components', got {mode!r}")
    chain = robot.chain
    f = chain.frame(robot.frame_id(frame))
    items = [
        ("joint", i + 1, chain.joints[i].name, chain.joints[i].translation)
        for i in chain.path(f.index)
    ]
    items.append(("frame", f.index, f.name, f.translation))
    out = []
    for kind, idx, name, t in items:
        t = np.array(t, float)
        if mode == "length":
            n = float(np.linalg.norm(t))
            if n > tol:
                out.append(LinkParameter(f"{name}.length", kind, idx, t / n, n))
        else:
            for a, e in zip("xyz", np.eye(3)):
                out.append(LinkParameter(f"{name}.{a}", kind, idx, e.copy(), float(t @ e)))
    return out


def _params(robot, frame, params, mode):
    return link_parameters(robot, frame, mode) if params is None else list(params)


def _parent_joint(chain, p: LinkParameter) -> int:
    """Pinocchio id of the joint whose frame ``p`` is expressed in (0: the base)."""
    return (
        chain.joints[p.index - 1].parent + 1
        if p.kind == "joint"
        else chain.frames[p.index].joint + 1
    )


# ----------------------------------------------------------------------------- Jacobians
def length_jacobian(robot, q, frame=None, params=None, mode: str = "length") -> np.ndarray:
    """J_L = ∂x/∂L, Eq. (6-118), 6 × n_L (rows (v; ω), world axes; ω rows are zero):
    column k = R_parent(k) d_k."""
    q = robot.check_q(q)
    if q.ndim != 1:
        raise ValueError(f"length_jacobian takes one configuration, got shape {q.shape}")
    ps = _params(robot, frame, params, mode)
    data = robot.data
    pin.forwardKinematics(robot.model, data, q)
    J = np.zeros((6, len(ps)))
    for k, p in enumerate(ps):
        J[:3, k] = data.oMi[_parent_joint(robot.chain, p)].rotation @ p.direction
    return J


def _perturbed_model(model: pin.Model, p: LinkParameter, delta: float) -> pin.Model:
    m = model.copy()
    if p.kind == "joint":
        M = m.jointPlacements[p.index].copy()
        M.translation = M.translation + delta * p.direction
        m.jointPlacements[p.index] = M
    else:
        f = m.frames[p.index]
        M = f.placement.copy()
        M.translation = M.translation + delta * p.direction
        f.placement = M
        m.frames[p.index] = f
    return m


def length_jacobian_fd(
    robot, q, frame=None, params=None, mode: str = "length", h: float = 1e-3
) -> np.ndarray:
    """J_L by central finite differences over Pinocchio models whose joint / frame placements
    are perturbed by ±h (m) along each parameter (the oracle for :func:`length_jacobian`).
    The pose is affine in each placement translation, so the differences are exact up to
    rounding for any h.
    Rows (v; ω), world axes; the ω rows measure any spurious rotation (log3)."""
    q = robot.check_q(q)
    ps = _params(robot, frame, params, mode)
    fid = robot.frame_id(frame)
    J = np.zeros((6, len(ps)))
    for k, p in enumerate(ps):
        poses = []
        for d in (h, -h):
            m = _perturbed_model(robot.model, p, d)
            dd = m.createData()
            pin.framesForwardKinematics(m, dd, q)
            poses.append(dd.oMf[fid].copy())
        J[:3, k] = (poses[0].translation - poses[1].translation) / (2 * h)
        J[3:, k] = pin.log3(poses[0].rotation @ poses[1].rotation.T) / (2 * h)
    return J


@dataclass
class ErrorPropagation:
    """Δx = J_q Δq + J_L ΔL (6-118), rows (Δp; Δφ) in world axes."""

    dx: np.ndarray
    Jq: np.ndarray
    JL: np.ndarray
    params: list[LinkParameter]

    @property
    def dp(self) -> np.ndarray:
        return self.dx[:3]


def tolerance_vector(x, n: int, name: str) -> np.ndarray:
    """``x`` as a finite vector of ``n`` values: ``None`` -> zeros, a scalar -> ``n`` copies;
    raises :class:`ValueError` naming ``name`` for another shape or a NaN / infinite value."""
    a = np.zeros(n) if x is None else np.asarray(x, dtype=float)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} has a NaN or infinite value: {a.tolist()}")
    return a


def propagate(
    robot, q, dq=None, dL=None, frame=None, params=None, mode: str = "length"
) -> ErrorPropagation:
    """First-order pose error of ``frame`` at ``q``, Eq. (6-118): Δx = J_q Δq + J_L ΔL."""
    q = robot.check_q(q)
    ps = _params(robot, frame, params, mode)
    dq = tolerance_vector(dq, robot.nv, "dq")
    dL = tolerance_vector(dL, len(ps), "dL")
    Jq = robot.jacobian(q, frame)
    JL = length_jacobian(robot, q, frame, ps)
    return ErrorPropagation(Jq @ dq + JL @ dL, Jq, JL, ps)


# ----------------------------------------------------------------------------- batched FK with
# perturbed dimensions
class PerturbedChain:
    """Batched forward kinematics of the path to ``frame`` whose link parameters are perturbed
    per sample: T(q, L + ΔL) for N samples at once (numpy, read from ``robot.chain``: revolute,
    continuous, prismatic and mimic joints; the oracle is Pinocchio on perturbed model copies)."""

    def __init__(self, robot, frame=None, params=None, mode: str = "length"):
        self.robot = robot
        chain = robot.chain
        self.fid = robot.frame_id(frame)
        self.params = _params(robot, frame, params, mode)
        self.path = chain.path(self.fid)
        self.joints = [chain.joints[i] for i in self.path]
        f = chain.frames[self.fid]
        self.Rf, self.tf = f.rotation, f.translation

    def pose(self, q, dL=None, dq=None) -> tuple[np.ndarray, np.ndarray]:
        """World rotation (N, 3, 3) and position (N, 3) of the frame for configurations ``q``
        (N, nq), parameter perturbations ``dL`` (N, n_L) (m) and optional joint errors ``dq``
        (N, nv) (rad or m, added to the joint angles: on the circle for a continuous joint;
        a mimic joint follows its source)."""
        q = np.atleast_2d(self.robot.check_q(q))
        N = q.shape[0]
        dL = np.zeros((N, len(self.params))) if dL is None else np.atleast_2d(np.asarray(dL, float))
        if dL.shape != (N, len(self.params)):
            raise ValueError(f"dL must have shape ({N}, {len(self.params)}), got {dL.shape}")
        if not np.all(np.isfinite(dL)):
            raise ValueError(
                "dL has a NaN or infinite value: "
                f"{dL[~np.all(np.isfinite(dL), axis=1)][0].tolist()}"
            )
        chain = self.robot.chain
        theta = chain.angles(q)
        if dq is not None:
            dq = np.broadcast_to(np.asarray(dq, float), (N, self.robot.nv))
            for j in chain.joints:
                src = chain.joints[j.mimic.source] if j.is_mimic else j
                gain = j.mimic.multiplier if j.is_mimic else 1.0
                theta[:, j.index] += gain * dq[:, src.idx_v]
        dt = {}
        for k, p in enumerate(self.params):
            key = (p.kind, p.index)
            dt[key] = dt.get(key, 0.0) + dL[:, k : k + 1] * p.direction
        R = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
        x = np.zeros((N, 3))
        for j in self.joints:
            t = j.translation + dt.get(("joint", j.index + 1), 0.0)
            x = x + np.einsum("nij,nj->ni", R, np.broadcast_to(t, (N, 3)))
            R = R @ j.rotation
            th = theta[:, j.index]
            if j.kind == "prismatic":
                x = x + np.einsum("nij,j->ni", R, j.axis) * th[:, None]
            else:
                R = R @ rot_axis(j.axis, th)  # Rodrigues, Eq. (5-84)
        t = self.tf + dt.get(("frame", self.fid), 0.0)
        x = x + np.einsum("nij,nj->ni", R, np.broadcast_to(t, (N, 3)))
        return R @ self.Rf, x


def log3_batch(R: np.ndarray) -> np.ndarray:
    """Rotation vectors of a batch of rotations (angles < π)."""
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    th = np.arccos(c)
    w = 0.5 * np.stack(
        [R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], -1
    )
    s = np.sin(th)
    k = np.where(s > 1e-12, th / np.where(s > 1e-12, s, 1.0), 1.0)
    return w * k[:, None]


# ----------------------------------------------------------------------------- Monte Carlo
@dataclass
class MonteCarloResult:
    """Monte Carlo tolerance analysis of one configuration.

    ``dx`` (N, 6): sampled pose errors (Δp; Δφ), world axes (nonlinear, exact FK);
    ``cov`` their covariance; ``linear_cov`` = J Σ Jᵀ, the first-order prediction of (6-118);
    ``rms_position`` (m), ``p95_position`` and ``max_position`` of |Δp|."""

    dx: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    linear_cov: np.ndarray
    rms_position: float
    p95_position: float
    max_position: float
    params: list[LinkParameter] = field(default_factory=list)


def draw_errors(rng, dist: str, scale: np.ndarray, n: int) -> np.ndarray:
    """``n`` samples (n, len(scale)) of errors with per-column ``scale``: ``"normal"`` (scale =
    standard deviation) or ``"uniform"`` (on ±scale), drawn from ``rng``."""
    if dist == "normal":
        return rng.normal(size=(n, scale.size)) * scale
    if dist == "uniform":
        return rng.uniform(-1.0, 1.0, size=(n, scale.size)) * scale
    raise ValueError(f"distribution must be 'normal' or 'uniform', got {dist!r}")


def monte_carlo(
    robot,
    q,
    sigma_q=0.0,
    sigma_L=0.0,
    n: int = 10000,
    rng=None,
    frame=None,
    params=None,
    mode: str = "length",
    distribution: str = "normal",
    batch: int = 2000,
    progress: bool = True,
) -> MonteCarloResult:
    """Sample joint errors Δq and link errors ΔL, evaluate the exact perturbed FK in batches
    (:class:`PerturbedChain`, with a tqdm progress bar), and compare the spread with the
    first-order prediction J Σ Jᵀ of Eq. (6-118).

    ``sigma_q`` (rad / m per joint) and ``sigma_L`` (m per parameter) are standard deviations
    for ``distribution="normal"`` or half-widths of the tolerance band for ``"uniform"``."""
    q = robot.check_q(q)
    if q.ndim != 1:
        raise ValueError(f"monte_carlo takes one configuration, got shape {q.shape}")
    if not (isinstance(n, (int, np.integer)) and n > 0):
        raise ValueError(f"n must be a positive integer, got {n!r}")
    chain = PerturbedChain(robot, frame, params, mode)
    ps = chain.params
    sq = tolerance_vector(sigma_q, robot.nv, "sigma_q")
    sL = tolerance_vector(sigma_L, len(ps), "sigma_L")
    if np.any(sq < 0) or np.any(sL < 0):
        raise ValueError(
            f"tolerances must be non-negative, got sigma_q={sq.tolist()}, sigma_L={sL.tolist()}"
        )
    rng = np.random.default_rng(rng)
    R0, x0 = chain.pose(q[None])
    out = np.empty((n, 6))
    starts = range(0, n, batch)
    if progress:
        starts = tqdm(
            starts, total=(n + batch - 1) // batch, desc="monte carlo", unit="batch", leave=False
        )
    for a in starts:
        m = min(batch, n - a)
        dq = draw_errors(rng, distribution, sq, m)
        dL = draw_errors(rng, distribution, sL, m)
        R, x = chain.pose(np.broadcast_to(q, (m, q.size)), dL, dq)
        out[a : a + m, :3] = x - x0
        out[a : a + m, 3:] = log3_batch(R @ R0[0].T)
    var_factor = 1.0 if distribution == "normal" else 1.0 / 3.0
    J = np.hstack([robot.jacobian(q, frame), length_jacobian(robot, q, frame, ps)])
    Sigma = np.diag(np.concatenate([sq, sL]) ** 2 * var_factor)
    dp = np.linalg.norm(out[:, :3], axis=1)
    return MonteCarloResult(
        dx=out,
        mean=out.mean(0),
        cov=np.cov(out.T) if n > 1 else np.zeros((6, 6)),
        linear_cov=J @ Sigma @ J.T,
        rms_position=float(np.sqrt(np.mean(dp**2))),
        p95_position=float(np.percentile(dp, 95)),
        max_position=float(dp.max()),
        params=ps,
    )
