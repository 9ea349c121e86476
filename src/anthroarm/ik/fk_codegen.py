"""Straight-line forward kinematics generated from ``robot.chain``, used to verify closed-form
IK candidates quickly and independently of the IK formulas.

The chain product of the path from the base to a frame (the joint placements, axes and the
frame's placement read from :class:`~anthroarm.chain.Chain`, the same model Pinocchio holds;
for the book's DH arms it is Eq. (6-14))

    T_0,frame(q) = O_1 Rot(a_1, q_1) O_2 Rot(a_2, q_2) … O_n Rot(a_n, q_n) O_frame

is built once per chain and frame in the project's one expression graph
(:mod:`anthroarm.codegen.graph`: hash-consed, constants folded, products with 0 and ±1
skipped) and printed by its emitter three times: with ``math`` (scalar floats, the single-pose
path), with ``numpy`` (arrays, the batched path) and as C (the compiled kernel of
:mod:`.analytic_c`).

The code is split into *stages* (consecutive joint groups).  IK branches form a tree — e.g. the
6R arm's 8 solutions share θ1 in fours and (θ2, θ3) in pairs — so the scalar path evaluates a
stage once per distinct prefix, and the numpy path gets the same sharing for free by
broadcasting (a stage's joint arrays carry one more branch axis of size > 1).

``FKStages.scalar[k](state, q...)`` returns the new state (the non-constant rotation and
position entries, a tuple); the last stage instead returns the FK residual
``max |FK(q) − T|`` over the 3×4 pose entries (or the position only) against the target entries
``T = (T00, T01, …, T23)`` (row-major, units m for the position).  Revolute and prismatic
joints about any axis; continuous and mimic joints raise ``NotImplementedError``.
"""

from __future__ import annotations

import math

import numpy as np

from ..codegen.graph import Graph, Node, snap, straight_line

#: the 12 entries of the 3×4 target pose, row-major
_T_NAMES = ["T00", "T01", "T02", "T03", "T10", "T11", "T12", "T13", "T20", "T21", "T22", "T23"]


def _inname(inp) -> str:
    if inp.kind == "T":
        return _T_NAMES[inp.k]
    return inp.name          # c{j}, s{j} (cos, sin of revolute joint j), q{j} (prismatic)


def _negated(g: Graph, v):
    """x if the node v is −x, else None."""
    if isinstance(v, Node):
        op = g.ops[v.i]
        if op[0] == "mul" and op[1] == -1.0:
            return Node(g, op[2])
    return None


def chain_product(chain, frame=None, bounds=None, position_only=False):
    """The symbolic chain product of the path to ``frame`` in a new :class:`Graph`.

    Returns ``(g, state, diffs)``: ``state[k]`` the non-constant entries of (R, p) after stage
    k (for the stage boundaries ``bounds``: joint positions along the path), ``diffs`` the 12
    (or 3) values ±(FK entry − T entry) of the last stage, of magnitude |FK − T|."""
    path = chain.path(frame)
    for i in path:
        j = chain.joints[i]
        if j.is_mimic or j.kind == "continuous":
            raise NotImplementedError(f"{chain.name}: joint {j.name!r} ({'mimic' if j.is_mimic else j.kind}): "
                                      "the generated FK takes revolute and prismatic joints only")
    bounds = bounds or [0, len(path)]
    g = Graph()
    states = []
    R, p = _product(g, chain, frame, path, bounds, states)
    T = [g.input("T", k) for k in range(12)]
    vals = p + ([] if position_only else [v for row in R for v in row])
    idx = [3, 7, 11, 0, 1, 2, 4, 5, 6, 8, 9, 10]
    diffs = []
    for v, k in zip(vals, idx):
        x = _negated(g, v)
        if x is not None:
            diffs.append(g.add(x, T[k]))              # −(−x − T) = x + T: the same magnitude
        else:
            diffs.append(g.add(v, g.mul(-1.0, T[k])))
    return g, states, diffs


def frame_product(chain, frame=None):
    """The pose of ``frame`` and the joints' frames along its path, in a new :class:`Graph`:
    ``(g, R, p, joints)`` with R (3 × 3 nested lists) and p (3,) the frame's rotation and
    position in the base frame, and ``joints[k]`` = (R_k, p_k) the frame of the k-th joint of
    ``chain.path(frame)`` after its placement (before its own motion: its axis in the base frame
    is R_k · axis, its origin p_k).  Inputs ``c{k}, s{k}`` (cos, sin of the k-th joint's angle)
    or ``q{k}`` (a prismatic joint's displacement), k the position along the path; a continuous
    joint is a revolute one here (its angle θ, not its (cos, sin) pair), a mimic joint reads its
    own angle θ_j = a θ_source + b (the caller supplies it)."""
    path = chain.path(frame)
    g = Graph()
    joints = []
    R, p = _product(g, chain, frame, path, [0, len(path)], [], joints)
    return g, R, p, joints


