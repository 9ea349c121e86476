"""Collision-aware QP IK: anthroarm's velocity damper vs pink's SelfCollisionBarrier and mink's
CollisionAvoidanceLimit, same targets.

Scenes: panda (example-robot-data URDF, its collision meshes as convex hulls) with a table and a
box in its workspace, from its "ready" pose; the 27-DOF human upper limb with its hand and a
torso (capsules + boxes, self collision only), from its neutral pose.  Targets: tool poses of
random configurations inside the limits whose bodies are clear of each other and of the
obstacles by more than d_min + 1 mm (reachable and collision-free by construction).  Each
target runs ``STEPS`` QP steps of dt = 10 ms from the start: FrameTask on the tool (costs 1 /
0.5, lm_damping 1e-3) + PostureTask (1e-3) toward the start, configuration + velocity limits,
both with daqp.

* ours: :class:`~anthroarm.ik.qp.limits.collision.CollisionLimit` (d_s = d_min, d_i = d_min +
  3 cm, ξ = 0.5 m/s, margin 1 mm) through :func:`~anthroarm.ik.qp.limits.collision_step.step`
  (with its step acceptance on the true distances);
* pink: ``SelfCollisionBarrier(n_collision_pairs = every pair, d_min, gain 1)`` on the same
  ``pin.GeometryModel`` (the robot's bodies and the obstacles, the same active pairs),
  ``solve_ik(..., solver="daqp", safety_break=False)``;
* mink (MuJoCo; its rows are left out, with a note, when mink is not installed):
  ``CollisionAvoidanceLimit(minimum_distance_from_collisions = d_min,
  collision_detection_distance = d_min + 3 cm, bound_relaxation 0)`` on a MuJoCo model of the
  robot's URDF whose geoms are the same bodies and obstacles (panda's hulls as MuJoCo meshes of
  the hull's points), one geom pair per active pair of ours and pink (mink's own filter drops
  panda_link6–panda_hand, bodies it calls parent and child: the notes list it), mink's FrameTask /
  PostureTask with the same costs, ConfigurationLimit (gain 0.5) + VelocityLimit,
  ``solve_ik(..., solver="daqp")``; the scene is checked before the run (tool FK against
  Pinocchio, mj_geomDistance against coal): :mod:`benchmarks.collision_mink`.  Two rows:
  "mink" with its default gain 0.85, and "mink, gain 0.85·dt".  mink's QP variable is the
  displacement Δq = v·dt (its VelocityLimit bounds Δq by v_max·dt) and the limit bounds the
  first-order distance change of that displacement by gain·(d − d_min)/dt (mink 1.3.0,
  ``limits/collision_avoidance_limit.py``): with dt = 10 ms the default gain lets a pair close
  85 times its gap to d_min in one step; gain 0.85·dt bounds it by 0.85·(d − d_min) per step.

Reported per scene and method: success (tool within 1 cm and 0.1 rad at the end), steps with
a pair closer than d_min − 1e-4 m (checked after every step with anthroarm.collision on the
Pinocchio model, every method alike), the smallest distance seen, median and p90 CPU time of
one step (``time.process_time``: the machine may be shared), and pink/ours, mink/ours.
"""

from __future__ import annotations

import logging
import time
import warnings

import numpy as np
import pinocchio as pin

import anthroarm as aa
from anthroarm import collision as C
from anthroarm.collision.checks import start_and_targets
from anthroarm.collision.distance import scene
from anthroarm.ik import qp
from anthroarm.ik.qp.limits import CollisionLimit
from anthroarm.ik.qp.limits.collision_step import step as collision_step

try:
    from . import collision_mink
except ModuleNotFoundError as exc:  # mink and mujoco: the optional "bench" extra
    if exc.name not in ("mink", "mujoco"):
        raise
    collision_mink = None

DT = 0.01
#: mink's rows: its CollisionAvoidanceLimit's gain in each (see the module docstring)
MINK_GAINS = {"mink": 0.85, "mink, gain 0.85·dt": 0.85 * DT}
PANDA_READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


