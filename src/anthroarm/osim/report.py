"""The import report: what of an OpenSim model the Robot represents, and what it does not.

Every component of the ``.osim`` file gets a row: ``kept`` (represented exactly), ``approximated``
(represented, but not as OpenSim does) or ``dropped`` (not represented), and why.  The
report is ``robot.report``; ``anthroarm check model.osim`` prints it and ``strict=True``
turns any row that is not ``kept`` into :class:`~anthroarm.errors.OsimStrictError`.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

KEPT, APPROXIMATED, DROPPED = "kept", "approximated", "dropped"


@dataclass(frozen=True)
class ReportRow:
    """One component of the model: its path (``/forceset/bic_long``), OpenSim type, status
    (kept / approximated / dropped), why, and its line in the file."""

    component: str
    type: str
    status: str
    why: str
    line: int | None = None


def _short(component: str) -> str:
    """The last part of a component path that names it (``/bodyset/femur_r/attached_geometry``
    -> ``femur_r``)."""
    parts = [p for p in component.split("/") if p and p != "attached_geometry"]
    return parts[-1] if parts else component


class ImportReport:
    """The rows of an import (see the module docstring), with summaries."""

    def __init__(self, path: str, model: str):
        self.path = path
        self.model = model
        self.rows: list[ReportRow] = []

    def add(self, component: str, type_: str, status: str, why: str, line=None) -> None:
        self.rows.append(ReportRow(component, type_, status, why, line))

    def by_status(self, status: str) -> list[ReportRow]:
        return [r for r in self.rows if r.status == status]

    @property
    def kept(self) -> list[ReportRow]:
        return self.by_status(KEPT)

    @property
    def approximated(self) -> list[ReportRow]:
        return self.by_status(APPROXIMATED)

    @property
    def dropped(self) -> list[ReportRow]:
        return self.by_status(DROPPED)

    def summary(self, status: str | None = None) -> dict:
        """{(status, type): count}, or {type: count} of one status."""
        if status is not None:
            return dict(Counter(r.type for r in self.rows if r.status == status))
        return dict(Counter((r.status, r.type) for r in self.rows))

    def text(self, detail: bool = False) -> str:
        """A printable report: per status, the counts by type and the reason (every row when
        ``detail``)."""
        lines = [f"import report of {self.model} ({self.path})"]
        for status in (KEPT, APPROXIMATED, DROPPED):
            rows = self.by_status(status)
            lines.append(f"  {status}: {len(rows)}")
            groups: dict[tuple[str, str], list[ReportRow]] = {}
            for r in rows:
                groups.setdefault((r.type, r.why), []).append(r)
            for (t, why), rs in groups.items():
                names = ", ".join(_short(r.component) for r in rs[:6])
                more = f", ... ({len(rs)})" if len(rs) > 6 else ""
                lines.append(f"    {len(rs):4d} {t}: {why} [{names}{more}]")
                if detail:
                    for r in rs:
                        at = f" (line {r.line})" if r.line else ""
                        lines.append(f"         {r.component}{at}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"ImportReport({self.model!r}: kept {len(self.kept)}, approximated "
            f"{len(self.approximated)}, dropped {len(self.dropped)})"
        )
