"""Mechanism design (book Ch. 2-4): mobility, grasp error, motion curves, synthesis, optimisers.

Submodules (import them directly, e.g. ``from anthroarm.design import structure``):
``structure`` (Table 2.1, Eq. (2-1)–(2-4)), ``grasp_error`` ((2-5)–(2-20)), ``motion_curves``
(Ch. 3 fitted curves, difference table, least squares, piecewise coordination), ``synthesis``
(four-bar path synthesis (3-11)–(3-30)), ``optimize`` (Ch. 4 optimisers), ``thumb_design`` (§4-5).
"""

import importlib

_SUBMODULES = {"structure", "grasp_error", "motion_curves", "synthesis", "optimize", "thumb_design"}


def __getattr__(name):
    if name in _SUBMODULES:
        mod = importlib.import_module(f".{name}", __name__)
        globals()[name] = mod
        return mod
    raise AttributeError(f"module 'anthroarm.design' has no attribute {name!r}")
