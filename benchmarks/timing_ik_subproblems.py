"""Closed-form IK by the arm's geometry (anthroarm.ik.geometric: IK-Geo's class solvers built on
the batched subproblems) vs PyPI ik-geo (Rust) on the same poses, one process.

Per arm: the class solver alone (all 8 branches, no limits, no FK check) and ``aa.ik.analytic``
(limits, FK check) for one pose; both batched at N poses; ik-geo's ``get_ik`` per pose; and
whether the exact solutions are the same (count and values, mod 2π).

Run: .venv/bin/python benchmarks/timing_ik_subproblems.py [--poses 200] [--batch 10000]
(a development script, not one of the benchmarks `python -m benchmarks` runs: those are the
bench_*.py modules with a run()).  Prints medians (µs per pose); writes nothing."""

from __future__ import annotations

import argparse
import time

import numpy as np

import anthroarm as aa
from anthroarm.ik import closed_form, geometric as G

ARMS = ("sixr_arm", "ur5", "ur10", "kinova", "prosthetic_arm", "talos_arm")


def _geo_pose(gp, T):
    R, p = T[:3, :3], T[:3, 3]
    if gp.reversed:
        R, p = R.T, -R.T @ p
    return (R @ gp.R_tool.T).T.tolist(), p.tolist()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--batch", type=int, default=10000)
    args = ap.parse_args()
    import ik_geo

    print(f"{'arm':15s} {'class':34s} {'same':>9s} {'ours 1':>8s} {'analytic 1':>10s} {'ik-geo 1':>8s} "
          f"{'ours N':>8s} {'analytic N':>10s}   (µs per pose)")
    for name in ARMS:
        robot = aa.load(name)
        gp = G.plan_for(robot)
        geo = getattr(ik_geo.Robot, gp.cls)(gp.H.tolist(), gp.P.tolist())
        Ts = robot.fk(robot.random_q(args.poses, np.random.default_rng(0)))
        G.solve(gp, Ts[:1])
        t_ours, t_geo, t_an, same = [], [], [], 0
        for T in Ts:
            t0 = time.perf_counter()
            q, valid, exact = G.solve(gp, T[None])
            t1 = time.perf_counter()
            sols = geo.get_ik(*_geo_pose(gp, T))
            t2 = time.perf_counter()
            t_ours.append(t1 - t0)
            t_geo.append(t2 - t1)
            th = np.array([s for s, ls in sols if not ls]).reshape(-1, 6)
            th = (th[:, ::-1] if gp.reversed else th)[:, gp.order]
            ours = q[0][exact[0]]
            if len(th) == len(ours):
                d = np.abs(np.angle(np.exp(1j * (ours[:, None] - th[None])))).max(-1) if len(th) else np.zeros((0, 0))
                same += bool(d.size == 0 or (d.min(1).max() < 1e-8 and d.min(0).max() < 1e-8))
        if closed_form.closed_form_info(robot).family == gp.cls:      # solved by geometry, not a book kernel
            for T in Ts[:50]:
                t0 = time.perf_counter()
                aa.ik.analytic(robot, T)
                t_an.append(time.perf_counter() - t0)
        big = np.repeat(Ts, max(1, args.batch // len(Ts)), axis=0)
        t0 = time.perf_counter()
        G.solve(gp, big)
        t_batch = (time.perf_counter() - t0) / len(big)
        t0 = time.perf_counter()
        if t_an:
            aa.ik.analytic_batch(robot, big)
        t_anb = (time.perf_counter() - t0) / len(big)
        an1 = f"{np.median(t_an) * 1e6:10.0f}" if t_an else f"{'(book)':>10s}"
        anb = f"{t_anb * 1e6:10.1f}" if t_an else f"{'(book)':>10s}"
        print(f"{name:15s} {gp.cls + (' rev' if gp.reversed else ''):34s} {same:4d}/{len(Ts):<4d} "
              f"{np.median(t_ours) * 1e6:8.0f} {an1} {np.median(t_geo) * 1e6:8.1f} {t_batch * 1e6:8.2f} {anb}")
    print("ours 1 / ik-geo 1: one pose, all branches; ours N: the class solver batched over N poses; "
          "analytic: + limits, FK check (registered book arms use their own kernels: '(book)')")


if __name__ == "__main__":
    main()
