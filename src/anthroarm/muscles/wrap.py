"""Muscle paths over wrap surfaces (filled in below)."""

from __future__ import annotations

from ..errors import MuscleError


def wrapped_length(xs, dxs, objs, muscle):
    raise MuscleError(f"muscle {muscle.name!r}: wrapping is not evaluated yet; pass wrap=False")
