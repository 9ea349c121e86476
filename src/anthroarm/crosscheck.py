"""The book-vs-Pinocchio cross-check: every closed form against an independent oracle.

:func:`run` collects :class:`CheckRow` s from the *providers* listed in :data:`PROVIDERS`.
A provider is a function ``rows(models, samples, rng) -> list[CheckRow]`` in some module; each
row compares one quantity of one model over ``samples`` random configurations inside the
limits and records the largest error seen.  ``anthroarm check`` prints the rows and exits
non-zero if any fails.

To add checks, write a provider next to the code it checks and append its dotted name
``"package.module:function"`` to :data:`PROVIDERS`.
"""

from __future__ import annotations

import importlib
import json
import math
from dataclasses import asdict, dataclass

import numpy as np

#: dotted names of row providers, run in this order
PROVIDERS: list[str] = [
    "anthroarm.kinematics.checks:rows",
    "anthroarm.design.structure:reach_rows",
    "anthroarm.dynamics.checks:rows",
    "anthroarm.spatial.checks:rows",
    "anthroarm.mechanisms.checks:rows",
    "anthroarm.ik.checks:rows",
    "anthroarm.ik.qp.checks:rows",
]


@dataclass
class CheckRow:
    """One line of the cross-check report.

    ``max_abs_err`` is the largest error seen (positions relative to the model's length scale
    when ``relative`` is set); ``ok`` is ``max_abs_err <= tol`` and finite."""

    model: str
    quantity: str
    max_abs_err: float
    tol: float
    samples: int
    oracle: str = "pinocchio"
    note: str = ""

    @property
    def ok(self) -> bool:
        return bool(math.isfinite(self.max_abs_err) and self.max_abs_err <= self.tol)

    def as_dict(self) -> dict:
        d = asdict(self)
        d["ok"] = self.ok
        return d


def _load_provider(dotted: str):
    mod, _, fn = dotted.partition(":")
    return getattr(importlib.import_module(mod), fn)


def run(models=None, samples: int = 200, seed: int = 0, providers=None, progress: bool = False) -> list[CheckRow]:
    """Run every provider; ``models`` restricts the model-specific rows to those names."""
    from . import models as catalog

    names = list(models) if models else catalog.names()
    for n in names:
        if n not in catalog.names():
            raise catalog._unknown(n)
    rows: list[CheckRow] = []
    provs = providers or PROVIDERS
    it = provs
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(provs, desc="cross-check", unit="provider", leave=False)
    for dotted in it:
        rng = np.random.default_rng(seed)
        rows.extend(_load_provider(dotted)(names, samples, rng))
    return rows


def format_table(rows: list[CheckRow]) -> str:
    """Plain-text table: model, quantity, max abs err, tol, samples, ok."""
    head = ("model", "quantity", "max_abs_err", "tol", "samples", "oracle", "ok")
    body = [
        (r.model, r.quantity, f"{r.max_abs_err:.3e}", f"{r.tol:.0e}", str(r.samples), r.oracle, "ok" if r.ok else "FAIL")
        for r in rows
    ]
    widths = [max(len(h), *(len(b[i]) for b in body)) if body else len(h) for i, h in enumerate(head)]
    fmt = "  ".join(f"{{:<{w}}}" for w in widths)
    lines = [fmt.format(*head), fmt.format(*("-" * w for w in widths))]
    lines += [fmt.format(*b) for b in body]
    n_bad = sum(not r.ok for r in rows)
    lines.append(f"{len(rows) - n_bad} passed, {n_bad} failed")
    return "\n".join(lines)


def to_json(rows: list[CheckRow]) -> str:
    return json.dumps([r.as_dict() for r in rows], indent=1)
