"""Complex polar vectors (5-1)-(5-11) and the spatial complex form (5-23)/(5-24)."""

import numpy as np
import pytest
from _spatial_strategies import angle, rate, vec3
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.spatial import polar as P

H = settings(max_examples=40, deadline=None)
pos = st.floats(0.1, 3.0)


@H
@given(pos, angle, angle)
def test_rules_5_5_to_5_9(r, th, phi):
    z = P.polar(r, th)
    assert np.isclose(P.rotate(z, phi), P.polar(r, th + phi))  # (5-5)
    assert np.isclose(1j * P.unit(th), P.unit(th + np.pi / 2))  # (5-6)
    assert np.isclose(1j * (1j * P.unit(th)), P.unit(th + np.pi))  # (5-7)
    assert np.isclose(P.unit(th) * P.unit(-th), 1.0)  # (5-8)
    assert np.isclose((P.unit(th) + P.unit(-th)) / 2, np.cos(th))  # (5-9)
    assert np.isclose((P.unit(th) - P.unit(-th)) / 2j, np.sin(th))
    assert np.allclose(P.to_xy(z), [r * np.cos(th), r * np.sin(th)])
    assert np.isclose(P.from_xy(P.to_xy(z)), z)


@H
@given(pos, rate, rate, angle, rate, rate)
def test_derivatives_5_10_5_11_vs_fd_and_terms(r, rd, rdd, th, thd, thdd):
    z = lambda t: P.polar(r + rd * t + 0.5 * rdd * t * t, th + thd * t + 0.5 * thdd * t * t)
    h = 1e-4
    m = P.polar_motion(r, rd, rdd, th, thd, thdd)
    assert np.isclose(m.velocity, (z(h) - z(-h)) / (2 * h), atol=1e-6)
    assert np.isclose(m.acceleration, (z(h) - 2 * z(0) + z(-h)) / h**2, atol=1e-4)
    e = np.exp(1j * th)
    assert np.isclose(m.coriolis, 2 * rd * thd * 1j * e)
    assert np.isclose(m.centripetal, -r * thd**2 * e)
    assert np.isclose(m.tangential_acc, r * thdd * 1j * e)
    assert np.isclose(m.radial_acc, rdd * e)
    # the OCR's intermediate term ṙ(e^{iθ} i θ̈) in place of ṙ(e^{iθ} i θ̇) breaks (5-11)
    printed = (rdd - r * thd**2) * e + (r * thdd + rd * thd) * 1j * e + rd * thdd * 1j * e
    if abs(rd * (thd - thdd)) > 1e-2:
        assert not np.isclose(printed, m.acceleration, atol=1e-6)


def test_polar_motion_batch():
    t = np.linspace(0, 1, 6)
    m = P.polar_motion(1 + t, 0.5 * np.ones(6), 0 * t, t, np.ones(6), 0 * t)
    assert m.acceleration.shape == (6,)
    assert np.isclose(m.acceleration[4], P.polar_motion(1 + t[4], 0.5, 0, t[4], 1, 0).acceleration)


@H
@given(vec3)
def test_spherical_round_trip_5_23_5_24(p):
    rp, th, ph = P.xyz_to_spherical(p)
    assert np.allclose(P.spherical_to_xyz(rp, th, ph), p, atol=1e-12)
    assert 0 <= ph <= np.pi


def test_polar_bad_input():
    with pytest.raises(ValueError, match="finite"):
        P.polar(np.nan, 0.0)
    with pytest.raises(ValueError, match="z must be finite"):
        P.rotate(complex(np.nan, 0.0), 0.1)
    with pytest.raises(ValueError, match="shape"):
        P.from_xy([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="shape"):
        P.xyz_to_spherical([1.0, 2.0])
