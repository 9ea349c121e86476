"""What :func:`anthroarm.ik.closed_form.analytic` returns: every closed-form solution of one pose
(:class:`AnalyticIKResult`) or of N poses on B fixed branches (:class:`AnalyticBatchResult`).

Solutions are joint configurations q (rad; a tree's whole configuration), each inside the joint
limits and verified by forward kinematics (``residuals``: max |FK(q) − T| over the 3×4 pose
entries, m / unitless).  Whether a solution lies at a singular configuration is computed on
first use: the normalised Jacobian volume |det J| / Π‖J_k‖ of the solution
(:func:`anthroarm.ik.geometric.jacobian_volumes`) against
:data:`anthroarm.ik.geometric.SINGULAR_TOL`, put in words by :func:`singular_text`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, fields

import numpy as np

from .. import geometric as _geo


@dataclass(slots=True)  # slots: made on every single-pose call, a sixth of whose Python time it was
class AnalyticIKResult:
    """Every closed-form solution of one pose.

    ``solutions`` (K, nq) rad, each inside the joint limits and verified by FK;
    ``branches`` K labels; ``reason`` is None when K > 0, else why there is none;
    ``swivel`` (K,) the swivel angle of each solution (human_arm7 only, else None);
    ``residuals`` (K,) the FK check: max |FK(q) − T| over the 3×4 pose entries (m / unitless);
    :attr:`singular` says whether the solutions lie at a singular configuration."""

    solutions: np.ndarray
    branches: list
    reason: str | None = None
    swivel: np.ndarray | None = None
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: the text of :attr:`singular`, or a function of :attr:`solutions` that makes it on first use
    #: (or of the solutions it was made for: a batch row's, the arm's of a tree)
    _singular: object = field(default=None, repr=False, compare=False)
    model: str = ""

    @property
    def singular(self) -> str | None:
        """None, or what makes the pose singular: a solution whose 6×6 Jacobian has a normalised
        volume |det J| / Π‖J_k‖ ≤ :data:`.geometric.SINGULAR_TOL` (aligned wrist axes, a stretched
        elbow, the wrist centre on the first axis) — there solutions coincide in pairs or form a
        one-parameter family, of which one member is returned per branch.  Computed on first
        use (arms solved by their geometry; None for the swivel and planar families)."""
        if callable(self._singular):
            self._singular = self._singular(self.solutions)
        return self._singular

    def __getstate__(self):
        """Pickled with :attr:`singular` evaluated (its lazy maker is a closure)."""
        state = {f.name: getattr(self, f.name) for f in fields(self)}
        state["_singular"] = self.singular
        return state

    def __setstate__(self, state):
        for name, value in state.items():
            setattr(self, name, value)

    @property
    def success(self) -> bool:
        return len(self.branches) > 0

    def __len__(self) -> int:
        return len(self.branches)

    def as_dict(self) -> dict:
        return {
            "model": self.model,
            "solutions": self.solutions.tolist(),
            "branches": list(self.branches),
            "reason": self.reason,
            "swivel": None if self.swivel is None else self.swivel.tolist(),
            "residuals": self.residuals.tolist(),
            "singular": self.singular,
        }


@dataclass
class AnalyticBatchResult:
    """Closed-form solutions of N poses, on B fixed branches.

    ``solutions`` (N, B, nq): entry [i, b] is a verified solution inside the limits where
    ``valid[i, b]``; elsewhere it is NaN (there is no solution on that branch — read ``valid``).
    ``branches`` the B labels, ``reasons`` N entries (None where some branch is valid),
    ``swivel`` (N, B) for human_arm7, :attr:`singular` N entries.  ``result[i]`` gives pose i
    as an AnalyticIKResult.  ``solutions``, ``valid`` and ``residuals`` are read-only: a record
    of what the call found, which :attr:`singular` reads when it is first asked for (copy
    them to edit; ``result[i]`` holds copies)."""

    solutions: np.ndarray
    valid: np.ndarray
    branches: list
    reasons: list
    swivel: np.ndarray | None = None
    residuals: np.ndarray | None = None
    #: a function of the pose indices (a list) giving their :attr:`AnalyticIKResult.singular`
    #: texts, called on first use; None: never singular (the swivel and planar families)
    _singular_of: object = field(default=None, repr=False, compare=False)
    model: str = ""

    def __post_init__(self):
        for a in (self.solutions, self.valid, self.residuals):  # what `singular` reads later
            if a is not None:
                a.flags.writeable = False

    @functools.cached_property
    def singular(self) -> list:
        """:attr:`AnalyticIKResult.singular` of every pose (N entries), computed on first use."""
        n = len(self)
        return [None] * n if self._singular_of is None else self._singular_of(list(range(n)))

    def __getstate__(self):
        """Pickled with :attr:`singular` evaluated (its lazy maker is a closure)."""
        self.singular  # noqa: B018 - evaluated into __dict__
        state = self.__dict__.copy()
        state["_singular_of"] = None
        return state

    def __len__(self) -> int:
        return self.solutions.shape[0]

    def __getitem__(self, i: int) -> AnalyticIKResult:
        v = self.valid[i]
        if self._singular_of is None or "singular" in self.__dict__:
            sing = self.singular[i]
        else:
            sing = functools.partial(pose_singular, self._singular_of, int(i))
        return AnalyticIKResult(
            solutions=self.solutions[i][v].copy(),
            branches=[b for b, ok in zip(self.branches, v) if ok],
            reason=self.reasons[i],
            swivel=None if self.swivel is None else self.swivel[i][v].copy(),
            residuals=np.zeros(int(v.sum()))
            if self.residuals is None
            else self.residuals[i][v].copy(),
            _singular=sing,
            model=self.model,
        )

    @property
    def n_solutions(self) -> np.ndarray:
        return self.valid.sum(axis=1)


def singular_from(make, solutions, _held) -> str | None:
    """:attr:`AnalyticIKResult.singular` by ``make`` (a :class:`_SingularOf`) from the
    ``solutions`` it was made for, not those the result holds (``_held``: a tree's result holds
    the robot's configurations, its arm's maker reads the arm's θ)."""
    return make(solutions)


def pose_singular(singular_of, i: int, _solutions) -> str | None:
    """:attr:`AnalyticIKResult.singular` of pose ``i`` of a batch, from the batch's maker
    ``singular_of`` (its solutions are those the batch holds)."""
    return singular_of([i])[0]


def singular_text(volume: float) -> str | None:
    """None, or what a normalised Jacobian volume ≤ :data:`.geometric.SINGULAR_TOL` of a
    solution (:func:`.geometric.jacobian_volumes`) means, in words."""
    if volume > _geo.SINGULAR_TOL:
        return None
    return (
        f"a singular configuration (normalised |det J| = {volume:.2g}: aligned wrist axes, a stretched "
        "elbow or the wrist centre on the first axis): solutions coincide in pairs or form a one-parameter "
        "family, one member is returned per branch"
    )
