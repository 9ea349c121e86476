"""Subproblem IK (anthroarm.ik.classify._solve_spherical_two_parallel, all 8 branches, no limit
filter or FK check) vs PyPI ik-geo (Rust, class spherical_two_parallel) on sixr_arm.

Run: .venv/bin/python benchmarks/timing_ik_subproblems.py [--poses 300]  (a development script, not one of
the benchmarks `python -m benchmarks` runs: those are the bench_*.py modules with a run())
Prints medians (µs per pose) and agreement; writes nothing."""

from __future__ import annotations

import argparse
import time

import numpy as np

import anthroarm as aa
from anthroarm.ik import classify as C


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--poses", type=int, default=300)
    args = ap.parse_args()
    import ik_geo

    robot = aa.load("sixr_arm")
    kin = C.classify(robot).kinematics
    P = C._spherical_wrist_P(kin)
    geo = ik_geo.Robot.spherical_two_parallel(kin.H.tolist(), P.tolist())
    rng = np.random.default_rng(0)
    qs = robot.chain.random_q(args.poses, rng)
    Ts = np.array([robot.fk(q) for q in qs])
    Rt = kin.R_tool.T
    t_ours, t_geo, agree = [], [], 0
    C._solve_spherical_two_parallel(kin, Ts[0])
    geo.get_ik((Ts[0, :3, :3] @ Rt).T.tolist(), Ts[0, :3, 3].tolist())
    for T in Ts:
        t0 = time.perf_counter()
        ours, valid, exact = C._solve_spherical_two_parallel(kin, T)
        t1 = time.perf_counter()
        theirs = geo.get_ik((T[:3, :3] @ Rt).T.tolist(), T[:3, 3].tolist())
        t2 = time.perf_counter()
        t_ours.append(t1 - t0)
        t_geo.append(t2 - t1)
        th = np.array([s for s, ls in theirs if not ls])
        if len(th) == exact.sum():
            d = np.abs(np.angle(np.exp(1j * (ours[exact][:, None] - th[None])))).max(-1)
            agree += bool(d.min(1).max() < 1e-8)
    t0 = time.perf_counter()
    big = np.repeat(Ts, max(1, 10000 // len(Ts)), axis=0)
    C._solve_spherical_two_parallel(kin, big)
    t_batch = (time.perf_counter() - t0) / len(big)
    print(f"poses {len(Ts)}; same 8 solutions on {agree}/{len(Ts)}")
    print(f"single pose, median µs: anthroarm subproblems {np.median(t_ours) * 1e6:.1f}, "
          f"ik-geo {np.median(t_geo) * 1e6:.1f}")
    print(f"batched N={len(big)}: anthroarm {t_batch * 1e6:.2f} µs/pose")


if __name__ == "__main__":
    main()
