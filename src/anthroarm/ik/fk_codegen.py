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
    """Builds statements; a value is a Python float (constant) or a variable name (str)."""

    def __init__(self):
        self.lines: list[str] = []
        self.n = 0

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
        self.lines.append(f"    {name} = {expr}")
        return name


def _mat_const(em, R, C):
    """R @ C for a constant 3×3 C."""
    return [[em.combo([(C[k][j], [R[i][k]]) for k in range(3)]) for j in range(3)] for i in range(3)]


class FKStages:
    """Generated FK of one spec, split into stages at the given joint indices.

    ``splits`` lists the first joint of each stage after the first, e.g. ``(1, 3)`` for the 6R
    arm: stage 0 = joint 0, stage 1 = joints 1–2, stage 2 = joints 3–5 (+ tool, residual)."""

    def __init__(self, spec, splits, position_only: bool = False):
        bounds = [0, *splits, len(spec.joints)]
        self.splits = tuple(splits)
        self.position_only = position_only
        self.n_stages = len(bounds) - 1
        self.source = self._generate(spec, bounds, position_only, "    c{j} = cos({q})\n    s{j} = sin({q})", False)
        self.source_numpy = self._generate(spec, bounds, position_only, "    c{j}, s{j} = cos_sin({q})", True)
        self.scalar = self._compile(self.source, {"cos": math.cos, "sin": math.sin, "_max": max, "_abs": abs})
        self.numpy = self._compile(self.source_numpy, {"cos_sin": cos_sin, "_abs": np.abs, "_max": _np_max})

    def _compile(self, source, ns):
        ns = dict(ns)
        exec(compile(source, "<fk_codegen>", "exec"), ns)
        return [ns[f"stage{k}"] for k in range(self.n_stages)]

    @staticmethod
    def _generate(spec, bounds, position_only, trig, vectorised) -> str:
        R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        p = [0.0, 0.0, 0.0]
        src = []
        state_in: list[str] = []
        for st in range(len(bounds) - 1):
            em = _Emitter()
            em.n = 1000 * st  # unique temporaries across stages
            qnames = [f"q{j}" for j in range(bounds[st], bounds[st + 1])]
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
                em.lines.append(trig.format(j=j, q=q))
                c, s = f"c{j}", f"s{j}"
                a, b = [(1, 2), (2, 0), (0, 1)][k]  # rotation about e_k mixes columns a, b
                Rn = [row[:] for row in R]
                for i in range(3):
                    Rn[i][a] = em.combo([(1.0, [R[i][a], c]), (sg, [R[i][b], s])])
                    Rn[i][b] = em.combo([(1.0, [R[i][b], c]), (-sg, [R[i][a], s])])
                R = Rn
            last = st == len(bounds) - 2
            if last:
                tp = [_clean(x) for x in np.asarray(spec.tool_origin, float)[:3, 3]]
                tR = [[_clean(x) for x in row] for row in np.asarray(spec.tool_origin, float)[:3, :3]]
                p = [em.combo([(1.0, [p[i]])] + [(tp[k], [R[i][k]]) for k in range(3)]) for i in range(3)]
                if not position_only:
                    R = _mat_const(em, R, tR)
            # function header: previous state + this stage's joints (+ the target on the last stage)
            args = []
            if state_in:
                args.append("st")
            args += qnames
            if last:
                args.append("T")
            head = [f"def stage{st}({', '.join(args)}):"]
            if state_in:
                head.append(f"    {', '.join(state_in)}{',' if len(state_in) == 1 else ''} = st")
            if last:
                head.append("    T00, T01, T02, T03, T10, T11, T12, T13, T20, T21, T22, T23 = T")
                diffs = [_diff(p[i], f"T{i}3") for i in range(3)]
                if not position_only:
                    diffs += [_diff(R[i][j], f"T{i}{j}") for i in range(3) for j in range(3)]
                if vectorised:
                    tail = [f"    return _max({', '.join(f'_abs({d})' for d in diffs)})"]
                else:  # plain comparisons beat 12 abs() calls and a 12-argument max() in CPython
                    tail = [f"    r = _abs({diffs[0]})"]
                    for d in diffs[1:]:
                        tail += [f"    d = {d}", "    if d > r:", "        r = d", "    elif -d > r:", "        r = -d"]
                    tail += ["    return r"]
            else:
                state_out = []
                for v in [v for row in R for v in row] + p:
                    if isinstance(v, str) and v.lstrip("-") not in state_out:
                        state_out.append(v.lstrip("-"))
                # keep state names stable across the boundary
                tail = [f"    return ({', '.join(state_out)}{',' if len(state_out) == 1 else ''})"]
                state_in = state_out
            src += head + em.lines + tail + [""]
        return "\n".join(src) + "\n"


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
