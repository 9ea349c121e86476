"""Structural analysis of biomimetic mechanisms, book Ch. 2 (§2-1 … §2-3).

* the kinematic-pair catalog of Table 2.1 (pair class = number of constraints k = 6 − f);
* a mechanism graph (links, pairs, independent loops) and the spatial mobility formula
  Eq. (2-1) ``F = 6n − Σ_{k=1..5} k·p_k`` (the OCR prints the upper limit as ``s``);
* the human upper-limb graph of Fig. 2-2 (F = 27, :func:`upper_limb_mechanism`) and its finger
  sub-graph (F = 20);
* the arm-layout count Eq. (2-2) ``N = m^n`` and the enumeration of §2-3 that leaves the
  book's four forms (Fig. 2-3);
* the reach of the R-P-R-P-R-P arm, Eq. (2-3) and Eq. (2-4), checked on every catalog arm
  whose spec declares the arm of Fig. 2-6 (``spec.reach``).

Lengths are in metres (any consistent unit works: the formulas are homogeneous), angles in rad.
"""

from __future__ import annotations

import itertools
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from .. import models as catalog
from ..check_rows import CheckRow
from ..models import hand as hand_model
from ..robot import load

ROMAN = {1: "I", 2: "II", 3: "III", 4: "IV", 5: "V"}


@dataclass(frozen=True)
class KinematicPair:
    """One kind of kinematic pair (运动副).

    ``dof`` is the relative freedom f (0 < f < 6); ``constraints`` = 6 − f is the pair's
    class k in the book's numbering (class I = 1 constraint … class V = 5 constraints)."""

    name: str
    symbol: str
    dof: int

    def __post_init__(self):
        if not (isinstance(self.dof, (int, np.integer)) and 0 < self.dof < 6):
            raise ValueError(
                f"pair {self.symbol!r}: dof must be an integer in 1..5, got {self.dof!r}"
            )

    @property
    def constraints(self) -> int:
        return 6 - int(self.dof)

    @property
    def pair_class(self) -> int:
        """Class k of Eq. (2-1): the number of constraints."""
        return self.constraints

    @property
    def class_name(self) -> str:
        return ROMAN[self.pair_class] + "级"


#: Table 2.1 (l. 464–472), verbatim: revolute, prismatic, spherical, cylindrical, helical.
TABLE_2_1: tuple[KinematicPair, ...] = (
    KinematicPair("revolute", "R", 1),
    KinematicPair("prismatic", "P", 1),
    KinematicPair("spherical", "S", 3),
    KinematicPair("cylindrical", "C", 2),
    KinematicPair("helical", "H", 1),
)

#: Every pair the toolkit knows: Table 2.1 plus the pairs Fig. 2-2 uses without a symbol —
#: the IV-class pair "with two relative rotations" (universal/Hooke, ``U``), the II-class pair
#: between ulna and radius (4 DOF, ``II``) and a planar pair (3 DOF, class III, ``E``).
PAIRS: dict[str, KinematicPair] = {p.symbol: p for p in TABLE_2_1}
PAIRS.update(
    {
        "U": KinematicPair("universal (two rotations, IV级)", "U", 2),
        "II": KinematicPair("class-II pair (4 DOF)", "II", 4),
        "E": KinematicPair("planar", "E", 3),
    }
)


def pair(symbol: str | KinematicPair) -> KinematicPair:
    """Look a pair up by symbol (``"R"``, ``"S"``, ``"U"``, ``"II"`` …)."""
    if isinstance(symbol, KinematicPair):
        return symbol
    try:
        return PAIRS[symbol]
    except KeyError:
        raise ValueError(f"unknown kinematic pair {symbol!r}; known: {sorted(PAIRS)}") from None


