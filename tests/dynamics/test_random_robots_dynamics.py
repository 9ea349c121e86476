"""Mimic and coupled dynamics proven generally (issue 30): random robots — trees of 2 to 12
revolute, prismatic, continuous and mimic joints on random axes, placements, multipliers and
offsets, random physical inertias (:mod:`random_robots`) — loaded from URDF as a user loads
them, with every quantity of the generated Lagrange code and the chain's batched FK and
Jacobians compared with Pinocchio.

Two oracles for every quantity, neither of them anthroarm:

1. Pinocchio's own mimic model (the robot's ``pin.Model``, built with ``mimic=True``):
   ``crba`` (with a mimic joint: M from ``rnea`` columns, rnea(q, 0, e_i) − g, because
   Pinocchio 4.1's ``crba`` is wrong on a mimic joint whose link carries two joints — FORK4 in
   test_mimic_dynamics.py, found by this test — and depends on the reused pin.Data's past on
   others), ``computeGeneralizedGravity``, ``nonLinearEffects``, ``rnea``,
   ``computeFrameJacobian``; ``aba`` where there is no mimic joint (it refuses them), else
   ``crba⁻¹(τ − nonLinearEffects)``.
2. The same URDF built without mimic relations (``mimic=False``, one coordinate per joint),
   projected by hand: q_full from the generator's own record of each relation
   (θ_m = a θ_s + b), q̇_full = G q̇ with the constant coupling G (so Ġ = 0):
   M = Gᵀ M_f G, g = Gᵀ g_f, C q̇ = Gᵀ (nle_f − g_f), C = Gᵀ C_f G (Christoffel symbols transform
   by a constant G), τ = Gᵀ rnea_f(q_f, G q̇, G q̈), forward dynamics = M⁻¹(τ − Gᵀ nle_f),
   T and V from ``computeKineticEnergy``/``computePotentialEnergy``, J = J_f G.

Errors are relative: max |ours − oracle| / max(1, max |oracle|).  Runtime: the symbolic
derivation is fast (< 0.5 s for 12 joints) but printing and compiling the generated Python of
a 12-joint tree (~80 000 lines) takes 2–4 s, so the default test draws 2 robots per joint count
2..12 (22 robots × 6 configurations); the ``slow`` variant draws 8 per joint count.
"""

import numpy as np
import pinocchio as pin
import pytest
from random_robots import random_robot

import anthroarm as aa
from anthroarm.dynamics import lagrange as L

QUANTITIES = ("M", "g", "Cqd", "C", "tau", "fd", "T", "V", "fk", "J")
#: relative tolerances; forward dynamics carries the conditioning of M (random tiny inertias)
TOL = dict.fromkeys(QUANTITIES, 1e-10) | {"fd": 1e-8}


@pytest.fixture(scope="module", autouse=True)
def _cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("ANTHROARM_CACHE", str(tmp_path_factory.mktemp("aacache")))
    yield
    mp.undo()