def _product(g, chain, frame, path, bounds, states, joints=None):
    """(R, p) of the chain product O_1 Rot(a_1, q_1) … O_n Rot(a_n, q_n) O_frame built in ``g``;
    appends the stage states to ``states`` and, if given, each joint's frame after its
    placement to ``joints``."""
    fr = chain.frame(frame)
    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    p = [0.0, 0.0, 0.0]

    def place(R, p, rot, tr):     # (R, p) ∘ (rot, tr), constant rot/tr
        rot = [[snap(x) for x in row] for row in np.asarray(rot, float)]
        tr = [snap(x) for x in np.asarray(tr, float)]
        p = [g.sum([p[i]] + [g.mul(tr[k], R[i][k]) for k in range(3)]) for i in range(3)]
        R = [[g.sum([g.mul(rot[k][c], R[i][k]) for k in range(3)]) for c in range(3)] for i in range(3)]
        return R, p

    for pos, i in enumerate(path):
        j = chain.joints[i]
        R, p = place(R, p, j.rotation, j.translation)
        if joints is not None:
            joints.append((R, p))
        ax = [snap(x) for x in j.axis]
        if j.kind == "prismatic":
            q = g.input("q", pos)
            p = [g.add(p[r], g.mul(q, g.sum([g.mul(ax[k], R[r][k]) for k in range(3)]))) for r in range(3)]
        else:
            c, s = g.input("c", pos), g.input("s", pos)
            k = int(np.argmax(np.abs(ax)))
            if abs(ax[k]) == 1.0 and sum(abs(x) for x in ax) == 1.0:
                sg = ax[k]
                a, b = [(1, 2), (2, 0), (0, 1)][k]   # a rotation about e_k mixes columns a, b
                Rn = [row[:] for row in R]
                for r in range(3):
                    Rn[r][a] = g.add(g.mul(R[r][a], c), g.mul(sg, g.mul(R[r][b], s)))
                    Rn[r][b] = g.add(g.mul(R[r][b], c), g.mul(-sg, g.mul(R[r][a], s)))
                R = Rn
            else:                                    # Rodrigues: I + s K + (1 − c) K²
                K = np.array([[0.0, -ax[2], ax[1]], [ax[2], 0.0, -ax[0]], [-ax[1], ax[0], 0.0]])
                K2 = K @ K
                omc = g.add(1.0, g.mul(-1.0, c))
                Rq = [[g.sum([float(r == cc), g.mul(snap(K[r, cc]), s), g.mul(snap(K2[r, cc]), omc)])
                       for cc in range(3)] for r in range(3)]
                R = [[g.sum([g.mul(R[r][k], Rq[k][cc]) for k in range(3)]) for cc in range(3)] for r in range(3)]
        if pos + 1 in bounds[1:-1]:
            states.append([v for row in R for v in row] + p)
    return place(R, p, fr.rotation, fr.translation)


class FKStages:
    """Generated FK of the path to ``frame`` of ``chain``, split into stages at the given
    joint indices (positions along the path).

    ``splits`` lists the first joint of each stage after the first, e.g. ``(1, 3)`` for the 6R
    arm: stage 0 = joint 0, stage 1 = joints 1–2, stage 2 = joints 3–5 (+ frame, residual).
    ``scalar`` / ``numpy``: the compiled Python stage functions; :meth:`c_source` the C text."""

    def __init__(self, chain, splits=(), position_only: bool = False, frame=None):
        n = len(chain.path(frame))
        bounds = [0, *splits, n]
        self.splits = tuple(splits)
        self.position_only = position_only
        self.n_stages = len(bounds) - 1
        g, states, diffs = chain_product(chain, frame, bounds, position_only)
        self.stages = _stages(g, states, diffs, bounds)
        self.source = _render_python(self.stages, vectorised=False)
        self.source_numpy = _render_python(self.stages, vectorised=True)
        self.scalar = self._compile(self.source, {"cos": math.cos, "sin": math.sin, "_abs": abs})
        self.numpy = self._compile(self.source_numpy, {"cos_sin": cos_sin, "_abs": np.abs, "_max": _np_max})

    def c_source(self, prefix: str) -> str:
        return _render_c(self.stages, prefix)

    def _compile(self, source, ns):
        ns = dict(ns)
        exec(compile(source, "<fk_codegen>", "exec"), ns)
        return [ns[f"stage{k}"] for k in range(self.n_stages)]


def _stages(g, states, diffs, bounds) -> list[dict]:
    """Per stage: its joints ``q``, the names it reads (``state_in``), its trig inputs, its
    statements for Python and C and either ``state_out`` (names) or the residual terms."""
    out = []
    known: dict[int, str] = {}
    for st in range(len(bounds) - 1):
        last = st == len(bounds) - 2
        if last:
            outs = diffs
        else:   # export x for an entry −x: the next stage negates inline
            outs = []
            for v in states[st]:
                if isinstance(v, Node):
                    x = _negated(g, v)
                    outs.append(x if x is not None else v)
        stage = {"q": [f"q{j}" for j in range(bounds[st], bounds[st + 1])],
                 "state_in": list(dict.fromkeys(known.values()))}
        for lang in ("py", "c"):
            stmts, ref = straight_line(g, outs, _inname, known=known, lang=lang, name_outputs=not last)
            stage[f"body_{lang}"] = stmts
            stage[f"out_{lang}"] = [ref(o) for o in outs]
        cone = g.cone(outs, stop=known)
        ins = [g.ops[i][1] for i in cone if g.ops[i][0] == "in" and i not in known]
        stage["trig"] = sorted({x.k for x in ins if x.kind in ("c", "s")})
        stage["used"] = {_inname(x) for x in ins} | {known[i] for i in cone if i in known}
        if not last:   # the next stage reads exactly this stage's exports, in this order
            known = {}
            for o, r in zip(outs, stage["out_py"]):
                known.setdefault(o.i, r)
            stage["state_out"] = list(known.values())
        out.append(stage)
    return out