def spatial_mobility(n: int, pair_counts, local_dof: int = 0, redundant: int = 0) -> int:
    """Spatial mobility, Eq. (2-1): ``F = 6n − Σ_{k=1}^{5} k·p_k``.

    ``n`` moving links; ``pair_counts`` either a mapping ``{k: p_k}`` (k = class = constraints)
    or a sequence ``(p_1, …, p_5)``.  The book warns (§2-1) that local DOF (局部自由度, e.g.
    the spin of an S–S rod) must be subtracted and redundant constraints (虚约束) added back:
    ``local_dof`` and ``redundant`` do that."""
    if int(n) != n or n < 0:
        raise ValueError(f"n (moving links) must be a non-negative integer, got {n!r}")
    if isinstance(pair_counts, dict):
        items = pair_counts.items()
    else:
        pc = list(pair_counts)
        if len(pc) != 5:
            raise ValueError(f"pair_counts must list p_1..p_5 (5 numbers), got {len(pc)}")
        items = zip(range(1, 6), pc)
    total = 0
    for k, p in items:
        if k not in ROMAN:
            raise ValueError(f"pair class must be 1..5, got {k!r}")
        if int(p) != p or p < 0:
            raise ValueError(f"p_{k} must be a non-negative integer, got {p!r}")
        total += int(k) * int(p)
    return 6 * int(n) - total - int(local_dof) + int(redundant)


def planar_mobility(n: int, lower_pairs: int, higher_pairs: int = 0) -> int:
    """Planar Grübler count ``F = 3n − 2p_l − p_h`` (the book cites it only in words, §2-3:
    the 1-DOF planar six-bar finger of Fig. 2-8)."""
    for name, v in (("n", n), ("lower_pairs", lower_pairs), ("higher_pairs", higher_pairs)):
        if int(v) != v or v < 0:
            raise ValueError(f"{name} must be a non-negative integer, got {v!r}")
    return 3 * int(n) - 2 * int(lower_pairs) - int(higher_pairs)


@dataclass
class Joint:
    name: str
    pair: KinematicPair
    a: str
    b: str


@dataclass
class Mechanism:
    """A mechanism graph: links are nodes (``ground`` is the frame 机架), pairs are edges.

    ``mobility()`` applies Eq. (2-1); ``loops`` is the number of independent closed loops
    ``p − n`` of a connected graph (0 for an open chain)."""

    name: str
    ground: str = "ground"
    links: list[str] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    local_dof: int = 0

    def __post_init__(self):
        if self.ground not in self.links:
            self.links.insert(0, self.ground)

    def add_link(self, *names: str) -> "Mechanism":
        for nm in names:
            if nm in self.links:
                raise ValueError(f"{self.name}: link {nm!r} already exists")
            self.links.append(nm)
        return self

    def add_joint(self, name: str, kind, a: str, b: str) -> "Mechanism":
        for end in (a, b):
            if end not in self.links:
                raise ValueError(
                    f"{self.name}: joint {name!r} names unknown link {end!r}; links: {self.links}"
                )
        if a == b:
            raise ValueError(f"{self.name}: joint {name!r} joins link {a!r} to itself")
        if any(j.name == name for j in self.joints):
            raise ValueError(f"{self.name}: joint {name!r} already exists")
        self.joints.append(Joint(name, pair(kind), a, b))
        return self

    @property
    def n_moving(self) -> int:
        return len(self.links) - 1

    def pair_counts(self) -> dict[int, int]:
        """``{k: p_k}`` for k = 1..5 (class = number of constraints)."""
        c = Counter(j.pair.pair_class for j in self.joints)
        return {k: c.get(k, 0) for k in range(1, 6)}

    def is_connected(self) -> bool:
        adj = {ln: set() for ln in self.links}
        for j in self.joints:
            adj[j.a].add(j.b)
            adj[j.b].add(j.a)
        seen, stack = {self.ground}, [self.ground]
        while stack:
            for nb in adj[stack.pop()] - seen:
                seen.add(nb)
                stack.append(nb)
        return len(seen) == len(self.links)

    @property
    def loops(self) -> int:
        """Independent loops of the connected graph: ``p − n`` (edges − nodes + 1)."""
        if not self.is_connected():
            raise ValueError(f"{self.name}: the link graph is not connected")
        return len(self.joints) - self.n_moving

    def mobility(self) -> int:
        """Eq. (2-1) with this graph's counts, minus declared local DOF."""
        if not self.is_connected():
            raise ValueError(f"{self.name}: the link graph is not connected; mobility is undefined")
        return spatial_mobility(self.n_moving, self.pair_counts(), local_dof=self.local_dof)