def scenes():
    """(name, robot, obstacles, q0, d_min) of the two scenes."""
    panda = aa.load("panda")
    obstacles = [
        C.box((0.6, 1.0, 0.04), xyz=(0.55, 0.0, 0.1), name="table"),
        C.box((0.1, 0.1, 0.1), xyz=(0.45, 0.2, 0.35), name="box"),
    ]
    limb = aa.load("human_upper_limb")
    return [
        ("panda + table + box", panda, obstacles, PANDA_READY, 0.02),
        ("human_upper_limb (self)", limb, [], None, 0.002),
    ]


def _errors(robot, q, T):
    M = robot.fk(q)
    return float(np.linalg.norm(M[:3, 3] - T[:3, 3])), float(
        np.linalg.norm(pin.log3(M[:3, :3].T @ T[:3, :3]))
    )


EE_KW = dict(position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)


def _run(robot, env, q0, targets, d_min, steps, method):
    times, viol, worst, succ, n_steps = [], 0, np.inf, 0, 0
    if method == "ours":
        conf = qp.IKConfiguration(robot, q0)
        ee = qp.FrameTask(robot, **EE_KW)
        post = qp.PostureTask(robot, cost=1e-3, target=q0)
        limits = [*qp.default_limits(robot), CollisionLimit(robot, env, d_min, d_min + 0.03, 0.5)]
    elif method in MINK_GAINS:
        mk = collision_mink.MinkIK(robot, env, q0, d_min, DT, EE_KW, MINK_GAINS[method])
    else:
        import pink  # noqa: PLC0415 - the peer, optional
        from pink.barriers import SelfCollisionBarrier  # noqa: PLC0415
        from pink.tasks import FrameTask, PostureTask  # noqa: PLC0415

        sc = scene(C.model(robot), env)
        gm = sc.geometry
        ee = FrameTask(robot.tool, **EE_KW)
        post = PostureTask(cost=1e-3)
        post.set_target(q0)
        barrier = SelfCollisionBarrier(n_collision_pairs=len(gm.collisionPairs), d_min=d_min)
    for T in targets:
        if method == "ours":
            conf.update(q0.copy())
            ee.set_target(T)
        elif method in MINK_GAINS:
            mk.reset(T)
        else:
            pconf = pink.Configuration(
                robot.model, robot.model.createData(), q0.copy(), collision_model=gm,
                collision_data=pin.GeometryData(gm),
            )  # fmt: skip
            ee.set_target(pin.SE3(T))
        for _ in range(steps):
            t0 = time.process_time()
            if method == "ours":
                v = collision_step(conf, None, [ee, post], DT, limits=limits)
                conf.integrate_inplace(v, DT)
                q = conf.q
            elif method in MINK_GAINS:
                q = mk.step()
            else:
                try:
                    v = pink.solve_ik(
                        pconf, [ee, post], DT, solver="daqp", barriers=[barrier], safety_break=False
                    )
                except Exception:  # NoSolutionFound: zero velocity, counted in success
                    v = np.zeros(robot.nv)
                pconf.integrate_inplace(v, DT)
                q = pconf.q
            times.append(time.process_time() - t0)
            d = float(C.min_distance(robot, q, env))
            worst = min(worst, d)
            viol += d < d_min - 1e-4
            n_steps += 1
        ep, er = _errors(robot, q, T)
        succ += ep < 0.01 and er < 0.1
    t = np.array(times) * 1e3
    return {
        "success": succ / max(len(targets), 1),
        "violations": int(viol),
        "steps": n_steps,
        "min_distance": worst,
        "median_ms": float(np.median(t)),
        "p90_ms": float(np.percentile(t, 90)),
        **(mk.report() if method in MINK_GAINS else {}),
    }


