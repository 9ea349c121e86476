"""``anthroarm models``: the run (the parser: :mod:`.models`)."""

from __future__ import annotations

import json

from .. import models
from ..errors import AmbiguousToolError, AnthroarmError
from ..loading import load


def describe(name, source: str, description: str = "") -> dict:
    """One entry of ``anthroarm models``: nq, nv, joint kinds and tool of a robot loaded by
    name, or what it needs (tool=, with its tips) or why it does not load."""
    out = {
        "name": name,
        "source": source,
        "description": description,
        "nq": None,
        "nv": None,
        "kinds": {},
        "tool": None,
        "tips": [],
        "needs_tool": False,
        "error": None,
    }
    try:
        try:
            r = load(name)
        except AmbiguousToolError:
            out["needs_tool"] = True
            r = load(
                name, tool="universe"
            )  # the base frame: every model has it; only to count and list tips
        out.update(
            nq=r.nq,
            nv=r.nv,
            kinds={k: n for k, n in r.chain.kind_counts().items() if n},
            tool=None if out["needs_tool"] else r.tool,
            tips=list(r.tips),
            description=description or r.description,
        )
    except AnthroarmError as exc:
        out["error"] = " ".join(str(exc).split())
    return out


def _kinds_text(kinds: dict) -> str:
    return " + ".join(f"{n} {k}" for k, n in kinds.items()) or "no joints"


def run(a) -> int:
    out = []
    for n in models.names():
        if n in models.BOOK_MODELS:
            s = models.spec(n)
            out.append(describe(n, s.source or "book", s.description))
        else:
            arm = models.ERD_ARMS[n]
            out.append(describe(n, f"example-robot-data {arm.subpath}", arm.description))
    if a.all:
        out += [
            describe(n, "example-robot-data") for n in models.erd_names() if n not in models.names()
        ]
    if a.json:
        print(json.dumps(out, indent=1))
        return 0
    w = max(len(o["name"]) for o in out)
    wk = max(len(_kinds_text(o["kinds"])) for o in out)
    catalog = set(models.names())
    for i, o in enumerate(out):
        if i == len(catalog):
            print("\nexample-robot-data (anthroarm.load(NAME); a tree needs tool=):")
        if o["error"] is not None:
            print(f"{o['name']:<{w}}  not loadable: {o['error']}")
            continue
        head = f"{o['name']:<{w}}  nq={o['nq']:<3} nv={o['nv']:<3} {_kinds_text(o['kinds']):<{wk}}"
        if o["needs_tool"]:
            print(f"{head}  needs tool=, one of: {', '.join(o['tips'])}")
        else:
            print(f"{head}  {o['description'] if o['name'] in catalog else 'tool ' + o['tool']}")
    return 0
