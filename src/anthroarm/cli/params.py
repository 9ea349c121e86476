"""A book model's builder parameters as command-line options (``anthroarm urdf human_arm7
--height 1.62``, ``--param height=1.62``), listed by ``--help`` with units and defaults.

Loaded by :func:`anthroarm.cli.build_parser` (through its registry) only when a command that
takes a model names one: reading a builder's signature imports the catalog.
"""

from __future__ import annotations

import argparse
import inspect
import math

from .. import models
from .common import UserError
from .person import RANGES, SEXES, check_person_value


def model_params(model) -> list[tuple[str, object, str, str]] | None:
    """The builder parameters of a book model, ``[(name, default, kind, unit)]`` (kind: ``float``,
    ``pair`` (two numbers, e.g. a stroke), ``map`` (a dict of numbers, e.g. the person arm's
    ``segment_lengths``, given as ``KEY=VALUE,KEY=VALUE``) or ``str``); None for any other model.
    Units: :func:`anthroarm.models.param_unit` (lengths in m, mass in kg, angles in rad)."""
    if not isinstance(model, str) or model not in models.BOOK_MODELS:
        return None
    out = []
    for p in inspect.signature(models.BOOK_MODELS[model]).parameters.values():
        d = p.default
        ann = (
            p.annotation if isinstance(p.annotation, str) else getattr(p.annotation, "__name__", "")
        )
        kind = (
            "pair"
            if isinstance(d, tuple)
            else "str"
            if isinstance(d, str)
            else "map"
            if isinstance(d, dict) or ann.split("|")[0].strip() == "dict"
            else "float"
        )
        unit = "" if kind == "str" else models.param_unit(model, p.name)
        out.append((p.name, d, kind, unit))
    return out


def param_names(model) -> str:
    return ", ".join(f"--{n}" for n, *_ in model_params(model) or [])


def convert_param(model, name, kind, unit, text):
    """The builder value of ``--NAME TEXT`` / ``--param NAME=TEXT``."""
    if kind == "str":
        if name == "sex" and is_person_model(model) and text not in SEXES:
            raise UserError(f"--sex must be one of {', '.join(SEXES)} (for {model}), got {text!r}")
        return text
    if kind == "map":
        out = {}
        for item in str(text).split(","):
            k, _, v = item.partition("=")
            try:
                x = float(v)
            except ValueError:
                x = math.nan
            if not k.strip() or not math.isfinite(x) or k.strip() in out:
                raise UserError(
                    f"{model} parameter {name} expects comma-separated KEY=VALUE pairs, each value a "
                    f"finite number ({unit}) and each KEY once; got {text!r} "
                    f"(see 'anthroarm urdf {model} --help')"
                )
            out[k.strip()] = x
        return out
    want = "two numbers MIN,MAX" if kind == "pair" else "a number"
    try:
        vals = [float(x) for x in str(text).split(",")]
    except ValueError:
        vals = []
    if len(vals) != (2 if kind == "pair" else 1) or not all(math.isfinite(v) for v in vals):
        raise UserError(f"{model} parameter {name} expects {want} ({unit}), got {text!r}")
    if name in RANGES and kind == "float" and is_person_model(model):
        return check_person_value(name, vals[0])
    return tuple(vals) if kind == "pair" else vals[0]


def is_person_model(model) -> bool:
    """A catalog model built from a person's height, mass and sex (their ranges apply)."""
    return {"height", "mass", "sex"} <= {n for n, *_ in model_params(model) or []}


def add_model_param_options(p, model) -> None:
    """``--NAME VALUE`` for every builder parameter of a book model (shown by ``--help`` with its
    unit and default); an option the command already has stays reachable through --param."""
    params = model_params(model)
    if not params:
        return
    paragraph = " ".join((models.BOOK_MODELS[model].__doc__ or "").strip().split("\n\n")[0].split())
    first = paragraph.split(". ")[0].rstrip(".") + "." if paragraph else ""
    g = p.add_argument_group(
        f"parameters of {model}", f"{first} Also accepted as --param NAME=VALUE.".strip()
    )
    for name, default, kind, unit in params:
        shown = (
            ",".join(f"{x:g}" for x in default)
            if kind == "pair"
            else "none"
            if kind == "map" and default is None
            else default
        )
        metavar = (
            "MIN,MAX" if kind == "pair" else "KEY=VALUE,..." if kind == "map" else name.upper()
        )
        help_ = (
            f"{unit + ', ' if unit else ''}{'min,max, ' if kind == 'pair' else ''}"
            f"{'comma-separated KEY=VALUE pairs, ' if kind == 'map' else ''}default {shown}"
        )
        flags = [f"--{name}"]
        if kind == "map" and "_" in name:  # a dict parameter also as --segment-lengths
            flags.append(f"--{name.replace('_', '-')}")
        # an option string the command already has conflicts (argparse.ArgumentError): try
        # without the dashed spelling, then leave the parameter to --param
        extra = {}
        if name == "sex" and kind == "str" and is_person_model(model):
            extra = dict(choices=SEXES, metavar=None)
        elif name in RANGES and is_person_model(model):
            help_ = (
                f"body {name}, {unit} ({RANGES[name][0]:g}–{RANGES[name][1]:g}), default {shown}"
            )
        for given in (flags, flags[:1]):
            try:
                g.add_argument(
                    *given,
                    dest=f"model_param:{name}",
                    default=None,
                    **{"metavar": metavar, "help": help_, **extra},
                )
                break
            except argparse.ArgumentError:
                continue
    p.set_defaults(_model=model)


def unknown_options_message(model, extras) -> str:
    """For arguments no option takes on a command that takes ``model``: name its parameters (or
    say it has none)."""
    names = param_names(model)
    if names:
        return (
            f"unknown option(s) {' '.join(extras)} for {model}; its parameters: {names} "
            "(or --param NAME=VALUE)"
        )
    return (
        f"unrecognized arguments: {' '.join(extras)} ({model} has no builder parameters; "
        f"the book models have: {', '.join(models.book_names())})"
    )


def parse_params(items, model=None, a=None) -> dict:
    """Builder keyword arguments from ``--param KEY=VALUE`` items and, for a book model, its
    ``--NAME VALUE`` options (in ``a``); a book model's names are checked against its builder
    and the values converted to the builder's kinds."""
    params = {}
    for it in items:
        if "=" not in it:
            raise UserError(f"--param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        params[k.strip()] = v
    spec = model_params(model)
    if spec is None:  # not a book model: numbers as floats; load() rejects any parameter
        out = {}
        for k, v in params.items():
            try:
                out[k] = float(v)
            except ValueError:
                out[k] = v
        return out
    kinds = {n: (kind, unit) for n, _, kind, unit in spec}
    unknown = [k for k in params if k not in kinds]
    if unknown:
        raise UserError(
            f"unknown parameter {unknown[0]!r} of {model}; its parameters: "
            f"{', '.join(kinds)} (e.g. --param {spec[0][0]}=VALUE or --{spec[0][0]} VALUE)"
        )
    for n in kinds:
        v = getattr(a, f"model_param:{n}", None) if a is not None else None
        if v is not None:
            if n in params and params[n] != v:
                raise UserError(
                    f"{model} parameter {n} given twice (--{n} {v} and --param {n}={params[n]})"
                )
            params[n] = v
    return {k: convert_param(model, k, *kinds[k], v) for k, v in params.items()}