def rel(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def sym(M):
    return np.triu(M) + np.triu(M, 1).T


def oracle_maps(rr, model, full):
    """(theta(q), q_full(q), G) from the generator's record and Pinocchio's joint layout only."""
    rec = {j.name: j for j in rr.joints}
    names = [j.name for j in rr.joints]

    def theta(q):
        th = {}
        for nm in names:
            jm = model.joints[model.getJointId(nm)]
            if rec[nm].mimic is None:
                i = jm.idx_q
                th[nm] = np.arctan2(q[i + 1], q[i]) if jm.nq == 2 else q[i]
        for nm in names:
            if rec[nm].mimic is not None:
                src, a, b = rec[nm].mimic
                th[nm] = a * th[src] + b
        return th

    def q_full(q):
        th = theta(q)
        out = np.zeros(full.nq)
        for nm in names:
            jf = full.joints[full.getJointId(nm)]
            t = th[nm]
            out[jf.idx_q : jf.idx_q + jf.nq] = [np.cos(t), np.sin(t)] if jf.nq == 2 else t
        return out

    G = np.zeros((full.nv, model.nv))
    for nm in names:
        src, a = (nm, 1.0) if rec[nm].mimic is None else rec[nm].mimic[:2]
        G[full.joints[full.getJointId(nm)].idx_v, model.joints[model.getJointId(src)].idx_v] = a
    return q_full, G


def check_robot(rr, path, nconf: int, rng) -> dict:
    """Largest relative error per quantity against both oracles (see the module docstring)."""
    path.write_text(rr.urdf)
    robot = aa.load(path, tool=rr.tool)
    m, d = robot.model, robot.model.createData()
    full = pin.buildModelFromXML(rr.urdf, mimic=False)
    fdata = full.createData()
    assert full.nv == len(rr.joints) and m.nv == len(rr.joints) - rr.n_mimic
    q_full, G = oracle_maps(rr, m, full)
    dyn = L.load(robot)
    n = robot.nv
    Q = robot.random_q(nconf, rng)
    V, A = rng.standard_normal((nconf, n)), rng.standard_normal((nconf, n))
    ours = dict(
        M=dyn.mass_matrix(Q),
        g=dyn.gravity(Q),
        Cqd=dyn.coriolis(Q, V),
        C=dyn.coriolis_matrix(Q, V),
        tau=dyn.tau(Q, V, A),
        fd=dyn.forward(Q, V, A),
        T=dyn.kinetic_energy(Q, V),
        V=dyn.potential_energy(Q),
    )
    bodies = [f"link{k}" for k in range(len(rr.joints))]
    kin = {b: (robot.fk(Q, b), robot.jacobian(Q, b)) for b in bodies}  # batched chain path
    err = dict.fromkeys(QUANTITIES, 0.0)
    mimic = rr.n_mimic > 0
    for i, (q, v, a) in enumerate(zip(Q, V, A)):
        qf, vf, af = q_full(q), G @ v, G @ a
        Mf = G.T @ sym(pin.crba(full, fdata, qf)) @ G
        gf = G.T @ pin.computeGeneralizedGravity(full, fdata, qf)
        nlef = G.T @ pin.nonLinearEffects(full, fdata, qf, vf)
        proj = dict(
            M=Mf,
            g=gf,
            Cqd=nlef - gf,
            C=G.T @ pin.computeCoriolisMatrix(full, fdata, qf, vf) @ G,
            tau=G.T @ pin.rnea(full, fdata, qf, vf, af),
            fd=np.linalg.solve(Mf, a - nlef),
            T=pin.computeKineticEnergy(full, fdata, qf, vf),
            V=pin.computePotentialEnergy(full, fdata, qf),
        )
        gp = pin.computeGeneralizedGravity(m, d, q).copy()
        if mimic:  # crba is wrong on some mimic trees (see the module docstring)
            Mp = np.column_stack([pin.rnea(m, d, q, 0 * v, e) - gp for e in np.eye(n)])
        else:
            Mp = sym(pin.crba(m, d, q))
        nle = pin.nonLinearEffects(m, d, q, v).copy()
        own = dict(
            M=Mp,
            g=gp,
            Cqd=nle - gp,
            tau=pin.rnea(m, d, q, v, a).copy(),
            fd=np.linalg.solve(Mp, a - nle) if mimic else pin.aba(m, d, q, v, a).copy(),
        )
        if not mimic:
            own["C"] = pin.computeCoriolisMatrix(m, d, q, v).copy()
        for k, ref in proj.items():
            err[k] = max(err[k], rel(ours[k][i], ref))
        for k, ref in own.items():
            err[k] = max(err[k], rel(ours[k][i], ref))
        pin.framesForwardKinematics(full, fdata, qf)
        pin.framesForwardKinematics(m, d, q)
        pin.computeJointJacobians(full, fdata, qf)
        pin.computeJointJacobians(m, d, q)
        lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        for b in bodies:
            T_ours, J_ours = kin[b][0][i], kin[b][1][i]
            ff, fm = full.getFrameId(b), m.getFrameId(b)
            err["fk"] = max(
                err["fk"],
                rel(T_ours, fdata.oMf[ff].homogeneous),
                rel(T_ours, d.oMf[fm].homogeneous),
            )
            err["J"] = max(
                err["J"],
                # (Pinocchio returns a 6 x 1 Jacobian as a (6,) array)
                rel(J_ours, pin.getFrameJacobian(full, fdata, ff, lwa).reshape(6, -1) @ G),
                rel(J_ours, pin.getFrameJacobian(m, d, fm, lwa).reshape(6, n)),
            )
    return err


def run(seeds_per_size: int, nconf: int, tmp_path, base_seed: int) -> dict:
    worst = dict.fromkeys(QUANTITIES, 0.0)
    count = dict(robots=0, mimic_robots=0, mimic_joints=0, configurations=0)
    for n in range(2, 13):
        for s in range(seeds_per_size):
            rng = np.random.default_rng([base_seed, n, s])
            rr = random_robot(rng, n, name=f"rand{n}_{s}")
            err = check_robot(rr, tmp_path / f"{rr.name}.urdf", nconf, rng)
            bad = {k: e for k, e in err.items() if not e <= TOL[k]}
            assert not bad, (rr.name, bad, rr.urdf)
            for k, e in err.items():
                worst[k] = max(worst[k], e)
            count["robots"] += 1
            count["mimic_robots"] += rr.n_mimic > 0
            count["mimic_joints"] += rr.n_mimic
            count["configurations"] += nconf
    print(f"\nrandom robots: {count}; largest relative errors: ", end="")
    print(", ".join(f"{k} {e:.1e}" for k, e in worst.items()))
    return count


def test_random_robots_dynamics_and_jacobians_match_pinocchio(tmp_path):
    count = run(seeds_per_size=2, nconf=6, tmp_path=tmp_path, base_seed=30)
    assert count["robots"] == 22 and count["mimic_robots"] >= 8


@pytest.mark.slow
def test_random_robots_dynamics_many(tmp_path):
    count = run(seeds_per_size=8, nconf=10, tmp_path=tmp_path, base_seed=3030)
    assert count["robots"] == 88 and count["mimic_robots"] >= 30
