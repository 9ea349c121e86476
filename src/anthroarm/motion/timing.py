"""Minimum-jerk timing of rest-to-rest motions (Flash & Hogan 1985).

Flash & Hogan, "The coordination of arm movements: an experimentally confirmed mathematical
model", J. Neurosci. 5(7), 1688–1703 (1985): the motion from rest to rest in time T that
minimises the integrated squared jerk ∫ (d³x/dt³)² dt is, for each coordinate::

    x(t) = x0 + (x1 − x0) s(τ),   s(τ) = 10 τ³ − 15 τ⁴ + 6 τ⁵,   τ = t / T,

the quintic with zero velocity and acceleration at both ends (their solution for a
point-to-point movement).  :func:`keyframe_trajectory` chains such segments through keyframes with
optional holds: q, q̇ and q̈ are continuous (every segment starts and ends at rest), q⃛ jumps at the
keyframes.

Units: s, and the coordinates' own units (rad, m).
"""

from __future__ import annotations

import numpy as np

from ..dynamics.profiles import minimum_jerk as _minimum_jerk


def minimum_jerk(x0, x1, duration: float, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and acceleration of the rest-to-rest minimum-jerk motion from ``x0``
    to ``x1`` (arrays of the same shape) in ``duration`` s, at times ``t`` (clipped to
    [0, duration]).  Returns arrays of shape ``t.shape + x0.shape``.  The formula is
    :func:`anthroarm.dynamics.profiles.minimum_jerk` (one source); this adds scalar
    coordinates."""
    x0 = np.asarray(x0, float)
    T = float(duration)
    if not (np.isfinite(T) and T > 0):
        raise ValueError(f"duration must be a positive number of seconds, got {duration!r}")
    x, v, a = _minimum_jerk(x0, x1, T, t)
    return (x[..., 0], v[..., 0], a[..., 0]) if x0.ndim == 0 else (x, v, a)


def keyframe_trajectory(Q, durations, holds=None, rate: float = 100.0):
    """Chain minimum-jerk segments through keyframes.

    Parameters
    ----------
    Q : (K, n)
        Keyframe coordinates; the motion starts at rest at ``Q[0]``.
    durations : (K,)
        s; ``durations[k]`` is the time to move from keyframe k−1 to k (``durations[0]`` is
        ignored unless ``holds[0]``).
    holds : (K,), optional
        s spent at rest at each keyframe after reaching it.
    rate : float
        Samples per second.

    Returns
    -------
    t (M,), q (M, n), qd (M, n), qdd (M, n), arrival (K,) times at which each keyframe is reached.
    """
    Q = np.asarray(Q, float)
    K = Q.shape[0]
    dur = np.asarray(durations, float)
    hold = np.zeros(K) if holds is None else np.asarray(holds, float)
    if (
        dur.shape != (K,)
        or hold.shape != (K,)
        or not (np.isfinite(dur).all() and np.isfinite(hold).all())
    ):
        raise ValueError(f"durations and holds must be {K} finite numbers (s)")
    if np.any(dur[1:] <= 0) or np.any(hold < 0):
        raise ValueError("durations must be > 0 s and holds >= 0 s")
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a positive number (Hz), got {rate!r}")
    # breakpoints: [hold 0] [move 1] [hold 1] [move 2] ...
    arrival = np.zeros(K)
    segs = []  # (t_start, t_end, q_from, q_to)
    tc = 0.0
    for k in range(K):
        if k > 0:
            segs.append((tc, tc + dur[k], Q[k - 1], Q[k]))
            tc += dur[k]
        arrival[k] = tc
        if hold[k] > 0:
            segs.append((tc, tc + hold[k], Q[k], Q[k]))
            tc += hold[k]
    total = tc
    M = int(np.floor(total * rate + 1e-9)) + 1
    t = np.arange(M) / rate
    q = np.empty((M, Q.shape[1]))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    q[:] = Q[0]
    for a, b, x0, x1 in segs:
        sel = (t >= a) & (t <= b)
        if not sel.any():
            continue
        x, v, acc = minimum_jerk(x0, x1, b - a, t[sel] - a)
        q[sel], qd[sel], qdd[sel] = x, v, acc
    return t, q, qd, qdd, arrival
