"""One row of a cross-check report (:class:`CheckRow`): what every ``checks`` module of the
algorithms returns and :mod:`anthroarm.crosscheck` collects.  In the foundation layer so that
an algorithm's checks never import the application that runs them."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

#: the status (and note prefix) of a row whose check cannot run on a model
UNSUPPORTED = "unsupported"


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

    @classmethod
    def unsupported(cls, model: str, quantity: str, reason: str) -> "CheckRow":
        """A row for a check that cannot run on ``model``: it compares nothing and does not pass."""
        return cls(
            model, quantity, math.nan, 0.0, 0, "-", f"{UNSUPPORTED}: {' '.join(reason.split())}"
        )

    @property
    def ok(self) -> bool:
        return bool(math.isfinite(self.max_abs_err) and self.max_abs_err <= self.tol)

    @property
    def status(self) -> str:
        """ "ok", "FAIL" or "unsupported"."""
        if self.ok:
            return "ok"
        return UNSUPPORTED if self.note.startswith(UNSUPPORTED + ":") else "FAIL"

    def as_dict(self) -> dict:
        d = asdict(self)
        d["ok"] = self.ok
        d["status"] = self.status
        return d


__all__ = ["UNSUPPORTED", "CheckRow"]
