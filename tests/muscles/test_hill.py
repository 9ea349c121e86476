"""Thelen2003 muscle forces (issue 34): the curves against the definitions of Thelen (2003)
(mathematics), the static equilibrium against OpenSim 4.6's ``equilibrateMuscles`` →
``getFiberForce`` / ``getTendonForce``, and joint torques τ = Rᵀ f against OpenSim's moment
arms times OpenSim's tendon forces.

The equilibrium is compared at OpenSim's own musculotendon lengths (``getLength``), so these
tests check the force model alone.  OpenSim's Newton stops at |residual| < 1e-8 F_max (its
fibre force is that far from equilibrium), so the comparison is relative to the maximum
isometric force: |ΔF| < 1e-6 F_max (measured ~1e-8 F_max; relative to the force itself,
≤ 3e-6 where the force is small).  States
where OpenSim ends at the fibre's minimum length (its ``Warning_FiberAtLowerBound``: a random
pose shortens the path below the tendon's slack length plus a minimal fibre) are left out and
counted (~5 % of gait2392's random states): there our bisection finds the true equilibrium and
OpenSim's Newton has stopped at the bound.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import MuscleError

TOL = 1e-6


def test_curves_meet_their_definitions():
    # Thelen (2003): f_L peaks at 1 at optimal length and is exp(-1/gamma) at +-1 l0 away
    assert muscles.active_force_length(1.0, 0.45) == 1.0
    assert np.isclose(muscles.active_force_length(2.0, 0.45), np.exp(-1 / 0.45), rtol=1e-15)
    # the passive force is F_max at the strain FmaxMuscleStrain, zero below optimal length
    assert np.isclose(muscles.passive_force_length(1.6, 0.6, 4.0), 1.0, rtol=1e-14)
    assert muscles.passive_force_length(0.9, 0.6, 4.0) == 0.0
    # the tendon carries F_max at the strain FmaxTendonStrain, nothing when slack, and its
    # toe meets the linear part with the same value and slope (C1)
    for e0 in (0.033, 0.04, 0.1):
        assert np.isclose(muscles.tendon_force_strain(1.0 + e0, e0), 1.0, rtol=1e-13)
        assert muscles.tendon_force_strain(0.99, e0) == 0.0
        t = np.exp(3.0)
        e_toe = 99 * e0 * t / (166 * t - 67)
        h = 1e-7
        lo, hi = (
            muscles.tendon_force_strain(1 + e_toe - h, e0),
            muscles.tendon_force_strain(1 + e_toe + h, e0),
        )
        assert np.isclose(muscles.tendon_force_strain(1 + e_toe, e0), 0.33, rtol=1e-12)
        assert abs(hi - lo) < 2 * h * 0.67 / (e0 - e_toe) * 1.001
        slope_toe = (
            muscles.tendon_force_strain(1 + e_toe - h, e0)
            - muscles.tendon_force_strain(1 + e_toe - 2 * h, e0)
        ) / h
        assert np.isclose(slope_toe, 0.67 / (e0 - e_toe), rtol=1e-4)


def test_rigid_tendon_identity():
    path = aa.osim.path("arm26")
    ms = muscles.read_muscles(path)
    L = np.array([m.tendon_slack_length + 1.05 * m.optimal_fiber_length for m in ms.muscles])
    eq = muscles.equilibrium(ms, L, 0.5, rigid_tendon=True)
    h = np.array(
        [m.optimal_fiber_length * np.sin(m.pennation_angle_at_optimal) for m in ms.muscles]
    )
    ls = np.array([m.tendon_slack_length for m in ms.muscles])
    np.testing.assert_allclose(eq.fiber_length, np.sqrt(h**2 + (L - ls) ** 2), rtol=1e-15)
    np.testing.assert_allclose(eq.tendon_force, eq.fiber_force * np.cos(eq.pennation_angle))
    np.testing.assert_allclose(np.sin(eq.pennation_angle) * eq.fiber_length, h, rtol=1e-14)


@pytest.mark.parametrize("bad", [-0.1, 1.2, np.nan])
def test_activation_outside_unit_interval(bad):
    ms = muscles.read_muscles(aa.osim.path("arm26"))
    L = np.array([m.tendon_slack_length + m.optimal_fiber_length for m in ms.muscles])
    with pytest.raises(MuscleError):
        muscles.equilibrium(ms, L, np.full(len(ms), bad))


def test_millard_beside_thelen_is_evaluated(tmp_path):
    # Millard2012 forces exist since issue 34 item 2 (tests/muscles/test_millard.py)
    text = (
        aa.osim.path("arm26")
        .read_text()
        .replace('<Thelen2003Muscle name="BRA">', '<Millard2012EquilibriumMuscle name="BRA">')
    )
    i = text.index('<Millard2012EquilibriumMuscle name="BRA">')
    j = text.index("</Thelen2003Muscle>", i)
    text = text[:j] + "</Millard2012EquilibriumMuscle>" + text[j + len("</Thelen2003Muscle>") :]
    p = tmp_path / "millard.osim"
    p.write_text(text)
    ms = muscles.read_muscles(p)
    assert ms["BRA"].type == "Millard2012EquilibriumMuscle"
    eq = muscles.equilibrium(ms, np.full(len(ms), 0.3), 0.5)
    assert np.all(np.isfinite(eq.tendon_force)) and eq.tendon_force[ms.names.index("BRA")] > 0


def _against_opensim(name, n, seed):
    opensim = pytest.importorskip("opensim")
    path = aa.osim.path(name)
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    model = opensim.Model(str(path))
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(c) for c in robot.joint_names]
    mus = [model.getMuscles().get(i) for i in range(len(ms))]
    rng = np.random.default_rng(seed)
    Q = robot.random_q(n, rng=rng)
    A = rng.uniform(0.0, 1.0, (n, len(ms)))
    err, at_bound = 0.0, 0
    for q, a in zip(Q, A):
        for c, v in zip(coords, q):
            c.setValue(state, float(v), False)
        for m, ai in zip(mus, a):
            m.setActivation(state, float(ai))
        model.equilibrateMuscles(state)
        model.realizeDynamics(state)
        L = np.array([m.getLength(state) for m in mus])
        eq = muscles.equilibrium(ms, L, a)
        for i, m in enumerate(mus):
            mm = ms.muscles[i]
            lmin = (
                mm.optimal_fiber_length * np.sin(mm.pennation_angle_at_optimal) / 0.99498743710662
            )
            if m.getFiberLength(state) <= max(lmin, 1e-3 * mm.optimal_fiber_length):
                at_bound += 1
                continue
            scale = mm.max_isometric_force
            err = max(
                err,
                abs(m.getFiberForce(state) - eq.fiber_force[i]) / scale,
                abs(m.getTendonForce(state) - eq.tendon_force[i]) / scale,
            )
    return err, at_bound / (n * len(ms))


def test_gait2392_equilibrium_against_opensim():
    err, bound = _against_opensim("gait2392", 15, seed=7)
    assert err < TOL, err
    assert bound < 0.1


def test_arm26_equilibrium_against_opensim():
    err, bound = _against_opensim("arm26", 30, seed=8)
    assert err < TOL, err
    assert bound < 0.1


def test_joint_torques_against_opensim(tmp_path):
    """τ = Rᵀ f against Σ OpenSim computeMomentArm × OpenSim getTendonForce (arm26 with the
    cylinders only, where our paths are OpenSim's)."""
    text = re.sub(
        r"(<WrapEllipsoid name=\"\w+\">\s*<!--[^>]*-->\s*<active>)true",
        r"\1false",
        aa.osim.path("arm26").read_text(),
    )
    opensim = pytest.importorskip("opensim")
    p = tmp_path / "arm26_cylinders.osim"
    p.write_text(text)
    robot = aa.load(p)
    model = opensim.Model(str(p))
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(c) for c in robot.joint_names]
    mus = [model.getMuscles().get(i) for i in range(6)]
    rng = np.random.default_rng(9)
    Q = robot.random_q(20, rng=rng)
    A = rng.uniform(0.05, 1.0, (20, 6))
    tau, eq, R = muscles.joint_torques(robot, p, Q, A)
    for q, a, t in zip(Q, A, tau):
        for c, v in zip(coords, q):
            c.setValue(state, float(v), False)
        for m, ai in zip(mus, a):
            m.setActivation(state, float(ai))
        model.equilibrateMuscles(state)
        model.realizeDynamics(state)
        t_os = [
            sum(m.computeMomentArm(state, c) * m.getTendonForce(state) for m in mus) for c in coords
        ]
        assert np.allclose(t, t_os, rtol=1e-6, atol=1e-6 * 1000 * 0.05), (t, t_os)
