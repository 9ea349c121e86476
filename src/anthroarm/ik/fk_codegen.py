"""Straight-line forward-kinematics code generated from a :class:`~anthroarm.models.spec.ChainSpec`,
used to verify closed-form IK candidates quickly and independently of the IK formulas.

The chain product of the catalog spec (the same joint table the URDF and Pinocchio's model are
built from; for the DH arms it is the book's Eq. (6-14))

    T_0,tool(q) = O_1 Rot(a_1, q_1) O_2 Rot(a_2, q_2) … O_n Rot(a_n, q_n) O_tool

is expanded symbolically once per spec: every rotation/position entry becomes one Python
statement, products with constant placements skip their zero and ±1 entries and fold constants.
The same source text is compiled twice, with ``math`` (scalar floats, the single-pose path) and
with ``numpy`` (arrays, the batched path).

The code is split into *stages* (consecutive joint groups).  IK branches form a tree — e.g. the
6R arm's 8 solutions share θ1 in fours and (θ2, θ3) in pairs — so the scalar path evaluates a
stage once per distinct prefix, and the numpy path gets the same sharing for free by
broadcasting (a stage's joint arrays carry one more branch axis of size > 1).

``FKStages.stages[k](state, q...)`` returns the new state (the non-constant rotation and
position entries, a tuple); the last stage instead returns the FK residual
``max |FK(q) − T|`` over the 3×4 pose entries (or the position only) against the target entries
``T00, T01, …, T23`` (row-major, units m for the position).  Only joints whose axis is ±x, ±y or
±z of their frame are expanded (every book arm); other chains raise ``NotImplementedError``.
"""

from __future__ import annotations

import math
import re

import numpy as np

_EPS = 1e-15


def _clean(x: float) -> float:
    """Snap a constant within 1e-15 of 0 or ±1 (cos 90° = 6e-17) so products skip it."""
    x = float(x)
    for v in (0.0, 1.0, -1.0):
        if abs(x - v) < _EPS:
            return v
    return x


class _Emitter:
    """Builds statements (name, expression); a value is a Python float (constant) or a variable
    name (str), possibly lazily negated ("-name")."""

    def __init__(self, start: int = 0):
        self.body: list[tuple] = []
        self.n = start

    def combo(self, terms) -> float | str:
        """Σ coef · Π factors as one statement; terms: list of (coef, [factors])."""
        const = 0.0
        parts = []
        for coef, factors in terms:
            k = float(coef)
            names = []
            for f in factors:
                if isinstance(f, str):
                    if f.startswith("-"):  # a lazily negated variable
                        k, f = -k, f[1:]
                    names.append(f)
                else:
                    k *= f
            if k == 0.0:
                continue
            if not names:
                const += k
                continue
            body = "*".join(names)
            if abs(k) != 1.0:
                body = f"{abs(k)!r}*{body}"
            parts.append(("+" if k > 0 else "-", body))
        if not parts:
            return _clean(const)
        if len(parts) == 1 and const == 0.0 and "*" not in parts[0][1]:
            # a single variable: no statement (negation stays symbolic: "-name")
            return parts[0][1] if parts[0][0] == "+" else "-" + parts[0][1]
        expr = ("-" if parts[0][0] == "-" else "") + parts[0][1]
        for sign, body in parts[1:]:
            expr += f" {sign} {body}"
        if const != 0.0:
            expr += f" + {const!r}" if const > 0 else f" - {-const!r}"
        name = f"t{self.n}"
        self.n += 1
        self.body.append(("assign", name, expr))
        return name


def _mat_const(em, R, C):
    """R @ C for a constant 3×3 C."""
    return [[em.combo([(C[k][j], [R[i][k]]) for k in range(3)]) for j in range(3)] for i in range(3)]


