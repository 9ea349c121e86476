"""anthroarm benchmark suite: one module per capability (``bench_<name>.py``), one runner.

Run ``python -m benchmarks [NAME ...] [--quick]`` from the repository root, or
``anthroarm bench [NAME]``.  Each benchmark runs ours and the peer side by side in one process
and writes ``benchmarks/results/<name>.json`` and ``<name>.md``.
"""

import os

# Warm speed is measured on compiled kernels: compiled on first use in this process (Numba's own
# behaviour; each benchmark's warm-up call pays it), never the reference path that a process in
# the default mode answers from while its background compilation runs (anthroarm.jit).  A run
# with ANTHROARM_JIT set keeps it; bench_cold_start sets the mode of each of its processes.
os.environ.setdefault("ANTHROARM_JIT", "compile")
