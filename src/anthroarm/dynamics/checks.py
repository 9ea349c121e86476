"""Cross-check rows of the dynamics package for ``anthroarm check``.

For every catalog model: the generated Lagrange code (:mod:`.lagrange`, loaded from the disk
cache) against Pinocchio on the same URDF — M vs ``crba``, C q̇ vs ``computeCoriolisMatrix`` q̇,
the Christoffel matrix vs ``computeCoriolisMatrix``, g vs ``computeGeneralizedGravity``,
τ = M q̈ + C q̇ + g vs ``rnea``, forward dynamics vs ``aba``, T and V vs
``computeKineticEnergy`` / ``computePotentialEnergy``.  Errors are relative:
max |ours − pin| / max(1, max |pin|) over the samples; tolerance 1e-10.

Any robot: q in the robot's layout (continuous joints' (cos, sin) pairs).  With mimic joints
Pinocchio 4's ``crba``, ``rnea``, ``computeGeneralizedGravity`` and ``nonLinearEffects`` are the
reduced quantities (tests/dynamics/test_lagrange_any_robot.py checks them against Gᵀ(·)G of the
model without mimic joints), but its ``computeCoriolisMatrix`` is not consistent with them and
``aba`` and the energy functions refuse mimic joints: there C q̇ and the Christoffel matrix
times q̇ are checked against ``nonLinearEffects − g``, forward dynamics against
``M⁻¹ (τ − nonLinearEffects)``, T against ½ q̇ᵀ M q̇ and V against −m gᵀ ``centerOfMass``, where
M is built from ``rnea`` (column i = rnea(q, 0, e_i) − g), not ``crba``: Pinocchio 4.1's
``crba`` is wrong on a mimic joint whose link carries two joints (both conventions) and, in its
default LOCAL convention, depends on the reused pin.Data's past on other mimic trees
(tests/dynamics/test_mimic_dynamics.py: FORK4, TREE5); its ``rnea`` agrees with the projection
of the model without mimic relations on all of them.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..check_rows import CheckRow
from ..robot import load as load_robot
from .lagrange import load

TOL = 1e-10


def _rel(ours, ref) -> float:
    ours, ref = np.asarray(ours, float), np.asarray(ref, float)
    return float(np.max(np.abs(ours - ref)) / max(1.0, float(np.max(np.abs(ref)))))


def model_rows(robot, samples: int, rng) -> list:
    """Rows for one Robot (see the module docstring)."""
    dyn = load(robot)
    m, d = robot.model, robot.data
    n = robot.nv
    Q = robot.random_q(samples, rng)
    Qd = rng.standard_normal((samples, n))
    Qdd = rng.standard_normal((samples, n))
    tau_in = rng.standard_normal((samples, n)) * 5.0
    M, Cqd, Cm = dyn.mass_matrix(Q), dyn.coriolis(Q, Qd), dyn.coriolis_matrix(Q, Qd)
    g, tau = dyn.gravity(Q), dyn.tau(Q, Qd, Qdd)
    T, V = dyn.kinetic_energy(Q, Qd), dyn.potential_energy(Q)
    fd = dyn.forward(Q, Qd, tau_in)
    ref = {k: [] for k in ("M", "Cqd", "C", "g", "tau", "fd", "T", "V")}
    mimic = robot.chain.has_mimic
    if mimic:
        Cm = np.einsum("nij,nj->ni", Cm, Qd)
    zero = np.zeros(n)
    for q, qd, qdd, ti in zip(Q, Qd, Qdd, tau_in):
        gp = pin.computeGeneralizedGravity(m, d, q).copy()
        if mimic:  # M e_i = rnea(q, 0, e_i) - g: Pinocchio 4.1's crba is wrong on some mimic trees
            Mp = np.column_stack([pin.rnea(m, d, q, zero, e) - gp for e in np.eye(n)])
            Mp = 0.5 * (Mp + Mp.T)
        else:
            Mp = pin.crba(m, d, q)
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
        ref["M"].append(Mp)
        ref["g"].append(gp)
        if mimic:
            nle = pin.nonLinearEffects(m, d, q, qd).copy()
            ref["Cqd"].append(nle - gp)
            ref["C"].append(nle - gp)
            ref["fd"].append(np.linalg.solve(Mp, ti - nle))
        else:
            Cp = pin.computeCoriolisMatrix(m, d, q, qd)
            ref["C"].append(Cp.copy())
            ref["Cqd"].append(Cp @ qd)
            ref["fd"].append(pin.aba(m, d, q, qd, ti).copy())
        ref["tau"].append(pin.rnea(m, d, q, qd, qdd).copy())
        if mimic:  # computeKineticEnergy / computePotentialEnergy refuse mimic joints
            ref["T"].append(0.5 * qd @ Mp @ qd)
            ref["V"].append(
                -pin.computeTotalMass(m) * float(m.gravity.linear @ pin.centerOfMass(m, d, q))
            )
        else:
            ref["T"].append(pin.computeKineticEnergy(m, d, q, qd))
            ref["V"].append(pin.computePotentialEnergy(m, d, q))
    ours = {"M": M, "Cqd": Cqd, "C": Cm, "g": g, "tau": tau, "fd": fd, "T": T, "V": V}
    label = {
        "M": ("dyn M(q) Lagrange", "pin.crba"),
        "Cqd": ("dyn C(q,qd)qd Christoffel", "pin.computeCoriolisMatrix@qd"),
        "C": ("dyn C(q,qd) Christoffel matrix", "pin.computeCoriolisMatrix"),
        "g": ("dyn g(q) = dV/dq", "pin.computeGeneralizedGravity"),
        "tau": ("dyn tau = M qdd + C qd + g", "pin.rnea"),
        "fd": ("dyn forward dynamics", "pin.aba"),
        "T": ("dyn kinetic energy T", "pin.computeKineticEnergy"),
        "V": ("dyn potential energy V", "pin.computePotentialEnergy"),
    }
    if mimic:
        label["C"] = ("dyn C(q,qd) Christoffel matrix @ qd", "pin.nonLinearEffects - g (mimic)")
        label["Cqd"] = (label["Cqd"][0], "pin.nonLinearEffects - g (mimic)")
        label["M"] = (label["M"][0], "pin.rnea columns (mimic)")
        label["fd"] = (label["fd"][0], "solve(M from pin.rnea, tau - nonLinearEffects) (mimic)")
        label["T"] = (label["T"][0], "qd' (M from pin.rnea) qd / 2 (mimic)")
        label["V"] = (label["V"][0], "-mass g'pin.centerOfMass (mimic)")
    rows = []
    for k, (q_name, oracle) in label.items():
        rows.append(
            CheckRow(
                robot.name,
                q_name,
                _rel(ours[k], ref[k]),
                TOL,
                samples,
                oracle,
                note=f"relative; generated code from {dyn.source}",
            )
        )
    return rows


def rows(models: list[str], samples: int, rng) -> list:
    """Provider for :mod:`anthroarm.crosscheck` (every catalog arm)."""
    out = []
    for name in models:
        out.extend(model_rows(load_robot(name), min(samples, 200), rng))
    return out
