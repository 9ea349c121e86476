"""Control of the book's §9-1 (industrial robots): servo, motor, teaching and playback.

* :mod:`~anthroarm.control.motor` — a DC motor with a gearbox: the torque–speed line of
  Eq. (9-1), stall torque, no-load speed, the thermal (RMS) limit, reflected inertia;
* :mod:`~anthroarm.control.servo` — the analog position servo (9-1)–(9-8) as an ODE and as
  transfer functions, its steady error and the load-torque estimator (Fig. 9-15, 9-16).

SI units throughout (the book prints kgf·cm); joint side unless a name says motor side.
"""

from . import motor, servo
from .motor import DCMotor, ThermalCheck, rms
from .servo import PositionServo, ServoResponse

__all__ = ["motor", "servo", "DCMotor", "ThermalCheck", "rms", "PositionServo", "ServoResponse"]
