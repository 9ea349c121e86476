"""An orthogonal manipulator in vector-loop form, book §6-4, Eqs. (6-48)/(6-50): the data of
the rotation-tensor method (constant vectors, joint axes, grip and attitude vectors), validated.

The method itself — the nested pose (6-59), the matrix product (6-60) and the arm as a
:class:`~anthroarm.models.spec.ChainSpec` — is :mod:`anthroarm.kinematics.vector_loop`, which
re-exports :class:`VectorLoop` and the ground axes ``I, J, K``; the book's two arms in this form
are in :mod:`anthroarm.models.templates`.  The ground frame, m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

I, J, K = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def _vec3(v, what: str, unit: bool = False) -> np.ndarray:
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{what} must be 3 finite numbers, got {v!r}") from None
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ParameterError(f"{what} must be 3 finite numbers, got {v!r}")
    if unit:
        n = np.linalg.norm(a)
        if abs(n - 1.0) > 1e-9:
            raise ParameterError(f"{what} must be a unit vector, got {v!r} (norm {n:.6g})")
    return a


@dataclass(frozen=True)
class VectorLoop:
    """An orthogonal manipulator in vector-loop form (see the module docstring)."""

    items: tuple
    G: np.ndarray
    a0: tuple = I
    b0: tuple = K
    name: str = "vector_loop"

    def __post_init__(self):
        items = []
        for n, it in enumerate(self.items):
            try:
                kind, v = it
            except (TypeError, ValueError):
                raise ParameterError(f"loop item {n} must be (kind, vector), got {it!r}") from None
            if kind not in ("C", "R", "L"):
                raise ParameterError(f"loop item {n}: kind must be 'C', 'R' or 'L', got {kind!r}")
            items.append((kind, _vec3(v, f"loop item {n} ({kind})", unit=kind != "C")))
        object.__setattr__(self, "items", tuple(items))
        object.__setattr__(self, "G", _vec3(self.G, "G"))
        object.__setattr__(self, "a0", _vec3(self.a0, "a0", unit=True))
        object.__setattr__(self, "b0", _vec3(self.b0, "b0", unit=True))

    @property
    def joints(self) -> tuple:
        """The joint items ("R" or "L", axis), base to tip."""
        return tuple(it for it in self.items if it[0] != "C")

    @property
    def nq(self) -> int:
        return len(self.joints)


__all__ = ["I", "J", "K", "VectorLoop"]
