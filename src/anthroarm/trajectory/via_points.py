"""Via-point joint trajectories (book §7-4 一, Figs. 7-7 / 7-8).

The book: choose a few safe via points (start A, lift-off, set-down, end E), solve the exact IK
at each, fit every joint with piecewise higher-order polynomials in t with zero velocity and
acceleration at both ends and continuity at the via points, and servo the joints to the curves.
It prints neither the degree nor the timing; we use a quintic interpolating spline per joint
(piecewise quintic polynomials, C⁴ at the via points — more than the C² required) with the two
end conditions q̇ = q̈ = 0 at each end (``scipy.interpolate.make_interp_spline``, k = 5).

Units: s, rad (or m for prismatic joints).
"""

from __future__ import annotations

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError
from ..ik.closed_form import analytic, closed_form_info


class ViaPointTrajectory:
    """q(t) through ``Q[k]`` at ``times[k]`` (strictly increasing), zero velocity and acceleration
    at ``times[0]`` and ``times[-1]``.  Call ``traj(t, derivative=0)`` with a scalar or an array
    of times; outside [t0, tN] the trajectory holds the end values (zero derivatives)."""

    def __init__(self, times, Q):
        from scipy.interpolate import make_interp_spline

        try:
            t = _check.time_grid(times, "times")
        except ControlError:
            raise ControlError(
                "times must be a strictly increasing 1-D array of >= 2 finite values, got "
                f"{_check.short(times)}"
            ) from None
        Q = _check.array(Q, "Q (joint values at the via points)")
        if Q.ndim != 2 or Q.shape[0] != t.size or Q.shape[1] == 0:
            raise ControlError(f"Q must be finite with shape ({t.size}, nq), got shape {Q.shape}")
        self.times, self.Q = t, Q
        bc = (
            [(1, np.zeros(Q.shape[1])), (2, np.zeros(Q.shape[1]))],
            [(1, np.zeros(Q.shape[1])), (2, np.zeros(Q.shape[1]))],
        )
        self._spl = make_interp_spline(t, Q, k=5, bc_type=bc)

    @property
    def duration(self) -> float:
        return float(self.times[-1] - self.times[0])

    def __call__(self, t, derivative: int = 0) -> np.ndarray:
        """q (derivative 0, rad or m), q̇ (1, per s), q̈ (2, per s²) … at time(s) ``t`` (s);
        shape ``t.shape + (nq,)``.  :class:`~anthroarm.errors.ControlError` (a ``ValueError``)
        for a NaN/inf time, a string or a derivative order
        that is not an integer in 0 … 5 (the pieces are quintic)."""
        t = _check.array(t, "t (s)")
        if (
            isinstance(derivative, bool)
            or not isinstance(derivative, (int, np.integer))
            or not 0 <= derivative <= 5
        ):
            raise ControlError(f"derivative must be an integer in 0 ... 5, got {derivative!r}")
        tc = np.clip(t, self.times[0], self.times[-1])
        out = self._spl(tc, nu=derivative)
        if derivative > 0:
            outside = (t < self.times[0]) | (t > self.times[-1])
            out = np.where(np.asarray(outside)[..., None], 0.0, out)
        return out


def joint_via_trajectory(
    robot, poses, times, *, q_start=None, swivel=0.0
) -> tuple[ViaPointTrajectory, np.ndarray]:
    """Solve the closed-form IK at each via pose (4×4, m) and fit :class:`ViaPointTrajectory`.

    At each via point the solution nearest (max-norm) to the previous one is taken (the first is
    nearest to ``q_start``, default the neutral configuration), so the trajectory stays on one
    branch.  Returns (trajectory, Q).  :class:`~anthroarm.errors.ControlError` (a ``ValueError``)
    names a via point without a solution."""
    poses = _check.array(poses, "poses")
    if poses.ndim != 3 or poses.shape[1:] != (4, 4):
        raise ControlError(f"poses must be an array of 4x4 poses (N, 4, 4), got {poses.shape}")
    prev = robot.neutral() if q_start is None else robot.check_q(q_start, "q_start")
    form = closed_form_info(robot)
    kw = {"swivel": swivel} if form is not None and form.swivel else {}  # redundant arm: one swivel
    Q = []
    for k, T in enumerate(poses):
        res = analytic(robot, T, **kw)
        if not res.success:
            raise ControlError(f"via point {k} has no IK solution: {res.reason}")
        i = int(np.argmin(np.abs(res.solutions - prev).max(1)))
        prev = res.solutions[i]
        Q.append(prev)
    Q = np.array(Q)
    return ViaPointTrajectory(times, Q), Q
