"""``anthroarm check``: the run (the parser: :mod:`.check`)."""

from __future__ import annotations

import sys

from .. import crosscheck
from .common import MAX_SAMPLES, UserError, parse_locked


def run(a) -> int:
    if not 1 <= a.samples <= MAX_SAMPLES:
        raise UserError(f"--samples must be in 1..{MAX_SAMPLES}, got {a.samples}")
    names = [n for item in [*a.model, *(a.models or [])] for n in item.split(",") if n]
    if (a.tool is not None or a.locked is not None) and not names:
        raise UserError(
            "--tool and --locked apply to the models given: name one (e.g. anthroarm check ur10 --tool tool0)"
        )
    rows = crosscheck.run(
        names or None,
        samples=a.samples,
        seed=a.seed,
        progress=not a.json and sys.stderr.isatty(),
        tool=a.tool,
        locked=parse_locked(a.locked),
    )
    print(crosscheck.to_json(rows) if a.json else crosscheck.format_table(rows))
    return 0 if all(r.ok for r in rows) else 1
