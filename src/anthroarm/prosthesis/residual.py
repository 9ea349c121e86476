"""A person's residual muscles in the sizing loop (issue 34 item 5): per joint, the torque the
muscles that remain can cover and the torque the motor must add.

The muscles come from an OpenSim model (``.osim``): which of them remain (``remaining``) and a
``strength`` factor on their maximum isometric force (a weak or atrophied residual muscle:
< 1).  ``joints`` maps each joint of the prosthesis arm to a coordinate of the OpenSim model,
with a sign when the two count the angle in opposite directions (``{"elbow_flexion":
("r_elbow_flex", +1)}``).  At each sample the mapped coordinates take the arm's angles (times
the sign), the others their default values.

The muscles' torque about the mapped coordinates is τ_m(a) = B a + p with
B = Rᵀ diag(k F_A), p = Rᵀ (k F_P) (moment arms R = −∂l/∂q of :func:`anthroarm.muscles.moment_arms`,
F_A, F_P the active force per unit activation and the passive force of a Thelen2003 muscle
with its tendon at slack length, at rest: :func:`anthroarm.muscles.force_coefficients`, as in
static optimisation; k the strength).  The muscles cover the torque closest to the demand τ
that activations 0 ≤ a ≤ 1 reach,

    min_a ‖τ − B a − p‖² + ε ‖a‖²,   0 ≤ a ≤ 1

(ε = 1e-9 × the largest diagonal of BᵀB: among activations that cover the same torque, the
least), solved per sample by the QP layer (:func:`anthroarm.ik.qp.make_backend`).  The motor
adds τ − τ_m.  For one mapped joint the minimiser is the demand clipped to the muscles' range
[τ_min, τ_max] (the sum of the passive torque and each muscle's full active torque of the
demand's sign): where the demand is inside the range the motor adds nothing.  A muscle that
also crosses an unmapped coordinate (the biceps at the shoulder of an elbow prosthesis) is
counted at the mapped joints only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MuscleError
from ..ik.qp import make_backend
from ..loading import load
from ..muscles import force_coefficients, lengths_and_moment_arms, read_muscles
from ..muscles.reader import MuscleSet

#: relative weight of the least-activation tie-break
EPS = 1e-9


def parse_joints(spec: str) -> dict:
    """``"elbow_flexion=r_elbow_flex,wrist_flexion=-flexion"`` → ``{arm joint: (coordinate,
    sign)}`` (a leading ``-`` on the coordinate: the two count the angle in opposite
    directions)."""
    out = {}
    for item in [s.strip() for s in str(spec).split(",") if s.strip()]:
        joint, eq, coord = item.partition("=")
        joint, coord = joint.strip(), coord.strip()
        if not eq or not joint or not coord.lstrip("-+"):
            raise MuscleError(
                f"joint map item {item!r}: write ARM_JOINT=OSIM_COORDINATE (or =-COORDINATE)"
            )
        sign = -1.0 if coord.startswith("-") else 1.0
        out[joint] = (coord.lstrip("-+"), sign)
    if not out:
        raise MuscleError("the joint map is empty: give ARM_JOINT=OSIM_COORDINATE[,...]")
    return out


@dataclass(frozen=True)
class ResidualMuscles:
    """The residual muscles (module docstring): the OpenSim ``robot`` and the ``muscles`` that
    remain, their ``strength`` factor, and ``joints`` {arm joint: (coordinate, sign)}."""

    robot: object
    muscles: MuscleSet
    strength: float
    joints: dict

    @classmethod
    def from_osim(cls, path, joints, remaining=None, strength: float = 1.0):
        """Read ``path`` (.osim); ``remaining``: muscle names (None: all); ``joints``: a dict
        or a :func:`parse_joints` string."""
        robot = load(path)
        ms = read_muscles(path)
        jm = parse_joints(joints) if isinstance(joints, str) else dict(joints)
        for j, (c, _) in jm.items():
            if c not in robot.joint_names:
                raise MuscleError(
                    f"{path}: coordinate {c!r} (for joint {j!r}) is not an independent "
                    f"coordinate of the model; coordinates: {', '.join(robot.joint_names)}"
                )
        if remaining is not None:
            names = [n.strip() for n in remaining if n.strip()]
            bad = [n for n in names if n not in ms.names]
            if bad or not names:
                raise MuscleError(
                    f"{path}: muscle(s) {bad or names} not in the model; muscles: "
                    f"{', '.join(ms.names)}"
                )
            ms = ms.select(names)
        s = float(strength)
        if not (np.isfinite(s) and 0.0 < s <= 10.0):
            raise MuscleError(f"strength must be a factor in (0, 10], got {strength!r}")
        return cls(robot, ms, s, jm)

    def check_arm(self, joint_names) -> list:
        """The arm's joint indices of the mapped joints (a typed error names a missing one)."""
        names = list(joint_names)
        missing = [j for j in self.joints if j not in names]
        if missing:
            raise MuscleError(
                f"joint(s) {missing} of the muscle map are not joints of the arm: "
                f"{', '.join(names)}"
            )
        return [names.index(j) for j in self.joints]

    def coordinates(self, joint_names, q) -> np.ndarray:
        """The OpenSim model's coordinates (N, nq_osim) at the arm's positions ``q`` (N, nv)."""
        idx = self.check_arm(joint_names)
        Q = np.atleast_2d(np.asarray(q, dtype=float))
        C = np.tile(self.robot.default_q(), (Q.shape[0], 1))
        for (c, sign), j in zip(self.joints.values(), idx):
            C[:, self.robot.joint_names.index(c)] = sign * Q[:, j]
        return C

    def cover(self, joint_names, q, tau, *, solver: str = "quadprog"):
        """(muscle torque, motor torque), each (N, nv) N m in the arm's joints: the part of the
        demand ``tau`` (N, nv) at positions ``q`` (N, nv) the muscles cover, and the rest
        (module docstring; zero muscle torque at unmapped joints)."""
        idx = self.check_arm(joint_names)
        T = np.atleast_2d(np.asarray(tau, dtype=float))
        if not np.all(np.isfinite(T)):
            raise MuscleError("demand torques must be finite")
        C = self.coordinates(joint_names, q)
        L, R = lengths_and_moment_arms(self.robot, self.muscles, C)
        FA, FP = force_coefficients(self.muscles, L)
        cols = [self.robot.joint_names.index(c) for c, _ in self.joints.values()]
        sign = np.array([s for _, s in self.joints.values()])
        M = len(self.muscles)
        backend = make_backend(solver, M, 0)
        lo, hi = np.zeros(M), np.ones(M)
        mus = np.zeros_like(T)
        for k in range(T.shape[0]):
            Rk = R[k][:, cols] * sign  # moment arms about the arm's joints
            B = Rk.T * (self.strength * FA[k])
            p = Rk.T @ (self.strength * FP[k])
            BtB = B.T @ B
            H = 2.0 * (BtB + EPS * max(float(np.diag(BtB).max()), 1e-12) * np.eye(M))
            c = -2.0 * B.T @ (T[k, idx] - p)
            a, status = backend.solve(H, c, lo, hi)
            if a is None:
                raise MuscleError(f"sample {k}: the muscles' QP failed ({status})")
            mus[k, idx] = B @ np.clip(a, 0.0, 1.0) + p
        return mus, T - mus

    def range(self, joint_names, q):
        """(τ_min, τ_max) (N, nv): the torque range of the muscles about each mapped joint alone
        (the others' demands ignored): passive torque plus every muscle's full active torque
        of one sign."""
        idx = self.check_arm(joint_names)
        C = self.coordinates(joint_names, q)
        L, R = lengths_and_moment_arms(self.robot, self.muscles, C)
        FA, FP = force_coefficients(self.muscles, L)
        lo = np.zeros((C.shape[0], len(list(joint_names))))
        hi = lo.copy()
        for (c, sign), j in zip(self.joints.values(), idx):
            r = sign * R[:, :, self.robot.joint_names.index(c)]
            act = r * self.strength * FA
            pas = (r * self.strength * FP).sum(axis=1)
            lo[:, j] = pas + np.minimum(act, 0).sum(axis=1)
            hi[:, j] = pas + np.maximum(act, 0).sum(axis=1)
        return lo, hi


def table(activities, joint_names) -> list[dict]:
    """Per joint over the activities that carry muscle torques (``muscle_tau``): the peak
    demand |τ|, the peak muscle torque, the peak motor torque (N m) and the share of the demand's
    ∫|τ| dt the muscles cover."""
    out = []
    acts = [a for a in activities if a.status == "ok" and a.muscle_tau is not None]
    for j, name in enumerate(joint_names):
        need = [a.tau[:, j] + a.muscle_tau[:, j] for a in acts]
        mus = [a.muscle_tau[:, j] for a in acts]
        mot = [a.tau[:, j] for a in acts]
        tot = sum(float(np.trapezoid(np.abs(n), a.t)) for n, a in zip(need, acts))
        cov = sum(
            float(np.trapezoid(np.abs(n) - np.abs(m), a.t)) for n, m, a in zip(need, mot, acts)
        )
        out.append(
            dict(
                joint=name,
                peak_demand=max((float(np.abs(n).max()) for n in need), default=0.0),
                peak_muscle=max((float(np.abs(m).max()) for m in mus), default=0.0),
                peak_motor=max((float(np.abs(m).max()) for m in mot), default=0.0),
                covered=cov / tot if tot > 0 else 0.0,
            )
        )
    return out
