"""Which catalog arm has a closed-form inverse kinematics, and with what: the one registry.

The IK modules (:mod:`anthroarm.ik.closed_form` and its fast paths) know *families* of closed
forms — a geometry and the book's procedure for it — and nothing about arms; this table says
which arm belongs to which family, which of its builder parameters (``ChainSpec.params``, SI)
the formulas read, and the facts about its branch tree the fast paths need.  An arm gains a
closed form by an entry here (and, for a new geometry, a family in ``ik/``).

Families (equations in :mod:`anthroarm.ik.closed_form`):

``spherical_wrist_6r``
    6R arm with a spherical wrist, Fig. 6-3, Eqs. (7-1)–(7-15) (8 branches).
``prosthetic_6r``
    the prosthetic arm of Fig. 7-2 / Table 7.1, Eqs. (7-17)–(7-31) (8 branches).
``planar_2r``
    two parallel hinges about x, Fig. 7-14 (2 branches; position only by default).
``srs_7r``
    redundant shoulder (3R) – elbow (R) – wrist (3R) arm of §6-3, parametrised by the elbow
    swivel angle (8 branches per swivel angle).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ClosedForm:
    """One arm's closed form.

    ``family``: the solver (see the module docstring); ``params``: the ``spec.params`` keys it
    reads (m); ``nq``: the joints it solves (all of them); ``splits``: where the branch tree
    fans out (first joint of each stage of the generated FK check after the first);
    ``branches``: candidates per pose (per swivel angle); ``position_only``: compare the
    position only by default; ``swivel``: redundant, one solution family per swivel angle;
    ``cost_us``: single-pose time of ``aa.ik.analytic`` in µs (compiled kernel,
    benchmarks/results/ik_analytic.md), a hint for callers choosing between solvers."""

    family: str
    params: tuple[str, ...]
    nq: int
    splits: tuple[int, ...]
    branches: int
    position_only: bool = False
    swivel: bool = False
    cost_us: float = 10.0


#: catalog name -> its closed form
REGISTRY: dict[str, ClosedForm] = {
    # one stage: the two elbow branches differ in both joints
    "planar2r": ClosedForm("planar_2r", ("l1", "l2"), 2, (), 2, position_only=True, cost_us=5.0),
    # q1–q4 (elbow × shoulder Euler branch) | q5–q7 (wrist Euler branch)
    "human_arm7": ClosedForm("srs_7r", ("l1", "l2", "l3"), 7, (4,), 8, swivel=True, cost_us=8.0),
}


#: catalog arms with a procedure of the book's own besides the general closed form
#: (``aa.ik.analytic(robot, T, method="book")``): the prosthetic arm's Cramer-rule solution
#: (7-17)–(7-31) that Table 7.2 prints (:func:`anthroarm.ik.closed_form.prosthetic_book_procedure`)
BOOK_PROCEDURES = ("prosthetic_arm",)


def names() -> tuple[str, ...]:
    """Catalog names of the arms with a closed form."""
    return tuple(REGISTRY)


def lookup(spec) -> ClosedForm | None:
    """The closed form of a catalog spec (:class:`~anthroarm.models.spec.ChainSpec`), or None."""
    if spec is None:
        return None
    form = REGISTRY.get(spec.name)
    if form is None or spec.nq != form.nq or any(k not in spec.params for k in form.params):
        return None
    return form
