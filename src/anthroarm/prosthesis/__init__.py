"""From a person's motion to a prosthesis's motors (issue 17): joint demands of activities with a
held object (:mod:`.envelope`, loads by Eq. (8-5)), motor and gearbox catalogues
(:mod:`.catalogue`), actuator sizing with the servo model of Eq. (9-1) (:mod:`.sizing`), the
book's weight rules (:mod:`.weight_rules`), a person's residual muscles (:mod:`.residual`), the whole loop for one person (:mod:`.study`) and the
HTML report (:mod:`.report`); the ``anthroarm size`` command is :mod:`anthroarm.cli.size`.

Modules are imported lazily (``aa.prosthesis.sizing``).
"""

from __future__ import annotations

import importlib

_SUBMODULES = {"catalogue", "envelope", "sizing", "weight_rules", "study", "report", "residual"}


def __getattr__(name):
    if name in _SUBMODULES:
        mod = importlib.import_module(f".{name}", __name__)
        globals()[name] = mod
        return mod
    raise AttributeError(f"module 'anthroarm.prosthesis' has no attribute {name!r}")


__all__ = sorted(_SUBMODULES)
