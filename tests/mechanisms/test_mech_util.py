"""The mechanisms' private rotation helpers agree with anthroarm.spatial (part A) and Pinocchio."""

import numpy as np
import pinocchio as pin
import pytest

from anthroarm.mechanisms._util import W, Wdot, fd_derivative, fd_rates, rot, skew, unit_axis, wrap
from anthroarm.spatial import screw


def test_helpers_equal_spatial_screw_and_pin():
    rng = np.random.default_rng(3)
    for _ in range(20):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        th, wd, wdd = rng.normal(size=3)
        np.testing.assert_allclose(rot(th, u), pin.exp3(th * u), atol=1e-15)
        np.testing.assert_allclose(skew(u), screw.P(u), atol=0)
        np.testing.assert_allclose(W(wd, u), screw.velocity_matrix(wd, u), atol=1e-15)
        np.testing.assert_allclose(
            Wdot(wd, wdd, u), screw.acceleration_matrix(wd, wdd, u), atol=1e-15
        )
        # Wdot is the second derivative of R(theta(t)) R(theta0)^T
        R0 = rot(th, u)
        d1, d2 = fd_rates(lambda t: rot(th + wd * t + 0.5 * wdd * t * t, u) @ R0.T)
        np.testing.assert_allclose(d1, W(wd, u), atol=1e-9)
        np.testing.assert_allclose(d2, Wdot(wd, wdd, u), atol=1e-8)
    ths = np.linspace(-3, 3, 7)
    assert rot(ths, [0, 0, 1]).shape == (7, 3, 3) and W(ths, [0, 0, 1]).shape == (7, 3, 3)


def test_unit_axis_and_wrap():
    with pytest.raises(ValueError, match="zero length"):
        unit_axis("u", [0, 0, 0])
    with pytest.raises(ValueError, match="unit"):
        unit_axis("u", [0, 0, 1.01])
    with pytest.raises(ValueError, match="shape"):
        unit_axis("u", [0, 1])
    assert (
        wrap(np.pi) == np.pi
        and wrap(-np.pi) == np.pi
        and abs(wrap(7.0) - (7.0 - 2 * np.pi)) < 1e-15
    )
    assert abs(fd_derivative(np.sin) - 1.0) < 1e-12
