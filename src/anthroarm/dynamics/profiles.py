"""Time profiles of point-to-point motions, numpy only (light to import: :mod:`anthroarm.motion`
uses them on the CLI's start-up path).

Flash & Hogan, "The coordination of arm movements: an experimentally confirmed mathematical
model", J. Neurosci. 5(7), 1688-1703 (1985): the rest-to-rest motion in time T that minimises
the integrated squared jerk is x0 + (x1 - x0) s(t/T), s(τ) = 10 τ³ - 15 τ⁴ + 6 τ⁵.
"""

from __future__ import annotations

import numpy as np


def minimum_jerk(q0, q1, T: float, t):
    """Minimum-jerk point-to-point motion q(t), q̇(t), q̈(t) from q0 to q1 in T seconds."""
    if not (np.isfinite(T) and T > 0):
        raise ValueError(f"minimum-jerk duration must be finite and > 0 s, got {T!r}")
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    s = np.clip(np.asarray(t, float) / T, 0.0, 1.0)[..., None]
    p = 10 * s**3 - 15 * s**4 + 6 * s**5
    pd = (30 * s**2 - 60 * s**3 + 30 * s**4) / T
    pdd = (60 * s - 180 * s**2 + 120 * s**3) / T**2
    d = q1 - q0
    return q0 + p * d, pd * d, pdd * d


__all__ = ["minimum_jerk"]