def _chain_stages(spec, bounds, position_only) -> list[dict]:
    """The symbolic chain product, stage by stage: for each stage its joints ``q`` (names), the
    incoming state names ``state_in``, the statements ``body`` (("assign", name, expr) or
    ("trig", j, q)), and either ``state_out`` (names) or, on the last stage, ``diffs``: the
    12 (or 3, position only) expressions ±(FK entry − T entry)."""
    R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    p = [0.0, 0.0, 0.0]
    stages = []
    state_in: list[str] = []
    for st in range(len(bounds) - 1):
        em = _Emitter(1000 * st)  # unique temporaries across stages
        for j in range(bounds[st], bounds[st + 1]):
            jt = spec.joints[j]
            O = [[_clean(x) for x in row] for row in np.asarray(jt.origin, float)[:3, :3]]
            po = [_clean(x) for x in np.asarray(jt.origin, float)[:3, 3]]
            p = [em.combo([(1.0, [p[i]])] + [(po[k], [R[i][k]]) for k in range(3)]) for i in range(3)]
            R = _mat_const(em, R, O)
            ax = np.asarray(jt.axis, float)
            ax = ax / np.linalg.norm(ax)
            k = int(np.argmax(np.abs(ax)))
            if abs(abs(ax[k]) - 1.0) > 1e-12:
                raise NotImplementedError(f"joint {jt.name}: axis {tuple(ax)} is not ±x/±y/±z")
            sg = 1.0 if ax[k] > 0 else -1.0
            q = f"q{j}"
            if jt.type == "prismatic":
                p = [em.combo([(1.0, [p[i]]), (sg, [R[i][k], q])]) for i in range(3)]
                continue
            em.body.append(("trig", j, q))
            c, s = f"c{j}", f"s{j}"
            a, b = [(1, 2), (2, 0), (0, 1)][k]  # rotation about e_k mixes columns a, b
            Rn = [row[:] for row in R]
            for i in range(3):
                Rn[i][a] = em.combo([(1.0, [R[i][a], c]), (sg, [R[i][b], s])])
                Rn[i][b] = em.combo([(1.0, [R[i][b], c]), (-sg, [R[i][a], s])])
            R = Rn
        stage = {"q": [f"q{j}" for j in range(bounds[st], bounds[st + 1])], "state_in": state_in,
                 "body": em.body}
        if st == len(bounds) - 2:
            tp = [_clean(x) for x in np.asarray(spec.tool_origin, float)[:3, 3]]
            tR = [[_clean(x) for x in row] for row in np.asarray(spec.tool_origin, float)[:3, :3]]
            p = [em.combo([(1.0, [p[i]])] + [(tp[k], [R[i][k]]) for k in range(3)]) for i in range(3)]
            diffs = [_diff(p[i], f"T{i}3") for i in range(3)]
            if not position_only:
                R = _mat_const(em, R, tR)
                diffs += [_diff(R[i][j], f"T{i}{j}") for i in range(3) for j in range(3)]
            stage["diffs"] = diffs
        else:
            state_out = []
            for v in [v for row in R for v in row] + p:
                if isinstance(v, str) and v.lstrip("-") not in state_out:
                    state_out.append(v.lstrip("-"))
            stage["state_out"] = state_out
            state_in = state_out  # names stay the same across the boundary
        _drop_dead(stage)
        stages.append(stage)
    return stages


_IDENT = re.compile(r"[A-Za-z_]\w*")


def _drop_dead(stage: dict) -> None:
    """Remove statements whose results are not used (e.g. the rotation in a position-only check)."""
    needed = set()
    for x in stage.get("diffs", ()) or stage.get("state_out", ()):
        needed.update(_IDENT.findall(x))
    keep = []
    for item in reversed(stage["body"]):
        if item[0] == "trig":
            j = item[1]
            if f"c{j}" in needed or f"s{j}" in needed:
                keep.append(item)
                needed.add(item[2])
        elif item[1] in needed:
            keep.append(item)
            needed.update(_IDENT.findall(item[2]))
    stage["body"] = keep[::-1]