FINGERS = ("thumb", "index", "middle", "ring", "little")


def human_fingers() -> Mechanism:
    """The finger part of Fig. 2-2 (l. 548–550): the palm is the frame, 15 phalanx links,
    5 IV-class base pairs (MP for fingers 2–5, CM for the thumb) and 10 revolute (V) pairs:
    n = 15, p_IV = 5, p_V = 10, F = 90 − 70 = 20."""
    m = Mechanism("human fingers (Fig. 2-2)", ground="palm")
    for f in FINGERS:
        m.add_link(f"{f}_1", f"{f}_2", f"{f}_3")
        m.add_joint(f"{f}_base", "U", "palm", f"{f}_1")
        m.add_joint(f"{f}_j2", "R", f"{f}_1", f"{f}_2")
        m.add_joint(f"{f}_j3", "R", f"{f}_2", f"{f}_3")
    return m


def upper_limb_mechanism() -> Mechanism:
    """Human upper-limb mechanism of Fig. 2-2 (l. 540–546), trunk as the frame (the book's
    graph; the catalog's 27-joint limb ``human_upper_limb`` has its own graph,
    :func:`mechanism_of`).

    Links: 1 humerus, 2 ulna, 3 radius, 4 palm, 5–19 phalanges (n = 19).  Pairs: shoulder S,
    humerus–ulna R (elbow flexion), humerus–radius S, ulna–radius class II, wrist (palm–radius)
    one IV-class pair, five IV-class finger bases, ten R between phalanges:
    p = (0, 1, 2, 6, 11) so F = 114 − 87 = 27, with one closed loop (humerus–ulna–radius)."""
    m = Mechanism("human upper limb (Fig. 2-2)", ground="trunk")
    m.add_link("humerus", "ulna", "radius", "palm")
    m.add_joint("shoulder", "S", "trunk", "humerus")
    m.add_joint("humero_ulnar", "R", "humerus", "ulna")
    m.add_joint("humero_radial", "S", "humerus", "radius")
    m.add_joint("radio_ulnar", "II", "ulna", "radius")
    m.add_joint("wrist", "U", "radius", "palm")
    fingers = human_fingers()
    for ln in fingers.links[1:]:
        m.add_link(ln)
    for j in fingers.joints:
        m.add_joint(j.name, j.pair, j.a, j.b)
    return m


def mechanism_of(spec):
    """The mechanism graph (:class:`Mechanism`) of a catalog model's tree spec (a
    :class:`~anthroarm.models.spec.ChainSpec`, e.g. ``aa.models.spec("human_upper_limb")``): joints
    whose child link is a zero-length connector (a base pair's middle link) are merged with the
    joint that follows at the same point into one pair with 2 (``U``, IV级) or 3 (``S``, III级)
    rotations; other revolute joints are ``R`` pairs.  Mimic joints count as the pair they are
    (a coupling is not a pair: subtract it from Eq. (2-1) yourself).  Links are the spec's
    links that are not connectors; the ground is ``spec.base_link``."""
    joints = list(spec.joints)
    # serial predecessor of every joint's parent (a joint with parent=None hangs on the previous
    # link)
    parents, prev = [], spec.base_link
    for j in joints:
        p = j.parent if j.parent is not None else prev
        parents.append(p)
        prev = j.link.name
    children = {}
    for p in parents:
        children[p] = children.get(p, 0) + 1

    def connector(link):
        return (
            link.mass <= hand_model.VIRTUAL_MASS * 1.0001
            or link.segment is None
            or np.linalg.norm(link.segment) < 1e-12
        ) and children.get(link.name, 0) == 1

    merged_into = {}  # connector link -> the link the group started from
    m = Mechanism(spec.name, ground=spec.base_link)
    groups = []  # (start link, end link, n rotations)
    for j, p in zip(joints, parents):
        start = merged_into.get(p, p)
        if p in merged_into:
            # extend the open group ending at p
            for g in groups:
                if g[1] == p:
                    g[1], g[2] = j.link.name, g[2] + 1
                    break
        else:
            groups.append([start, j.link.name, 1])
        zero_origin_next = True
        if connector(j.link):
            nxt = [k for k, pp in zip(joints, parents) if pp == j.link.name]
            zero_origin_next = bool(nxt) and np.allclose(nxt[0].origin[:3, 3], 0.0)
        if connector(j.link) and zero_origin_next:
            merged_into[j.link.name] = start
    kind = {1: "R", 2: "U", 3: "S"}
    for start, end, n in groups:
        for ln in (start, end):
            if ln not in m.links:
                m.add_link(ln)
        m.add_joint(f"{start}->{end}", kind[n], start, end)
    return m


