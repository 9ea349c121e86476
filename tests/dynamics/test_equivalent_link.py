"""§8-2 equivalent link (8-15)–(8-29) on a finger four-bar, against Pinocchio (recipe R4)."""

import numpy as np
import pinocchio as pin
import pytest

from anthroarm.dynamics import equivalent_link as EL
from anthroarm.errors import InertiaError


@pytest.mark.parametrize("phi", [0.2, 0.7, 1.3, 2.5, -2.0])
def test_J_star_M_star_vs_pinocchio_tree(phi):
    fb = EL.FourBarFinger()
    model = fb.pin_tree()
    data = model.createData()
    q, G, Gp = fb.tree_coordinates(phi)
    # the cut tree really closes at B
    pin.forwardKinematics(model, data, q)
    B_coupler = data.oMi[2].act(np.array([fb.r3, 0, 0]))
    B_rocker = data.oMi[3].act(np.array([fb.r4, 0, 0]))
    assert np.allclose(B_coupler, B_rocker, atol=1e-12)
    J = fb.J_star(phi)
    assert abs(J - 2 * pin.computeKineticEnergy(model, data, q, G)) < 1e-15  # (8-23)/(8-28)
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    assert abs(J - G @ M @ G) < 1e-15
    half_dJ = G @ (pin.rnea(model, data, q, G, Gp) - pin.computeGeneralizedGravity(model, data, q))
    assert abs(0.5 * fb.dJ_star(phi) - half_dJ) < 1e-15
    h = 1e-6
    assert abs(fb.dJ_star(phi) - (fb.J_star(phi + h) - fb.J_star(phi - h)) / (2 * h)) < 1e-9
    g = pin.computeGeneralizedGravity(model, data, q)
    assert abs(fb.M_star(phi) - (-G @ g)) < 1e-15  # (8-19)/(8-20)
    # a drive moment on the crank and a moment on the rocker: M* = M_d + M_r ω4/ω2
    assert (
        abs(fb.M_star(phi, drive=0.01, rocker_moment=-0.02) - (-G @ g + 0.01 - 0.02 * G[2])) < 1e-15
    )


def test_energy_form_and_moment_form_agree():
    fb = EL.FourBarFinger()
    drive = 0.002
    phi, om, t = fb.integrate_energy_form(0.0, 5.0, 2 * np.pi, drive=drive, samples=4001)  # (8-15)
    sol = fb.integrate_moment_form(0.0, 5.0, 0.999 * t[-1], drive=drive)  # (8-16)
    ph_m, om_m = sol.y
    # the same ω(φ) (linear interpolation on the energy-form grid limits the agreement)
    assert np.max(np.abs(np.interp(ph_m, phi, om) - om_m) / om_m) < 1e-4
    # and the same t(φ): one full turn of the crank in the same time
    assert abs(np.interp(sol.t[-1], t, phi) - ph_m[-1]) < 1e-3
    # and against the Pinocchio-reduced dynamics φ̈ = Gᵀ(τ − h(q, G φ̇, G′ φ̇²)) / (Gᵀ M G)
    model = fb.pin_tree()
    data = model.createData()
    x = np.array([0.0, 5.0])
    dt = 2e-4

    def f(x):
        q, G, Gp = fb.tree_coordinates(x[0])
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        bias = pin.rnea(model, data, q, G * x[1], Gp * x[1] ** 2)
        return np.array([x[1], (drive - G @ bias) / (G @ M @ G)])

    T = 0.1  # inside the moment-form solution's interval
    for _ in range(int(T / dt)):
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)  # noqa: E702
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    assert np.allclose(sol.sol(T), x, rtol=1e-7, atol=1e-8)


def test_generic_formulas_8_20_8_28():
    # one body rotating about a fixed axis through its CoM: J* = J (8-28), M* = M_z (8-20)
    assert EL.equivalent_inertia([(2.0, [0, 0, 0], [0, 0, 1.0], np.diag([1, 2, 3.0]))]) == 3.0
    # a point mass on a 0.5 m arm: J* = m r²
    assert (
        abs(EL.equivalent_inertia([(2.0, [0, 0.5, 0], [0, 0, 1.0], np.zeros((3, 3)))]) - 0.5)
        < 1e-15
    )
    assert EL.equivalent_moment([([0, -10.0, 0], [0, 0.5, 0], [0, 0, 2.0], [0, 0, 1.0])]) == -3.0


def test_stops_and_bad_input():
    fb = EL.FourBarFinger()
    with pytest.raises(ValueError, match="stops"):
        fb.integrate_energy_form(0.0, 0.1, 6.0, drive=-0.01)
    with pytest.raises(ValueError, match="finite"):
        fb.J_star(np.nan)
    with pytest.raises(InertiaError):
        EL.FourBarFinger(mass=(0, 0, 0))
    with pytest.raises(ValueError, match="assemble"):
        EL.FourBarFinger(r1=0.1, r2=0.01, r3=0.02, r4=0.02).J_star(0.3)
    with pytest.raises(ValueError, match="r3 must be a positive length"):
        EL.FourBarFinger(r3=-0.01)
    with pytest.raises(ValueError, match="drive"):
        fb.M_star(0.3, drive=np.nan)
    with pytest.raises(ValueError, match="omega0"):
        fb.integrate_energy_form(0.0, np.nan, 1.0)
    with pytest.raises(ValueError, match="t_end"):
        fb.integrate_moment_form(0.0, 1.0, np.inf)
    with pytest.raises(ValueError, match="NaN"):
        EL.equivalent_inertia([(np.nan, [0, 0, 0], [0, 0, 1.0], np.eye(3))])
