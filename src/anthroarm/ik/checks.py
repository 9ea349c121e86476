"""Cross-check rows of the closed-form IK (``anthroarm check``): FK∘IK round trips.

For each catalog arm solved as a family by :mod:`anthroarm.ik.families` (an SRS arm by swivel
angle, a planar 2R arm; the 6R classes have their rows in :func:`anthroarm.ik.geometric.check_rows`):
random configurations inside the limits → Pinocchio FK →
:func:`anthroarm.ik.analytic_batch` → Pinocchio FK of every returned solution; the row reports
the largest pose difference (3×4 entries; position only for a planar arm) and whether every pose
got at least one solution (a pose without one counts as an infinite error)."""

from __future__ import annotations

import numpy as np

from .. import models as catalog
from ..check_rows import CheckRow
from ..robot import load
from .closed_form import PLANAR, SRS, analytic_batch, closed_form_info
from .qp.tasks.swivel import swivel_angle


def rows(models, samples, rng) -> list[CheckRow]:
    out = []
    for name in catalog.names() if models is None else models:
        try:
            robot = load(name)
        except Exception:  # noqa: BLE001 - not a catalog arm: its rows come from elsewhere
            continue
        form = closed_form_info(robot)
        if form is None or form.family not in (SRS, PLANAR):
            continue
        Q = robot.random_q(samples, rng)
        T = robot.fk(Q)
        kw = {"swivel": swivel_angle(robot, Q)} if form.swivel else {}
        res = analytic_batch(robot, T, **kw)
        i, b = np.nonzero(res.valid)
        Tf = robot.fk(res.solutions[i, b]) if len(i) else np.zeros((0, 4, 4))
        if form.position_only:
            err = np.abs(Tf[:, :3, 3] - T[i, :3, 3]).max(1) if len(i) else np.zeros(0)
        else:
            err = np.abs(Tf[:, :3, :] - T[i, :3, :]).max(axis=(1, 2)) if len(i) else np.zeros(0)
        worst = float(err.max()) if len(err) else float("inf")
        if not res.valid.any(1).all():
            worst = float("inf")
        out.append(
            CheckRow(
                name,
                "analytic IK: FK(IK(T)) = T, all branches",
                worst,
                1e-10,
                samples,
                oracle="pinocchio FK",
                note=f"{res.valid.sum(1).mean():.2f} solutions/pose",
            )
        )
    return out