def run(quick: bool = False, n_targets: int | None = None) -> dict:
    warnings.filterwarnings("ignore")
    n = n_targets or (5 if quick else 1000)
    steps = 40 if quick else 150
    methods = ("ours", "pink", *(MINK_GAINS if collision_mink is not None else ()))
    rows, out, mink_notes = [], {}, []
    for name, robot, obstacles, q0, d_min in scenes():
        env = C.environment(obstacles)
        qs, targets = start_and_targets(
            robot, n, rng=0, d_clear=d_min + 0.001, obstacles=env, tries=50 * n
        )
        q0 = qs if q0 is None else q0
        logging.disable(logging.WARNING)  # pink logs an out-of-limit step (inside its timed call)
        try:
            res = {m: _run(robot, env, q0, targets, d_min, steps, m) for m in methods}
        finally:
            logging.disable(logging.NOTSET)
        out[name] = res
        for m in methods:
            r = res[m]
            ratio = r["median_ms"] / res["ours"]["median_ms"]
            rows.append([
                name, m, len(targets), d_min, f"{100 * r['success']:.1f} %", r["violations"],
                r["steps"], r["min_distance"], r["median_ms"], r["p90_ms"],
                ratio if m == "pink" else "", ratio if m in MINK_GAINS else "",
            ])  # fmt: skip
        if "mink" in res:
            mink_notes.append(_mink_note(name, res))
    return {
        "title": (
            "Collision-aware QP IK: velocity damper vs pink's SelfCollisionBarrier and mink's "
            "CollisionAvoidanceLimit"
        ),
        "columns": [
            "scene",
            "method",
            "targets",
            "d_min (m)",
            "success",
            "steps < d_min - 1e-4",
            "steps",
            "min distance (m)",
            "median step (ms CPU)",
            "p90 step (ms CPU)",
            "pink / ours",
            "mink / ours",
        ],  # fmt: skip
        "rows": rows,
        "results": out,
        "notes": (__doc__ or "").strip()
        + f"\n\nThis run: {n} targets per scene requested, {steps} steps per target."
        + (
            "\n\n" + "\n\n".join(mink_notes)
            if collision_mink is not None
            else "\n\nmink is not installed: its rows are left out (pip install -e '.[bench]')."
        ),
    }


def _mink_note(name: str, res: dict) -> str:
    """The checks of mink's MuJoCo scene and its QP failures, as a line of the notes."""
    r = res["mink"]
    dropped = ", ".join(f"{a}–{b}" for a, b in r["dropped_pairs"])
    return (
        f"mink, {name} ({r['versions']}): tool FK vs Pinocchio {r['fk_error']:.1e} over 100 "
        f"random q; mj_geomDistance vs coal {r['distance_error']:.1e} m over "
        f"{r['distance_pairs']} separated pairs within the detection distance, "
        f"{r['depth_error']:.1e} m over {r['penetrating_pairs']} penetrating ones"
        + (
            " (MuJoCo's capsule-box penetration depth is not coal's EPA depth)"
            if r["depth_error"] > 1e-6
            else ""
        )
        + f", {r['sign_errors']} sign disagreements; {r['pairs']} geom pairs"
        + (f", of which mink's filter drops {dropped} (parent-child bodies)" if dropped else "")
        + "; solve_ik raised NoSolutionFound "
        + ", ".join(f"{res[m]['no_solution']} times ({m})" for m in MINK_GAINS)
        + " (zero velocity)."
    )


