"""§8-4 prosthetic-hand model, Eqs. (8-97)–(8-112), against Pinocchio (recipe R1 of the notes)."""

import numpy as np
import pinocchio as pin
import pytest

from anthroarm.dynamics import hand_model as H
from anthroarm.errors import InertiaError


def random_hand(rng, axes, isotropic=True):
    n = len(axes)
    m = rng.uniform(0.01, 0.05, n)
    J = rng.uniform(1e-6, 1e-5, n)
    return H.HandModel(
        axes=axes,
        l=rng.uniform(-0.05, 0.05, (n + 1, 3)),
        r=rng.uniform(-0.03, 0.03, (n, 3)),
        m=m,
        J=J,
        xi=rng.uniform(0, 0.01, n),
    )


@pytest.mark.parametrize(
    "axes", [["k", "i", "j", "i", "k"], ["k"] * 4, ["j", "i", "i"], ["i", "j", "k", "j", "i", "k"]]
)
def test_book_recursion_vs_pinocchio(axes):
    rng = np.random.default_rng(len(axes))
    hand = random_hand(rng, axes)
    model = hand.pin_model()
    data = model.createData()
    for _ in range(5):
        th = rng.uniform(-2, 2, hand.n)
        thd = rng.standard_normal(hand.n)
        thdd = rng.standard_normal(hand.n)
        UW, dV, _ = hand.terms(th)
        M = pin.crba(model, data, th)
        M = np.triu(M) + np.triu(M, 1).T
        assert np.max(np.abs(UW - M)) < 1e-14  # (8-105)
        assert (
            np.max(np.abs(dV - pin.computeGeneralizedGravity(model, data, th))) < 1e-14
        )  # (8-107)
        F = hand.inverse(th, thd, thdd)  # (8-109)
        assert np.max(np.abs(F - (pin.rnea(model, data, th, 0 * th, thdd) + hand.xi * thd))) < 1e-13
        Ffull = hand.inverse(th, thd, thdd, coriolis=True)
        assert (
            np.max(np.abs(Ffull - (pin.rnea(model, data, th, thd, thdd) + hand.xi * thd))) < 1e-13
        )
        a = hand.forward(th, thd, F + 0.01)
        assert np.max(np.abs(a - pin.aba(model, data, th, 0 * th, F + 0.01 - hand.xi * thd))) < 1e-9
        # CoM positions (8-98) vs Pinocchio's body placements
        pin.forwardKinematics(model, data, th)
        for i, p in enumerate(hand.positions(th)):
            assert np.allclose(p, data.oMi[i + 1].act(hand.r[i]), atol=1e-15)


def test_printed_gravity_sign_8_109_fails():
    hand = H.default_hand()
    model = hand.pin_model()
    th = np.array([0.2, 0.9, 0.4])
    ref = pin.computeGeneralizedGravity(model, model.createData(), th)
    assert np.allclose(hand.gravity(th), ref, atol=1e-15)
    assert not np.allclose(hand.gravity_printed(th), ref, atol=1e-6)  # printed "+Σ m g k⁰ ∂r/∂θ"


def test_printed_delta_i_fails():
    """dE^{iθ}/dθ = Δ^i E^{iθ}; the printed Δ^i (third row zero, l. 6725) does not satisfy it."""
    th, h = 0.7, 1e-6
    dE = (H.elementary_rotation("i", th + h) - H.elementary_rotation("i", th - h)) / (2 * h)
    for ax in "ijk":
        dEa = (H.elementary_rotation(ax, th + h) - H.elementary_rotation(ax, th - h)) / (2 * h)
        assert np.allclose(dEa, H.DELTA[ax] @ H.elementary_rotation(ax, th), atol=1e-9)
    assert not np.allclose(dE, H.DELTA_I_PRINTED @ H.elementary_rotation("i", th), atol=1e-3)


def test_coriolis_over_grasp_is_significant_for_a_fast_grasp():
    res = H.coriolis_over_grasp(duration=0.3)
    assert res["F_full"].shape == (61, 3)
    # the dropped terms are not negligible for a 0.3 s grasp (several % of the torque)
    assert np.max(res["ratio"]) > 0.02
    slow = H.coriolis_over_grasp(duration=3.0)
    assert np.max(slow["ratio"]) < np.max(res["ratio"])  # slow motion: the book's assumption


def test_bad_input():
    with pytest.raises(ValueError, match="axes"):
        H.HandModel(axes=["q"], l=np.zeros((2, 3)), r=np.zeros((1, 3)), m=[1.0], J=[0.1])
    with pytest.raises(InertiaError):
        H.HandModel(axes=["i"], l=np.zeros((2, 3)), r=np.zeros((1, 3)), m=[0.0], J=[0.0])
    with pytest.raises(InertiaError):
        H.HandModel(axes=["i"], l=np.zeros((2, 3)), r=np.zeros((1, 3)), m=[1.0], J=[-0.1])
    hand = H.default_hand()
    with pytest.raises(ValueError, match="NaN"):
        hand.inverse([0, np.nan, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="shape"):
        hand.gravity([0, 0])
    with pytest.raises(ValueError, match="duration"):
        H.coriolis_over_grasp(duration=0.0)
