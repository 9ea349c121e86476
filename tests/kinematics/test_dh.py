"""The book's H-D convention (``anthroarm.kinematics.dh``): A = Rz(θ) Tz(s) Tx(h) Rx(α), and the
H-D chain and its Jacobian of every H-D catalog arm against Pinocchio."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.kinematics.dh import dh_fk, dh_jacobian, dh_transform
from anthroarm.models.spec import DHRow, dh_matrix

N = 300


def test_dh_transform_is_rz_tz_tx_rx():
    """Eq. (6-12) equals Rz(θ) Tz(s) Tx(h) Rx(α) (mathematics, element by element)."""
    rng = np.random.default_rng(0)
    th, s, h, al = rng.uniform(-3, 3, 4)
    Rz = np.eye(4)
    Rz[:2, :2] = [[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]
    Rx = np.eye(4)
    Rx[1:3, 1:3] = [[np.cos(al), -np.sin(al)], [np.sin(al), np.cos(al)]]
    Tz, Tx = np.eye(4), np.eye(4)
    Tz[2, 3], Tx[0, 3] = s, h
    np.testing.assert_allclose(dh_transform(th, s, h, al), Rz @ Tz @ Tx @ Rx, atol=1e-15)
    np.testing.assert_allclose(
        dh_matrix(DHRow("R", al, s=s, h=h), th), Rz @ Tz @ Tx @ Rx, atol=1e-15
    )


@pytest.mark.parametrize("name", ["sixr_arm", "unimate5", "rrprr5", "prosthetic_arm"])
def test_dh_chain_and_jacobian_vs_pinocchio(name):
    r = aa.load(name)
    Q = r.random_q(N, 1)
    np.testing.assert_allclose(dh_fk(r.spec.dh, Q, r.spec.tool_dh), r.fk(Q), atol=1e-13)
    np.testing.assert_allclose(dh_jacobian(r.spec.dh, Q, r.spec.tool_dh), r.jacobian(Q), atol=1e-13)
