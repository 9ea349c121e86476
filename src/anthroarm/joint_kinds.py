"""The kinds of joint every layer names (foundation: imports nothing).

``robot.chain`` (:class:`anthroarm.chain.Chain`) gives each joint one of these kinds and the
batched kernel (:mod:`anthroarm.serial_chain`) reads them; both import them from here, so
neither imports the other to learn them.  :mod:`anthroarm.chain` re-exports them.
"""

from __future__ import annotations

#: a bounded revolute joint (angle in rad)
REVOLUTE = "revolute"
#: a prismatic joint (displacement in m)
PRISMATIC = "prismatic"
#: an unbounded revolute joint: its configuration is (cos θ, sin θ), two entries of q, one of v
CONTINUOUS = "continuous"
