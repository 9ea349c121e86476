"""The batched serial chain (``anthroarm.serial_chain.SerialChain``, built per frame by
``robot.chain``): pose and LOCAL_WORLD_ALIGNED Jacobian of every catalog model against Pinocchio."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.serial_chain import SerialChain


@pytest.mark.parametrize("name", aa.models.names())
def test_serial_chain_vs_pinocchio(name):
    r = aa.load(name)
    Q = r.random_q(100, 6)
    T, J = SerialChain.of(r).fk_jacobian(Q)
    np.testing.assert_allclose(T, r.fk(Q), atol=1e-13)
    np.testing.assert_allclose(J, r.jacobian(Q), atol=1e-13)