def run_grasps(quick: bool = False, n: int | None = None) -> dict:
    """Collision-free grasps on the human limb's hand (:func:`anthroarm.hand.solve_grasp` with
    ``collision_free=True``) beside the same grasps without collisions, on the same problems:
    ``hand.problems.collision_free_grasps`` (thumb-index pinches of cylinders and spheres,
    radius 15-35 mm, whose witness is collision-free by coal: fingertip capsules within the
    1 mm contact margin, nothing into the object or another body), given contacts, the
    comfortable arm posture with the hand open as the start.  Reported per shape: success
    (the solver's criteria; with collisions also coal's: every fingertip capsule within
    [-1e-4, 1e-3] m of the object and nothing deeper than 1e-4 m into it or into another
    body), the deepest penetration (object or self) among the successes, the deepest
    penetration into the object and the deepest self-collision at every answer, failures
    included (coal), median CPU time per grasp, and which phase of the collision-free solve
    succeeded (direct / fingers / repair / approach)."""
    from anthroarm import hand as H  # noqa: PLC0415
    from anthroarm.hand.problems import collision_free_grasps, open_hand  # noqa: PLC0415
    from anthroarm.ik.qp.tasks.posture import comfortable_posture  # noqa: PLC0415

    n = n or (2 if quick else 250)
    robot = aa.load("human_upper_limb")
    hand = H.Hand(robot, tips=("index_tip", "thumb_tip"))
    q0 = open_hand(robot, hand, comfortable_posture(robot))
    rows, out = [], {}
    for kind in ("cylinder", "sphere"):
        t_gen = time.perf_counter()
        problems = collision_free_grasps(robot, n, kind=kind, rng=2026, hand=hand, per_hand=5)
        t_gen = time.perf_counter() - t_gen
        stats = {False: ([], [], [], []), True: ([], [], [], [])}
        phases = {}
        for pb in problems:
            env = C.environment([pb.obj.obstacle()])
            for cf in (False, True):
                t0 = time.process_time()
                r = H.solve_grasp(robot, pb.obj, pb.contacts, hand=hand, q0=q0, collision_free=cf)
                stats[cf][0].append(time.process_time() - t0)
                d = C.distances(robot, r.q, env)
                obj = d.body_b < 0
                stats[cf][1].append(r.success)
                stats[cf][2].append(max(0.0, -float(d.distance[obj].min())))
                stats[cf][3].append(max(0.0, -float(d.distance[~obj].min())))
                if cf:
                    ph = r.info.get("phase", "none")
                    phases[ph] = phases.get(ph, 0) + 1
        out[kind] = {"problems": len(problems), "generation_s": t_gen, "phases": phases}
        for cf in (False, True):
            t, s, pen, spen = (np.array(a, dtype=float) for a in stats[cf])
            out[kind]["collision_free" if cf else "plain"] = {
                "success": float(s.mean()) if len(s) else float("nan"),
                "max_penetration": float(np.max(pen)) if len(pen) else float("nan"),
                "median_ms": 1e3 * float(np.median(t)) if len(t) else float("nan"),
            }
            ok = s.astype(bool)
            pen_ok = float(max(np.max(pen[ok]), np.max(spen[ok]))) if ok.any() else float("nan")
            out[kind]["collision_free" if cf else "plain"]["max_depth_successes"] = pen_ok
            rows.append([
                kind, "collision_free=True" if cf else "without collisions", len(problems),
                f"{100 * s.mean():.1f} %", pen_ok, float(np.max(pen)), float(np.median(pen)),
                float(np.max(spen)), 1e3 * float(np.median(t)), 1e3 * float(np.percentile(t, 90)),
                ", ".join(f"{k} {v}" for k, v in sorted(phases.items())) if cf else "",
            ])  # fmt: skip
    return {
        "title": "Collision-free grasps on the human limb's hand (thumb-index pinches)",
        "columns": [
            "shape",
            "grasp",
            "problems",
            "success",
            "deepest penetration of the successes, object or self (m)",
            "max penetration (m)",
            "median penetration (m)",
            "max self-collision depth (m)",
            "median time (ms CPU)",
            "p90 time (ms CPU)",
            "phases",
        ],  # fmt: skip
        "rows": rows,
        "results": out,
        "notes": (run_grasps.__doc__ or "").strip()
        + f"\n\nThis run: {n} problems per shape requested.",
    }


if __name__ == "__main__":  # pragma: no cover
    import sys

    from .common import compiled_kernels, write_result

    quick = "--quick" in sys.argv
    compiled_kernels(strict=not quick)
    n = int(sys.argv[sys.argv.index("--n") + 1]) if "--n" in sys.argv else None
    if "--grasps" in sys.argv:  # python -m benchmarks.bench_collision --grasps [--n N]
        print(write_result("collision_grasp", dict(run_grasps(quick=quick, n=n), quick=quick)))
    else:  # python -m benchmarks.bench_collision [--n N]: N targets per scene (default 1000)
        print(write_result("collision", dict(run(quick=quick, n_targets=n), quick=quick)))
