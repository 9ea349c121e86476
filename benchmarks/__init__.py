"""anthroarm benchmark suite: one module per capability (``bench_<name>.py``), one runner.

Run ``python -m benchmarks [NAME ...] [--quick]`` from the repository root, or
``anthroarm bench [NAME]``.  Each benchmark runs ours and the peer side by side in one process
and writes ``benchmarks/results/<name>.json`` and ``<name>.md``.
"""
