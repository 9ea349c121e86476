"""``anthroarm batch``: the run (the parser: :mod:`.batch`)."""

from __future__ import annotations

import json

import numpy as np

from .. import batch
from .common import UserError, parse_locked
from .person import SEXES, check_person_value
from .runtime import load_model, parse_params, resolve_model


def _floats(text, what):
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise UserError(f"--{what} expects comma-separated numbers, got {text!r}") from None


def _sexes(text) -> list[str]:
    out = [s.strip() for s in text.split(",") if s.strip()]
    bad = [s for s in out if s not in SEXES]
    if bad or not out:
        raise UserError(f"--sexes takes comma-separated {' and '.join(SEXES)}, got {text!r}")
    return out


def run(a) -> int:
    resolve_model(a)
    if a.workers is not None and a.scheduler != "local":
        raise UserError(
            "--workers goes with --scheduler local (a running scheduler has its own workers)"
        )
    params = parse_params(a.param, a.model, a)
    kw = dict(progress=not a.no_progress, seed=a.seed)
    if a.chunk_size is not None:
        kw["chunk_size"] = a.chunk_size
    if a.n is not None:
        kw["n"] = a.n
    args = ()
    if a.job == "population":
        kw.update(
            model=a.model,
            heights=[
                check_person_value("height", h, "--heights") for h in _floats(a.heights, "heights")
            ],
            masses=[check_person_value("mass", m, "--masses") for m in _floats(a.masses, "masses")],
            sexes=_sexes(a.sexes),
            voxel=a.voxel,
        )
    else:
        robot = load_model(a.model, params, a.tool, parse_locked(a.locked))
        args = (robot,)
        if a.job in ("reach", "comfort"):
            kw["voxel"] = a.voxel
        elif a.job == "tolerance":
            args += (robot.random_q(a.configs, rng=a.seed, margin=0.05),)
            kw.update(sigma_q=a.sigma_q, sigma_L=a.sigma_l)
        elif a.job == "ik":
            n = kw.pop("n", 1000)
            args += (robot.fk(robot.random_q(n, rng=a.seed, margin=0.05)),)  # reachable targets
        elif a.job == "cells":
            kw.pop("seed")
            kw.pop("n", None)
            kw["D"] = a.D
    res = batch.run_job(
        a.job,
        *args,
        out=a.out,
        plot=a.plot,
        scheduler=a.scheduler,
        workers=a.workers,
        timeout=a.timeout,
        **kw,
    )
    summary = {"job": res.job, **{k: list(v.shape) for k, (_, v) in res.variables.items()}}
    for k in ("volume", "n", "outside"):
        if k in res.attrs:
            summary[k] = res.attrs[k]
    if a.job == "ik":
        summary["success_rate"] = float(np.mean(res["success"]))
    if a.job == "population":
        summary["volume_m3"] = [round(float(v), 6) for v in res["volume"].ravel()]
    if a.out:
        summary["out"] = a.out
    print(json.dumps(summary))
    return 0