_T_NAMES = ["T00", "T01", "T02", "T03", "T10", "T11", "T12", "T13", "T20", "T21", "T22", "T23"]


def _render_python(stages, vectorised: bool) -> str:
    """Python source: ``stage{k}([st,] q..., [T])``; math or numpy names are bound at exec."""
    src = []
    for k, stg in enumerate(stages):
        args = (["st"] if stg["state_in"] else []) + stg["q"] + (["T"] if "diffs" in stg else [])
        lines = [f"def stage{k}({', '.join(args)}):"]
        if stg["state_in"]:
            lines.append(f"    {', '.join(stg['state_in'])}{',' if len(stg['state_in']) == 1 else ''} = st")
        if "diffs" in stg:
            lines.append(f"    {', '.join(_T_NAMES)} = T")
        for item in stg["body"]:
            if item[0] == "trig":
                j, q = item[1], item[2]
                if vectorised:
                    lines.append(f"    c{j}, s{j} = cos_sin({q})")
                else:
                    lines += [f"    c{j} = cos({q})", f"    s{j} = sin({q})"]
            else:
                lines.append(f"    {item[1]} = {item[2]}")
        if "diffs" in stg:
            d = stg["diffs"]
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
        last = "diffs" in stg
        head = (f"static double {prefix}{k}(const double *st, const double *q, const double *T)" if last else
                f"static void {prefix}{k}(const double *st, const double *q, double *out)")
        used = set()
        for item in stg["body"]:
            used.update(_IDENT.findall(item[2]))
        for x in stg.get("diffs", ()) or stg.get("state_out", ()):
            used.update(_IDENT.findall(x))
        lines = [head + " {", "    (void)st; (void)q;"]
        lines += [f"    const double {n} = st[{i}];" for i, n in enumerate(stg["state_in"]) if n in used]
        lines += [f"    const double {n} = q[{i}];" for i, n in enumerate(stg["q"]) if n in used]
        if last:
            lines += [f"    const double {n} = T[{i}];" for i, n in enumerate(_T_NAMES) if n in used]
        for item in stg["body"]:
            if item[0] == "trig":
                j, q = item[1], item[2]
                lines.append(f"    const double c{j} = cos({q}), s{j} = sin({q});")  # gcc fuses to sincos
            else:
                lines.append(f"    const double {item[1]} = {item[2]};")
        if last:
            d = stg["diffs"]
            lines.append(f"    double r = fabs({d[0]}), d;")
            for x in d[1:]:
                lines.append(f"    d = {x}; if (d > r) r = d; else if (-d > r) r = -d;")
            lines.append("    return r;")
        else:
            lines += [f"    out[{i}] = {n};" for i, n in enumerate(stg["state_out"])]
        src += lines + ["}", ""]
    return "\n".join(src) + "\n"


class FKStages:
    """Generated FK of one spec, split into stages at the given joint indices.

    ``splits`` lists the first joint of each stage after the first, e.g. ``(1, 3)`` for the 6R
    arm: stage 0 = joint 0, stage 1 = joints 1–2, stage 2 = joints 3–5 (+ tool, residual).
    ``scalar`` / ``numpy``: the compiled Python stage functions; :meth:`c_source` the C text."""

    def __init__(self, spec, splits, position_only: bool = False):
        bounds = [0, *splits, len(spec.joints)]
        self.splits = tuple(splits)
        self.position_only = position_only
        self.n_stages = len(bounds) - 1
        self.stages = _chain_stages(spec, bounds, position_only)
        self.state_sizes = [len(s.get("state_out", ())) for s in self.stages]
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


def _diff(v, t: str) -> str:
    """±(v − t) as source text (a lazily negated v = "-x" gives x + t, of the same magnitude)."""
    if isinstance(v, str):
        return f"{v[1:]} + {t}" if v.startswith("-") else f"{v} - {t}"
    return f"{v!r} - {t}"


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
