"""Generated Lagrange dynamics (M, g, tau) vs a Python loop over Pinocchio; derivation time.

For each model: the symbolic derivation time (T, V -> M, C q̇, g, τ in the expression graph),
the code-generation time and, per quantity and batch size N, the time per configuration of
the generated numpy code, of the optional compiled C code, and of a Python loop calling
``pin.crba`` / ``pin.computeGeneralizedGravity`` / ``pin.rnea`` N times.  N = 1 is one call of
the single-state path.  Ratios > 1 mean ours is faster.
"""

from __future__ import annotations

import os
import tempfile
import time

import numpy as np

from .common import time_call

MODELS = ["planar2r", "prosthetic_arm", "human_arm7", "ur5", "panda"]


def run(quick: bool = False) -> dict:
    import pinocchio as pin

    import anthroarm as aa
    from anthroarm.dynamics import lagrange as L
    from anthroarm.dynamics.ccode import compiler

    os.environ.setdefault("ANTHROARM_CACHE", tempfile.mkdtemp(prefix="aa_bench_cache_"))
    models = MODELS[:2] + MODELS[-1:] if quick else MODELS
    sizes = [1, 100] if quick else [1, 100, 10_000]
    have_c = compiler() is not None
    rows = []
    derive_rows = []
    for name in models:
        robot = aa.load(name)
        m, d = robot.model, robot.data
        t0 = time.perf_counter()
        der = L.derive(robot)
        t_der = time.perf_counter() - t0
        t0 = time.perf_counter()
        L.generate_python(der)
        t_gen = time.perf_counter() - t0
        nodes = len(der.graph.ops)
        dyn = L.load(robot)
        t_c = float("nan")
        dync = None
        if have_c:
            t0 = time.perf_counter()
            dync = L.load(robot, backend="c")
            t_c = time.perf_counter() - t0
        derive_rows.append((name, t_der, t_gen, t_c, nodes))
        rng = np.random.default_rng(0)
        for N in sizes:
            Q = robot.random_q(N, rng)
            V = rng.standard_normal((N, robot.nv))
            A = rng.standard_normal((N, robot.nv))
            reps = 3 if N >= 10_000 else 5
            cases = {
                "M": (
                    lambda dd, Q=Q: dd.mass_matrix(Q if N > 1 else Q[0]),
                    lambda Q=Q: [pin.crba(m, d, q) for q in Q],
                ),
                "g": (
                    lambda dd, Q=Q: dd.gravity(Q if N > 1 else Q[0]),
                    lambda Q=Q: [pin.computeGeneralizedGravity(m, d, q) for q in Q],
                ),
                "tau": (
                    lambda dd, Q=Q, V=V, A=A: (
                        dd.tau(Q, V, A) if N > 1 else dd.tau(Q[0], V[0], A[0])
                    ),
                    lambda Q=Q, V=V, A=A: [pin.rnea(m, d, q, v, a) for q, v, a in zip(Q, V, A)],
                ),
            }
            for qty, (ours, theirs) in cases.items():
                mt = 0.2 if N == 1 else 0.0
                t_np = time_call(lambda: ours(dyn), repeat=reps, min_time=mt) / N
                t_cc = (
                    time_call(lambda: ours(dync), repeat=reps, min_time=mt) / N
                    if dync
                    else float("nan")
                )
                t_pin = time_call(theirs, repeat=reps, min_time=mt) / N
                rows.append(
                    [name, qty, N, t_np * 1e6, t_cc * 1e6, t_pin * 1e6, t_pin / t_np, t_pin / t_cc]
                )
    for name, t_der, t_gen, t_c, nodes in derive_rows:
        rows.append(
            [
                name,
                "derive / generate py / compile C [s]",
                nodes,
                t_der,
                t_gen,
                t_c,
                float("nan"),
                float("nan"),
            ]
        )
    return dict(
        title="Generated Lagrange dynamics vs Pinocchio (time per configuration)",
        columns=[
            "model",
            "quantity",
            "N (nodes for derive rows)",
            "numpy µs/config",
            "C µs/config",
            "pin loop µs/config",
            "pin/numpy",
            "pin/C",
        ],
        rows=rows,
        notes=(
            "Time per configuration; N = 1 is a single call (scalar Python path for numpy, ctypes for C), "
            "N > 1 one batched call vs a Python loop of N Pinocchio calls. The last rows give, per model, "
            "the symbolic derivation time, the Python code generation time and the C compile time (s; "
            "the C time is the first call in a fresh cache) and the number of expression-graph nodes."
        ),
    )