def rrss_mechanism() -> Mechanism:
    """The thumb's RRSS spatial four-bar (Fig. 2-9): 3 moving links, pairs R, R, S, S.
    Eq. (2-1) gives 2; one is the local spin of the S–S rod (局部自由度), so F = 1."""
    m = Mechanism("RRSS", ground="frame", local_dof=1)
    m.add_link("R1", "R2", "rod")
    m.add_joint("u0", "R", "frame", "R1")
    m.add_joint("u2", "R", "R1", "R2")
    m.add_joint("b", "S", "R2", "rod")
    m.add_joint("b0", "S", "rod", "frame")
    return m


# ---------------------------------------------------------------- arm layouts, §2-3


def count_layouts(m: int, n: int) -> int:
    """Eq. (2-2): permutations with repetition ``N = m^n`` (m pair types, n positions)."""
    if int(m) != m or int(n) != n or m < 1 or n < 0:
        raise ValueError(f"m >= 1 and n >= 0 must be integers, got m={m!r}, n={n!r}")
    return int(m) ** int(n)


#: The four forms of Fig. 2-3 (l. 586) in the book's order (a)–(d); (a) is chosen (Fig. 2-4).
#: "R" = roll (回转型) about the link axis, "P" = pitch/swing (摆动型) — NOT prismatic.
BOOK_ARM_FORMS = ("R-P-R-P-R-P", "R-P-P-R-P-R", "R-P-R-P-P-R", "P-R-P-R-P-R")


def enumerate_arm_layouts(
    n: int = 6, types: str = "RP", n_R: int | None = 3, forbid: tuple[str, ...] = ("RR",)
) -> list[str]:
    """All ``len(types)**n`` joint sequences (Eq. (2-2)), filtered as in §2-3 (l. 579–587):
    exactly ``n_R`` roll joints and no forbidden adjacent pair (default: no R–R).  Pass
    ``n_R=None, forbid=()`` to get all 64.  Returned as ``"R-P-…"`` strings, sorted."""
    if not types or len(set(types)) != len(types):
        raise ValueError(f"types must be distinct single letters, got {types!r}")
    out = []
    for seq in itertools.product(types, repeat=int(n)):
        s = "".join(seq)
        if n_R is not None and s.count("R") != n_R:
            continue
        if any(f in s for f in forbid):
            continue
        out.append("-".join(seq))
    return sorted(out)


# ---------------------------------------------------------------- reach, (2-3) (2-4)


def _link_lengths(l1, l2, l3):
    ls = tuple(np.asarray(v, dtype=float) for v in (l1, l2, l3))
    if not all(np.all(v > 0) and np.all(np.isfinite(v)) for v in ls):  # NaN fails v > 0
        raise ValueError(
            f"link lengths l1, l2, l3 must be positive and finite, got {l1!r}, {l2!r}, {l3!r}"
        )
    return ls


def reach_max(l1, l2, l3):
    """Eq. (2-3): ``R_max = l1 + l2 + l3`` (arm stretched)."""
    l1, l2, l3 = _link_lengths(l1, l2, l3)
    return l1 + l2 + l3


