"""Dynamics (book Ch. 8): symbolic Lagrange equations, the book's formulations, simulation.

Modules (imported lazily, e.g. ``aa.dynamics.lagrange``):

* :mod:`.lagrange` — T, V -> M(q), C(q, q̇)q̇ (Christoffel), g(q), τ for any catalog arm; LaTeX;
  generated numpy code cached on disk (optional C backend, :mod:`.ccode`);
* :mod:`.equivalent_link` — §8-2 equivalent link J*, M* (8-19)–(8-29), energy/moment forms;
* :mod:`.euler_chain` — §8-3 X–Y–X Euler-angle ball-joint chain (8-41)–(8-96);
* :mod:`.hand_model` — §8-4 prosthetic-hand Lagrange model (8-97)–(8-112);
* :mod:`.profiles` — the minimum-jerk rest-to-rest profile (numpy only, light to import);
* :mod:`.simulate` — RK4 / solve_ivp with damping and energy bookkeeping;
* :mod:`.human` — gravity-torque maps and reaching torques of ``human_arm7``;
* :mod:`.loads` — external wrenches and held objects as generalised forces (8-5), τ = rnea − Jᵀw;
* :mod:`.checks` — the rows of ``anthroarm check``.
"""

from __future__ import annotations

import importlib

_SUBMODULES = {
    "lagrange",
    "equivalent_link",
    "euler_chain",
    "hand_model",
    "simulate",
    "human",
    "checks",
    "ccode",
    "loads",
    "profiles",
}


def __getattr__(name):
    """Lazy submodules (PEP 562), and ``load``: the shortcut for
    :func:`anthroarm.dynamics.lagrange.load`, loaded on first use like the submodules (importing
    :mod:`.lagrange` costs ~50 ms, which ``import anthroarm.dynamics.profiles`` does not pay)."""
    if name in _SUBMODULES:
        mod = importlib.import_module(f".{name}", __name__)
        globals()[name] = mod
        return mod
    if name == "load":
        return importlib.import_module(".lagrange", __name__).load
    raise AttributeError(f"module 'anthroarm.dynamics' has no attribute {name!r}")


__all__ = sorted(_SUBMODULES) + ["load"]
