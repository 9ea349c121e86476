"""First calls per model with an empty cache: every catalog model and ur5, xarm7, kinova.

One fresh Python process per model, with a new ``ANTHROARM_CACHE`` and ``NUMBA_CACHE_DIR`` and
the default mode (``ANTHROARM_JIT=auto``: the reference path answers while one background
process compiles).  In that process, one after the other, the first call of each public entry
point the model takes: ``aa.ik.analytic`` on one pose and ``aa.ik.analytic_batch`` on 100 (arms
with a closed form; a swivel angle for an SRS arm, the held joint at 0 for a 7-joint arm),
``aa.ik.solve`` on one pose, ``robot.fk(Q)`` and ``robot.jacobian(Q)`` on 1000 configurations,
one ``aa.ik.qp.step`` and ``aa.dynamics.lagrange.load(robot).tau``.  Wall time around each call
only; the import of anthroarm and the model's load are timed apart.  Every answer is checked in
the process (a pose reached by FK, finite arrays): a first call that answers wrongly is an error,
not a time.  The background compilation is stopped when the process ends, so models do not load
each other.  Target (issue 28): ≤ 1 s median, ≤ 2 s worst, per entry point over the models.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from statistics import median

from .bench_cold_start import fresh_process

EXTRA = ("ur5", "xarm7", "kinova")

SCRIPT = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import anthroarm as aa
from anthroarm.ik import qp
from anthroarm.ik.closed_form import closed_form_info, held_joint
out = {"import": time.perf_counter() - t0}
t = time.perf_counter()
r = aa.load(sys.argv[1])
out["load"] = time.perf_counter() - t

def timed(label, fn):
    t = time.perf_counter()
    got = fn()
    out[label] = time.perf_counter() - t
    return got

q = r.random_q(rng=3)
form = closed_form_info(r)
k = held_joint(r) if form is not None else None
if k is not None and r.nq == len(r.chain.independent):
    q[k] = 0.0
T = r.fk(q)
if form is not None:
    kw = {"swivel": 0.3} if form.swivel else {"param": 0.0} if k is not None else {}
    timed("analytic", lambda: aa.ik.analytic(r, T, **kw))
    Qb = r.random_q(100, rng=4)
    if k is not None and r.nq == len(r.chain.independent):
        Qb[:, k] = 0.0
    Tb = r.fk(Qb)
    kwb = {key: np.full(100, v) if key == "param" else v for key, v in kw.items()}
    res = timed("analytic_batch", lambda: aa.ik.analytic_batch(r, Tb, **kwb))
    assert np.all(np.isfinite(res.solutions[res.valid]))
sol = timed("solve", lambda: aa.ik.solve(r, T))
assert sol.success and np.allclose(r.fk(sol.q), T, atol=1e-5), sol
Q = r.random_q(1000, rng=5)
fk, jac = timed("fk+jacobian batch", lambda: (r.fk(Q), r.jacobian(Q)))
assert np.all(np.isfinite(fk)) and np.all(np.isfinite(jac))
conf = qp.IKConfiguration(r)
ee = qp.FrameTask(r, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
ee.set_target(T)
v = timed("qp.step", lambda: qp.step(conf, None, [ee], dt=0.01))
assert np.all(np.isfinite(v))
z = np.zeros(r.nv)
tau = timed("lagrange", lambda: aa.dynamics.lagrange.load(r).tau(q, z, z))
assert np.all(np.isfinite(tau))
from anthroarm import jit
out["jit"] = jit.status()
print("RESULT" + json.dumps(out))
"""

ENTRIES = ["analytic", "analytic_batch", "solve", "fk+jacobian batch", "qp.step", "lagrange"]


def run(quick: bool = False) -> dict:
    import anthroarm as aa

    models = [*aa.models.names(), *(m for m in EXTRA if m not in aa.models.names())]
    if quick:
        models = models[:3]
    rows, cols = [], {e: [] for e in ENTRIES}
    with tempfile.TemporaryDirectory() as tmp:
        for m in models:
            got = fresh_process(SCRIPT, m, Path(tmp) / m, "auto")
            for e in ENTRIES:
                if e in got:
                    cols[e].append(got[e])
            rows.append(
                [
                    m,
                    *(got.get(e, "") for e in ENTRIES),
                    got["import"],
                    got["load"],
                    got["jit"].split(" (")[0],
                ]  # fmt: skip
            )
    for label, f in (("median", median), ("worst", max)):
        rows.append([label, *(f(cols[e]) if cols[e] else "" for e in ENTRIES), "", "", ""])
    return dict(
        title="First call of each entry point per model, empty cache (fresh process per model)",
        columns=["model", *(f"{e} s" for e in ENTRIES), "import s", "load s", "ran"],
        rows=rows,
        notes=(
            "One fresh process per model with a new ANTHROARM_CACHE and NUMBA_CACHE_DIR, the "
            "default mode (auto: the reference path answers while one background process "
            "compiles); the entry points called one after the other in that process, each its "
            "first call there; wall time around the call only. analytic: one pose (swivel 0.3 "
            "rad for an SRS arm, the held joint at 0 for a 7-joint arm); analytic_batch: 100 "
            "poses; solve: one pose (its answer checked by FK to 1e-5); fk+jacobian batch: "
            "1000 configurations; qp.step: one step of a FrameTask; lagrange: load + one tau. "
            "Blank: the model has no closed form. Target: <= 1 s median, <= 2 s worst. Shared "
            "2-core machine: read times ±30 %."
        ),
    )
