"""OpenSim models: marker IK on a real walk and batched FK, anthroarm vs OpenSim 4.6 itself.

Marker IK: the Gait2354 pipeline's subject01_walk1.trc (41 markers, 60 Hz) with its
Setup_IK.xml (31 marker weights, 4 coordinate tasks, 0.4-1.6 s = 73 frames) on the scaled
subject01 model it was recorded for (23 coordinates, knee translations splines of the knee
angle), loaded by aa.load.  OpenSim: its InverseKinematicsTool run from the setup file
(run(): the model's initSystem, the marker file, the solve, the .mot written), and its
InverseKinematicsSolver set up as the tool does (assemble the first frame, track the others;
the per-frame time is the mean track).  anthroarm: motion.osim_marker_ik (Levenberg-Marquardt
in the coordinates through the coupling map, a compiled normal-equations kernel, warm start;
tolerance 1e-4 rad on the estimated distance to the optimum) on the same frames with the same weights; the 'file to file' row times
aa.load + read_trc + read_ik_setup + osim_marker_ik + write_mot, the tool's counterpart.
Both run in this process, interleaved, wall-clock medians of the repeats; the compiled kernel is
loaded from the disk cache (warm).  The 'cold' row runs the file-to-file pipeline in a fresh
process with an empty cache (the kernel compiled on that first call).  Agreement: the largest
excess of our per-frame marker RMS over OpenSim's (target <= 0.1 mm) and the worst coordinate's
angle RMS difference from OpenSim's (target <= 0.5 deg).

Batched FK: the world pose of every body (12) of the same model for N random states inside
the coordinate ranges: anthroarm's motion.body_poses on the (N, 23) batch (one walk down the
tree through the coupling map), and the public robot.fk(Q, body) (one batched serial chain per
body), against a Python loop over OpenSim states (state.setQ, model.realizePosition,
getTransformInGround of each body, its position read into numpy).  Max abs diff of the
positions (m) over all states and of the rotation matrices over the first 200.  Targets: IK >= 10x faster per frame than OpenSim's tool, FK >= 10x.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

import numpy as np

import anthroarm as aa
from anthroarm.motion import (
    body_poses,
    opensim_ik,
    opensim_tool,
    osim_marker_ik,
    read_ik_setup,
    read_trc,
    rotational_coordinates,
    write_mot,
)

RECORDINGS = Path(aa.__file__).parent / "data" / "opensim" / "recordings"
MODEL = RECORDINGS.parent / "subject01_simbody.osim"
TRC = RECORDINGS / "subject01_walk1.trc"
SETUP = RECORDINGS / "subject01_Setup_IK.xml"

COLD = """
import time, sys
t0 = time.perf_counter()
import anthroarm as aa
from anthroarm.motion import osim_marker_ik, read_ik_setup, read_trc, write_mot
robot = aa.load(sys.argv[1])
res = osim_marker_ik(robot, read_trc(sys.argv[2]), read_ik_setup(sys.argv[3]))
write_mot(sys.argv[4], res, robot=robot)
print(time.perf_counter() - t0, len(res))
"""


def _ours_file_to_file(out: Path):
    t0 = time.perf_counter()
    robot = aa.load(str(MODEL))
    res = osim_marker_ik(robot, read_trc(TRC), read_ik_setup(SETUP))
    write_mot(out, res, robot=robot)
    return time.perf_counter() - t0, res


def _ik_rows(quick: bool) -> tuple[list, dict]:
    import opensim as osim

    osim.Logger.setLevelString("Error")
    osim.Logger.removeFileSink()
    setup = read_ik_setup(SETUP)
    trial = read_trc(TRC)
    robot = aa.load(str(MODEL))
    osim_marker_ik(robot, trial, setup)  # warm: the kernel from the disk cache
    repeats = 1 if quick else 5
    tool_s, solver_s, ours_s, f2f_s = [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            _, s = opensim_tool(SETUP, MODEL, TRC, tmp)
            tool_s.append(s)
            ref = opensim_ik(MODEL, TRC, setup)
            solver_s.append(float(np.mean(ref.seconds[1:])))
            res = osim_marker_ik(robot, trial, setup)
            ours_s.append(res.seconds / len(res))
            s, _ = _ours_file_to_file(Path(tmp) / "ours.mot")
            f2f_s.append(s)
        cold = None
        if not quick:
            env = dict(os.environ, ANTHROARM_CACHE=str(Path(tmp) / "cache"))
            env.pop("NUMBA_CACHE_DIR", None)
            out = subprocess.run(
                [
                    sys.executable,
                    "-c",
                    COLD,
                    str(MODEL),
                    str(TRC),
                    str(SETUP),
                    str(Path(tmp) / "c.mot"),
                ],
                env=env,
                capture_output=True,
                text=True,
                check=True,
            )
            cold = float(out.stdout.split()[0])
    n = len(res)
    d = res.q - ref.q[:, [ref.coordinates.index(c) for c in robot.joint_names]]
    rot = np.array([c in rotational_coordinates(robot) for c in robot.joint_names])
    angle_rms = np.rad2deg(np.sqrt(np.mean(d[:, rot] ** 2, axis=0)))
    excess = float((res.rms - ref.rms).max()) * 1e3
    worst = str(np.array(robot.joint_names)[rot][angle_rms.argmax()])
    tool_ms = 1e3 * median(tool_s) / n
    rows = [
        ["OpenSim InverseKinematicsTool.run() (setup file -> .mot)", n, tool_ms, 1.0, "", ""],
        [
            "OpenSim InverseKinematicsSolver (assemble + track)",
            n,
            1e3 * median(solver_s),
            tool_ms / (1e3 * median(solver_s)),
            float(np.median(ref.rms)) * 1e3,
            "reference",
        ],
        [
            "anthroarm osim_marker_ik (solve)",
            n,
            1e3 * median(ours_s),
            tool_ms / (1e3 * median(ours_s)),
            float(np.median(res.rms)) * 1e3,
            f"{excess:+.4f} mm; {angle_rms.max():.4f} deg ({worst})",
        ],
        [
            "anthroarm file to file (aa.load, read_trc, osim_marker_ik, write_mot)",
            n,
            1e3 * median(f2f_s) / n,
            tool_ms / (1e3 * median(f2f_s) / n),
            "",
            "",
        ],
    ]
    if cold is not None:
        rows.append(
            [
                "anthroarm file to file, fresh process, empty cache (incl. imports, compile)",
                n,
                1e3 * cold / n,
                tool_ms / (1e3 * cold / n),
                "",
                "",
            ]
        )
    info = {
        "ours_ms_per_frame": 1e3 * median(ours_s),
        "opensim_tool_ms_per_frame": tool_ms,
        "opensim_track_ms_per_frame": 1e3 * median(solver_s),
        "rms_excess_max_mm": excess,
        "angle_rms_deg": dict(zip(np.array(robot.joint_names)[rot].tolist(), angle_rms.tolist())),
        "translation_rms_mm": (np.sqrt(np.mean(d[:, ~rot] ** 2, axis=0)) * 1e3).tolist(),
        "ours_iterations_mean": float(np.mean(res.iterations)),
    }
    return rows, info


def _fk_rows(quick: bool) -> list:
    import opensim as osim

    robot = aa.load(str(MODEL))
    N = 1000 if quick else 10_000
    Q = robot.random_q(N, rng=0)
    model = osim.Model(str(MODEL))
    state = model.initSystem()
    cs = model.getCoordinateSet()
    bodies = [model.getBodySet().get(i) for i in range(model.getBodySet().getSize())]
    names = [b.getName() for b in bodies]
    # the state's Q index of each coordinate (OpenSim orders Q by mobilizer, not by name)
    qidx = []
    for name in robot.joint_names:
        state.setQ(osim.Vector(state.getNQ(), 0.0))
        cs.get(name).setValue(state, 0.123, False)
        qidx.append(int(np.flatnonzero(state.getQ().to_numpy() == 0.123)[0]))
    nq = state.getNQ()

    def opensim_loop(QQ, rotations=False):
        P = np.empty((len(QQ), len(bodies), 3))
        R = np.empty((len(QQ), len(bodies), 3, 3))
        v = osim.Vector(nq, 0.0)
        for n, q in enumerate(QQ):
            for k, i in enumerate(qidx):
                v.set(i, float(q[k]))
            state.setQ(v)
            model.realizePosition(state)
            for b, body in enumerate(bodies):
                T = body.getTransformInGround(state)
                P[n, b] = T.p().to_numpy()
                if rotations:  # element by element: only for the comparison, not timed
                    Rm = T.R()
                    R[n, b] = [[Rm.get(i, j) for j in range(3)] for i in range(3)]
        return P, R

    def ours(QQ):
        poses = body_poses(robot, QQ, names)
        T = np.stack([poses[b] for b in names], axis=1)
        return T[..., :3, 3], T[..., :3, :3]

    def ours_fk(QQ):  # the public one-frame FK, one batched call per body
        return np.stack([robot.fk(QQ, b) for b in names], axis=1)

    ours(Q[:10])
    ours_fk(Q[:10])
    t_ours = min(_timed(lambda: ours(Q)) for _ in range(3))
    t_fk = min(_timed(lambda: ours_fk(Q)) for _ in range(3))
    P1, R1 = ours(Q)
    M = 1000 if quick else 10_000
    t0 = time.perf_counter()
    P2, _ = opensim_loop(Q[:M])
    t_osim = time.perf_counter() - t0
    _, R2 = opensim_loop(Q[:200], rotations=True)
    dp = float(np.abs(P1[:M] - P2).max())
    dr = float(np.abs(R1[:200] - R2).max())
    us_ours, us_fk, us_osim = 1e6 * t_ours / N, 1e6 * t_fk / N, 1e6 * t_osim / M
    return [
        [
            f"motion.body_poses (one tree walk) of all {len(bodies)} bodies",
            N,
            us_ours,
            us_osim,
            us_osim / us_ours,
            f"{dp:.2e} m, {dr:.2e}",
        ],
        [
            f"robot.fk(Q, body), one call per body, {len(bodies)} bodies",
            N,
            us_fk,
            us_osim,
            us_osim / us_fk,
            "",
        ],
    ]


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def run(quick: bool = False) -> dict:
    ik_rows, info = _ik_rows(quick)
    fk_rows = _fk_rows(quick)
    rows = [["marker IK: " + r[0], *r[1:]] for r in ik_rows] + [
        [
            f"FK: anthroarm {r[0]} vs OpenSim's loop (setQ, realizePosition, "
            "getTransformInGround per body)",
            r[1],
            r[2],
            r[4],
            "",
            f"OpenSim {r[3]:.1f} µs/state" + (f"; max diff {r[5]}" if r[5] else ""),
        ]
        for r in fk_rows
    ]
    ik_speed = info["opensim_tool_ms_per_frame"] / info["ours_ms_per_frame"]
    notes = (
        __doc__.split("\n\n", 1)[1].replace("\n", " ").strip()
        + f" Headline: marker IK {info['ours_ms_per_frame']:.2f} ms per frame vs OpenSim's tool "
        f"{info['opensim_tool_ms_per_frame']:.1f} ms ({ik_speed:.1f}x) and its solver's track "
        f"{info['opensim_track_ms_per_frame']:.1f} ms; FK {fk_rows[0][4]:.1f}x. The IK and FK "
        "rows' 'ms or µs' column is ms per frame for IK rows and µs per state for the FK row."
    )
    return dict(
        title="OpenSim models: marker IK on a real walk and batched FK, anthroarm vs OpenSim 4.6",
        columns=[
            "what",
            "frames or states",
            "ms/frame (IK) or µs/state (FK)",
            "speed-up (vs OpenSim's tool; FK: vs OpenSim's loop)",
            "median marker RMS (mm)",
            "agreement with OpenSim",
        ],
        rows=rows,
        notes=notes,
        info=info,
    )
