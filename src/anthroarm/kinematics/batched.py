"""Batched forward kinematics and Jacobians of any serial chain:
:class:`~anthroarm.serial_chain.SerialChain`, re-exported here.

The class lives in the model layer (:mod:`anthroarm.serial_chain`) because ``robot.chain``
builds one per frame (:meth:`anthroarm.chain.Chain.serial`); the algorithms import it from here
or from there.
"""

from __future__ import annotations

from ..serial_chain import SerialChain

__all__ = ["SerialChain"]