def _render_python(stages, vectorised: bool) -> str:
    """Python source: ``stage{k}([st,] q..., [T])``; math or numpy names are bound at exec."""
    src = []
    for k, stg in enumerate(stages):
        last = "state_out" not in stg
        args = (["st"] if stg["state_in"] else []) + stg["q"] + (["T"] if last else [])
        lines = [f"def stage{k}({', '.join(args)}):"]
        if stg["state_in"]:
            lines.append(f"    {', '.join(stg['state_in'])}{',' if len(stg['state_in']) == 1 else ''} = st")
        if last:
            lines.append(f"    {', '.join(_T_NAMES)} = T")
        for j in stg["trig"]:
            if vectorised:
                lines.append(f"    c{j}, s{j} = cos_sin(q{j})")
            else:
                lines += [f"    c{j} = cos(q{j})", f"    s{j} = sin(q{j})"]
        lines += [f"    {n} = {e}" for n, e in stg["body_py"]]
        if last:
            d = stg["out_py"]
            if vectorised:
                lines.append(f"    return _max({', '.join(f'_abs({x})' for x in d)})")
            else:  # plain comparisons beat 12 abs() calls and a 12-argument max() in CPython
                lines.append(f"    r = _abs({d[0]})")
                for x in d[1:]:
                    lines += [f"    d = {x}", "    if d > r:", "        r = d", "    elif -d > r:", "        r = -d"]
                lines.append("    return r")
        else:
            so = stg["state_out"]
            lines.append(f"    return ({', '.join(so)}{',' if len(so) == 1 else ''})")
        src += lines + [""]
    return "\n".join(src) + "\n"


def _render_c(stages, prefix: str) -> str:
    """C99 source: ``void {prefix}{k}(const double *st, const double *q, double *out)`` for the
    inner stages (``out`` = new state), ``double {prefix}{last}(const double *st, const double *q,
    const double *T)`` (T = the 12 entries of the 3×4 pose, row-major) returning the residual."""
    src = []
    for k, stg in enumerate(stages):
        last = "state_out" not in stg
        head = (f"static double {prefix}{k}(const double *st, const double *q, const double *T)" if last else
                f"static void {prefix}{k}(const double *st, const double *q, double *out)")
        used = stg["used"]
        lines = [head + " {", "    (void)st; (void)q;"]
        lines += [f"    const double {n} = st[{i}];" for i, n in enumerate(stg["state_in"]) if n in used]
        lines += [f"    const double {n} = q[{i}];" for i, n in enumerate(stg["q"])
                  if n in used or int(n[1:]) in stg["trig"]]
        if last:
            lines += [f"    const double {n} = T[{i}];" for i, n in enumerate(_T_NAMES) if n in used]
        for j in stg["trig"]:
            lines.append(f"    const double c{j} = cos(q{j}), s{j} = sin(q{j});")  # gcc fuses to sincos
        lines += [f"    const double {n} = {e};" for n, e in stg["body_c"]]
        if last:
            d = stg["out_c"]
            lines.append(f"    double r = fabs({d[0]}), d;")
            for x in d[1:]:
                lines.append(f"    d = {x}; if (d > r) r = d; else if (-d > r) r = -d;")
            lines.append("    return r;")
        else:
            lines += [f"    out[{i}] = {n};" for i, n in enumerate(stg["state_out"])]
        src += lines + ["}", ""]
    return "\n".join(src) + "\n"


def cos_sin(q):
    """(cos q, sin q) of an array from t = tan(q/2): cos = (1 − t²)/(1 + t²), sin = 2t/(1 + t²).

    numpy's float64 tan is vectorised (≈ 1 ns per value here) while cos and sin are not (≈ 8 ns
    each); the identity is exact and the result agrees with np.cos/np.sin to a few ulp for any
    angle (near q = ±π, t is large and finite: cos → −1, sin = 2/t keeps its relative accuracy)."""
    t = np.tan(0.5 * q)
    t2 = t * t
    w = 1.0 / (1.0 + t2)
    return (1.0 - t2) * w, (2.0 * w) * t


def _np_max(*xs):
    """Elementwise maximum of broadcastable arrays (in place once the full shape is reached)."""
    out = np.maximum(xs[0], xs[1])
    for x in xs[2:]:
        if np.shape(x) == out.shape or np.broadcast_shapes(out.shape, np.shape(x)) == out.shape:
            np.maximum(out, x, out=out)
        else:
            out = np.maximum(out, x)
    return out