def reach_min(l1, l2, l3, theta3):
    """Eq. (2-4): shoulder-to-hand distance with both distal swing joints bent by the same
    angle ``theta3`` (rad) in one plane (Fig. 2-6; the book's θ3 is this bend angle, not
    Table 2.2's θ3).  Built as in the book: ``m² = l2² + l3² + 2 l2 l3 cos θ3``,
    ``β = π − θ3 − α``, ``R_min² = l1² + m² − 2 l1 m cos β``.

    Corrected (docs/errata.md, Ch. 2–4): the book writes ``α = asin(l3 sin θ3 / m)``, which
    picks the acute angle and is wrong whenever the angle between m and l2 is obtuse
    (``l2 + l3 cos θ3 < 0``, e.g. a short forearm and a strong bend).  We use
    ``α = atan2(l3 sin θ3, l2 + l3 cos θ3)``, equal to the printed form elsewhere.
    Broadcasts over arrays."""
    l1, l2, l3 = _link_lengths(l1, l2, l3)
    t = np.asarray(theta3, dtype=float)
    if np.any(~np.isfinite(t)):
        raise ValueError("theta3 contains NaN/inf")
    m2 = l2**2 + l3**2 + 2 * l2 * l3 * np.cos(t)
    m = np.sqrt(np.maximum(m2, 0.0))
    alpha = np.arctan2(l3 * np.sin(t), l2 + l3 * np.cos(t))
    # R² = l1² + m² − 2 l1 m cos β with β = π − θ3 − α, i.e. + 2 l1 m cos(θ3 + α)
    r2 = l1**2 + m2 + 2 * l1 * m * np.cos(t + alpha)
    return np.sqrt(np.maximum(r2, 0.0))


def reach_min_fk(l1, l2, l3, theta3):
    """Independent form of (2-4) by planar forward kinematics:
    ``|l1 + l2 e^{iθ} + l3 e^{2iθ}|``."""
    t = np.asarray(theta3, dtype=float)
    return np.abs(l1 + l2 * np.exp(1j * t) + l3 * np.exp(2j * t))


def bent_q(reach, nq: int, theta3, q_shoulder=None) -> np.ndarray:
    """Joint vector of the (2-4) posture of an arm whose spec declares ``reach``
    (:class:`~anthroarm.models.spec.ReachPosture`): both swing joints ``reach.bend`` at
    ``theta3`` (rad), the shoulder joints (those before ``reach.bend[0]``) at ``q_shoulder``
    (default 0), every other joint 0.  Shape (nq,) for a scalar ``theta3``, else (N, nq)."""
    i, k = reach.bend
    t = np.atleast_1d(np.asarray(theta3, dtype=float))
    q = np.zeros((t.size, int(nq)))
    if q_shoulder is not None:
        q[:, :i] = np.asarray(q_shoulder, dtype=float)
    q[:, i] = t
    q[:, k] = t
    return q if np.ndim(theta3) else q[0]


def reach_rows(models, samples, rng):
    """Cross-check provider: Eq. (2-3)/(2-4) against Pinocchio FK of every catalog model among
    ``models`` whose spec declares the arm of Fig. 2-6 (``spec.reach``)."""
    rows = []
    for name in models:
        if name not in catalog.BOOK_MODELS:
            continue
        reach = catalog.spec(name).reach
        if reach is None:
            continue
        robot = load(name)
        L1, L2, L3 = reach.lengths
        n = max(int(samples), 1)
        i, k = reach.bend
        hi = min(robot.upper[i], robot.upper[k], np.deg2rad(90.0))  # inside both joints' ranges
        th = rng.uniform(0.0, hi, n)
        q = bent_q(reach, robot.nq, th)
        for j in range(i):
            q[:, j] = rng.uniform(robot.lower[j], robot.upper[j], n)
        d = np.linalg.norm(robot.fk(q)[:, :3, 3], axis=1)
        err_min = float(np.max(np.abs(d - reach_min(L1, L2, L3, th))))
        d0 = np.linalg.norm(robot.fk(np.zeros(robot.nq))[:3, 3])
        err_max = abs(float(d0 - reach_max(L1, L2, L3)))
        rows += [
            CheckRow(name, "reach R_min (2-4) vs |fk|", err_min, 1e-9, n),
            CheckRow(name, "reach R_max (2-3) vs |fk(0)|", err_max, 1e-9, 1),
        ]
    return rows
