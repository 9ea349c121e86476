"""The one default person of the command line: body height, mass and sex, their defaults,
choices and ranges, for every command that builds a person's arm (``size``, ``ik-markers``,
``demo``, and ``view``/``teach``/``urdf``/``ik``... of a person model through its ``--height``,
``--mass``, ``--sex`` parameters).

Light (standard library only): the parsers read it.  The values are those of the catalog's
person models (:func:`anthroarm.models.human.segment_parameters`: de Leva 1996 tables, 0.5–2.6
m, 10–300 kg); tests/cli/test_cli_person.py checks that they agree.  A value outside its range
is refused with its unit and the remedy (``--height 175`` is centimetres: "give metres").
"""

from __future__ import annotations

import math

from .common import UserError

#: The default person (the catalog builders' defaults).
PERSON = {"height": 1.75, "mass": 75.0, "sex": "male"}

#: The sexes of the de Leva (1996) segment tables.
SEXES = ("male", "female")

#: name -> (low, high, unit, what to give, the unit a wrong value is likely in)
RANGES = {
    "height": (0.5, 2.6, "m", "metres, e.g. 1.75", "cm"),
    "mass": (10.0, 300.0, "kg", "kilograms, e.g. 75", "g or lb"),
}


def range_text(name: str) -> str:
    lo, hi, unit, *_ = RANGES[name]
    return f"{lo:g}–{hi:g} {unit}"


def check_person_value(name: str, value, flag: str | None = None) -> float:
    """``value`` of ``height`` or ``mass`` as a float inside its range, else a one-line
    :class:`~anthroarm.cli.common.UserError` with the unit and the remedy."""
    lo, hi, unit, give, _ = RANGES[name]
    flag = flag or f"--{name}"
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise UserError(f"{flag} expects a number ({unit}), got {value!r}") from None
    if not (math.isfinite(v) and lo <= v <= hi):
        raise UserError(f"{flag} {value:g} is outside {range_text(name)}: give {give}")
    return v


def person_help(name: str) -> str:
    return f"body {name}, {RANGES[name][2]} ({range_text(name)}; default {PERSON[name]:g})"


def add_person_options(p, given_only: bool = False) -> None:
    """``--height`` (m), ``--mass`` (kg) and ``--sex`` with the one default person.
    ``given_only``: None unless given (a command whose model may be no person: the person
    model's builder then uses the same defaults)."""
    d = {k: None if given_only else v for k, v in PERSON.items()}
    p.add_argument(
        "--height", type=float, default=d["height"], metavar="M", help=person_help("height")
    )
    p.add_argument("--mass", type=float, default=d["mass"], metavar="KG", help=person_help("mass"))
    p.add_argument(
        "--sex",
        default=d["sex"],
        choices=SEXES,
        help=f"body segment tables (de Leva 1996; default {PERSON['sex']})",
    )


def check_person(a) -> dict:
    """``dict(height, mass, sex)`` of a parsed command line with :func:`add_person_options`,
    each checked (a value not given is left out)."""
    out = {k: getattr(a, k) for k in PERSON if getattr(a, k) is not None}
    for k in RANGES:
        if k in out:
            out[k] = check_person_value(k, out[k])
    return out
