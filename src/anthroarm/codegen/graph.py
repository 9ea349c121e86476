"""The one code generator of anthroarm: an exact expression graph with symbolic
differentiation and its emitters (Python/numpy and C).

Used by :mod:`anthroarm.dynamics.lagrange` (M, C q̇, g, τ; compiled by
:mod:`anthroarm.dynamics.ccode`).

Why not plain sympy expression trees?  The kinetic energy of a 7-DOF arm written out as one
sympy expression has hundreds of thousands of terms, and sympy's automatic distribution of
numeric coefficients over sums makes building it (and differentiating it three times for the
Christoffel symbols) take minutes.  This module keeps the same mathematics — exact
expressions, exact differentiation — but stores them as a *graph* (a straight-line program):

* every node is ``x + y`` or ``x * y`` of earlier nodes, a numeric constant, or an input
  symbol (``s_k = sin q_k``, ``c_k = cos q_k``, ``q_k`` of a prismatic joint, ``qd_k``,
  ``qdd_k``);
* nodes are *hash-consed*: building the same sum or product twice returns the same node, so
  common subexpressions are shared by construction (global value numbering = CSE);
* constants are folded and the identities ``x*0 = 0``, ``x*1 = x``, ``x+0 = x``,
  ``a*(b*x) = (ab)*x`` applied on the fly;
* :meth:`Graph.forward` is forward-mode differentiation (directional derivative / total time
  derivative), :meth:`Graph.reverse` reverse-mode (gradient of a scalar).  Both only apply the
  sum and product rules node by node, so their results are again exact expressions.

:meth:`Graph.to_sympy` turns any node into an ordinary sympy expression (``s_k -> sin(q_k)``)
for display, simplification and independent checks.  :func:`emit_python` / :func:`emit_c` print
a set of outputs as straight-line functions; :func:`straight_line` is their common core for
callers that write their own function frame (statements for the shared subexpressions,
single-use nodes inlined as nested expressions, nodes computed by an earlier function taken as
given).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A value is either a Python float (a constant) or an int node id >= 0 wrapped in `Node`.


class Node:
    """Handle of a graph node (supports ``+ - *`` with nodes and numbers)."""

    __slots__ = ("g", "i")

    def __init__(self, g: "Graph", i: int):
        self.g = g
        self.i = i

    def __add__(self, o):
        return self.g.add(self, o)

    __radd__ = __add__

    def __sub__(self, o):
        return self.g.add(self, self.g.mul(-1.0, o))

    def __rsub__(self, o):
        return self.g.add(o, self.g.mul(-1.0, self))

    def __mul__(self, o):
        return self.g.mul(self, o)

    __rmul__ = __mul__

    def __neg__(self):
        return self.g.mul(-1.0, self)

    def __repr__(self) -> str:
        return f"Node({self.i}: {self.g.ops[self.i]})"


def is_const(x) -> bool:
    return not isinstance(x, Node)


def snap(v: float, tol: float = 1e-15) -> float:
    """Round numerical noise of a model constant: |v| < tol -> 0, within tol of ±1 -> ±1."""
    v = float(v)
    if abs(v) < tol:
        return 0.0
    if abs(abs(v) - 1.0) < tol:
        return 1.0 if v > 0 else -1.0
    return v


@dataclass(frozen=True)
class Input:
    """An input symbol: ``kind`` in {"s", "c", "q", "qd", "qdd"} and the joint index ``k``."""

    kind: str
    k: int

    @property
    def name(self) -> str:
        return f"{self.kind}{self.k}"


class Graph:
    """Hash-consed expression graph (see the module docstring)."""

    def __init__(self):
        self.ops: list[
            tuple
        ] = []  # ("in", Input) | ("add", a, b) | ("mul", a, b); a, b: int id or float
        self._index: dict[tuple, int] = {}
        self.inputs: dict[Input, Node] = {}

    # ------------------------------------------------------------------ construction
    def _new(self, key: tuple) -> Node:
        # the index must tell a constant (float) from a node id (int): ("mul", 2.0, 7) is 2·x7,
        # ("mul", 2, 7) is x2·x7, and the two tuples are equal, with equal hashes, in Python
        ikey = (key, type(key[1]) is float)
        i = self._index.get(ikey)
        if i is None:
            i = len(self.ops)
            self.ops.append(key)
            self._index[ikey] = i
        return Node(self, i)

    def input(self, kind: str, k: int) -> Node:
        inp = Input(kind, k)
        n = self.inputs.get(inp)
        if n is None:
            n = self._new(("in", inp))
            self.inputs[inp] = n
        return n

    def add(self, a, b):
        ca, cb = is_const(a), is_const(b)
        if ca and cb:
            return float(a) + float(b)
        if ca:
            a, b, ca, cb = b, a, cb, ca
        if cb:
            if b == 0.0:
                return a
            return self._new(("add", float(b), a.i))
        ia, ib = a.i, b.i
        if ia == ib:
            return self.mul(2.0, a)
        if ia > ib:
            ia, ib = ib, ia
        return self._new(("add", ia, ib))

    def mul(self, a, b):
        ca, cb = is_const(a), is_const(b)
        if ca and cb:
            return float(a) * float(b)
        if ca:
            a, b, ca, cb = b, a, cb, ca
        if cb:
            b = float(b)
            if b == 0.0:
                return 0.0
            if b == 1.0:
                return a
            op = self.ops[a.i]
            if op[0] == "mul" and isinstance(op[1], float):  # b*(c*x) = (bc)*x
                return self.mul(b * op[1], Node(self, op[2]))
            return self._new(("mul", b, a.i))
        ia, ib = a.i, b.i
        if ia > ib:
            ia, ib = ib, ia
        # pull constant factors out: (c*x)*y = c*(x*y)
        oa, ob = self.ops[ia], self.ops[ib]
        if oa[0] == "mul" and isinstance(oa[1], float):
            return self.mul(oa[1], self.mul(Node(self, oa[2]), Node(self, ib)))
        if ob[0] == "mul" and isinstance(ob[1], float):
            return self.mul(ob[1], self.mul(Node(self, ia), Node(self, ob[2])))
        return self._new(("mul", ia, ib))

    def sum(self, terms):
        out = 0.0
        for t in terms:
            out = self.add(out, t)
        return out

    def wrap(self, x):
        """Node handle or float for an int id / float."""
        return Node(self, x) if isinstance(x, int) else x

    # ------------------------------------------------------------------ structure
    def cone(self, outputs, stop=()) -> list[int]:
        """Ids of every node the outputs depend on, ascending (= a topological order); the
        search does not go below the ids in ``stop`` (values computed elsewhere)."""
        seen: set[int] = set()
        stack = [o.i for o in outputs if isinstance(o, Node)]
        while stack:
            i = stack.pop()
            if i in seen:
                continue
            seen.add(i)
            op = self.ops[i]
            if op[0] != "in" and i not in stop:
                for a in op[1:]:
                    if isinstance(a, int) and a not in seen:
                        stack.append(a)
        return sorted(seen)

    # ------------------------------------------------------------------ differentiation
    def forward(self, outputs, seeds: dict) -> list:
        """Directional derivative of ``outputs`` for input tangents ``seeds`` {Node: value}.

        Exact forward-mode differentiation: ``d(a+b) = da + db``, ``d(ab) = da b + a db``."""
        tan: dict[int, object] = {n.i: v for n, v in seeds.items()}
        for i in self.cone(outputs):
            op = self.ops[i]
            if op[0] == "in":
                continue
            _, a, b = op
            if op[0] == "add":
                da = 0.0 if isinstance(a, float) else tan.get(a, 0.0)
                db = tan.get(b, 0.0)
                d = self.add(da, db)
            else:  # mul
                if isinstance(a, float):
                    d = self.mul(a, tan.get(b, 0.0))
                else:
                    da, db = tan.get(a, 0.0), tan.get(b, 0.0)
                    d = self.add(
                        self.mul(da, Node(self, b)) if not (is_const(da) and da == 0.0) else 0.0,
                        self.mul(Node(self, a), db) if not (is_const(db) and db == 0.0) else 0.0,
                    )
            if not (is_const(d) and d == 0.0):
                tan[i] = d
        return [tan.get(o.i, 0.0) if isinstance(o, Node) else 0.0 for o in outputs]

    def reverse(self, y) -> dict[int, object]:
        """Adjoints ``∂y/∂node`` of every node in the cone of the scalar ``y`` (reverse mode)."""
        if not isinstance(y, Node):
            return {}
        adj: dict[int, object] = {y.i: 1.0}
        for i in reversed(self.cone([y])):
            ai = adj.get(i)
            if ai is None:
                continue
            op = self.ops[i]
            if op[0] == "in":
                continue
            _, a, b = op
            if op[0] == "add":
                if not isinstance(a, float):
                    adj[a] = self.add(adj.get(a, 0.0), ai)
                adj[b] = self.add(adj.get(b, 0.0), ai)
            else:
                if isinstance(a, float):
                    adj[b] = self.add(adj.get(b, 0.0), self.mul(a, ai))
                else:
                    adj[a] = self.add(adj.get(a, 0.0), self.mul(ai, Node(self, b)))
                    adj[b] = self.add(adj.get(b, 0.0), self.mul(ai, Node(self, a)))
        return adj

    # ------------------------------------------------------------------ sympy
    def to_sympy(self, outputs, symbols: dict | None = None, inline_inputs: bool = True):
        """Sympy expressions of ``outputs``.  ``symbols`` maps :class:`Input` -> sympy
        expression (default: ``s_k -> sin(q_k)``, ``c_k -> cos(q_k)``, ``qd_k -> \\dot q_k``)."""
        import sympy as sp

        symbols = dict(symbols or {})
        memo: dict[int, object] = {}
        for i in self.cone(outputs):
            op = self.ops[i]
            if op[0] == "in":
                inp = op[1]
                if inp not in symbols:
                    symbols[inp] = default_symbol(inp)
                memo[i] = symbols[inp]
                continue
            _, a, b = op
            ea = sp.Float(a) if isinstance(a, float) else memo[a]
            ea = _nice_number(a) if isinstance(a, float) else ea
            eb = memo[b]
            memo[i] = ea + eb if op[0] == "add" else ea * eb
        return [memo[o.i] if isinstance(o, Node) else _nice_number(o) for o in outputs]


def _nice_number(v: float):
    import sympy as sp

    if float(v).is_integer():
        return sp.Integer(int(v))
    return sp.Float(v, 15)


def default_symbol(inp: Input):
    import sympy as sp

    q = sp.Symbol(f"q_{inp.k + 1}", real=True)
    if inp.kind == "s":
        return sp.sin(q)
    if inp.kind == "c":
        return sp.cos(q)
    if inp.kind == "q":
        return q
    if inp.kind == "qd":
        return sp.Symbol(rf"\dot{{q}}_{inp.k + 1}", real=True)
    if inp.kind == "qdd":
        return sp.Symbol(rf"\ddot{{q}}_{inp.k + 1}", real=True)
    raise ValueError(inp)


# ---------------------------------------------------------------------- code emission
def schedule(g: Graph, outputs) -> tuple[list[int], dict[int, str]]:
    """Topological order of the non-input nodes needed by ``outputs`` and a variable name for
    each, reusing names after their last use (linear-scan allocation, so a batched numpy
    evaluation keeps only the live intermediate arrays in memory)."""
    order = [i for i in g.cone(outputs) if g.ops[i][0] != "in"]
    out_ids = {o.i for o in outputs if isinstance(o, Node)}
    last: dict[int, int] = {}
    for pos, i in enumerate(order):
        for a in refs(g, i):
            last[a] = pos
    free: list[str] = []
    names: dict[int, str] = {}
    count = 0
    for pos, i in enumerate(order):
        if free:
            names[i] = free.pop()
        else:
            names[i] = f"t{count}"
            count += 1
        for a in set(refs(g, i)):
            if last.get(a) == pos and a in names and a not in out_ids and g.ops[a][0] != "in":
                free.append(names[a])
        if i not in last and i not in out_ids:  # dead (cannot happen) — recycle
            free.append(names[i])
    # outputs must keep their names until the end: give them fresh, never-reused names
    for i in out_ids:
        if i in names:
            names[i] = f"o{i}"
    return order, names


def _see_through(g: Graph, i: int, a, b):
    """For ``add(a, b)``: which operand is a negation ``-x`` printed as ``... - x``;
    returns (kept, negated_inner) or None."""
    if isinstance(a, float):
        return None
    ob, oa = g.ops[b], g.ops[a]
    if ob[0] == "mul" and ob[1] == -1.0:
        return a, ob[2]
    if oa[0] == "mul" and oa[1] == -1.0:
        return b, oa[2]
    return None


def refs(g: Graph, i: int) -> list[int]:
    """Node ids that the printed line of node ``i`` reads (see :func:`expr_text`)."""
    op = g.ops[i]
    _, a, b = op
    if op[0] == "add":
        st = _see_through(g, i, a, b)
        if st is not None:
            return [st[0], st[1]]
    return [x for x in (a, b) if isinstance(x, int)]


def expr_text(g: Graph, i: int, names: dict[int, str], inname, lang: str = "py") -> str:
    """One line's right-hand side: node ``i`` over its operands, each printed by name (an
    input by ``inname``); an operand without a name is printed inline as a nested expression
    (parenthesised so that the evaluation order is the graph's)."""

    def ref(x, pos):
        if isinstance(x, float):
            return repr(x) if lang == "py" else _c_float(x)
        op = g.ops[x]
        if op[0] == "in":
            return inname(op[1])
        name = names.get(x)
        if name is not None:
            return name
        t = expr_text(g, x, names, inname, lang)
        if (
            op[0] == "add"
            and pos != "add_l"
            or op[0] == "mul"
            and pos == "mul_r"
            or t.startswith("-")
            and pos in ("sub_r", "neg")
        ):
            return f"({t})"
        return t

    op = g.ops[i]
    _, a, b = op
    if op[0] == "add":
        if isinstance(a, float):
            return (
                f"{ref(b, 'add_l')} + {ref(a, 'add_r')}"
                if a >= 0
                else f"{ref(b, 'add_l')} - {ref(-a, 'sub_r')}"
            )
        st = _see_through(g, i, a, b)
        if st is not None:  # a - x
            return f"{ref(st[0], 'add_l')} - {ref(st[1], 'sub_r')}"
        return f"{ref(a, 'add_l')} + {ref(b, 'add_r')}"
    if isinstance(a, float) and a == -1.0:
        return f"-{ref(b, 'neg')}"
    return f"{ref(a, 'mul_l')}*{ref(b, 'mul_r')}"


def straight_line(
    g: Graph,
    outputs,
    inname,
    *,
    known: dict | None = None,
    lang: str = "py",
    prefix: str = "x",
    name_outputs: bool = True,
) -> tuple[list[tuple[str, str]], object]:
    """Statements ``(name, right-hand side)`` computing ``outputs`` in order, and ``ref(value)``:
    the text of an output (a name, an input, a constant or a short inline expression).

    Nodes used more than once (and the outputs) get a statement named ``{prefix}{id}``; nodes
    used once are inlined into their user (``name_outputs=False``: an output used nowhere else
    is inlined into ``ref(output)``, for the caller to place).  ``known`` maps ids of nodes
    already computed (for example by an earlier stage function) to their names: they are read,
    not recomputed."""
    known = dict(known or {})
    out_ids = [o.i for o in outputs if isinstance(o, Node)]
    printed: set[int] = set()  # nodes whose text is needed (a negation seen through is not)
    stack = [i for i in out_ids if g.ops[i][0] != "in" and i not in known]
    while stack:
        i = stack.pop()
        if i not in printed:
            printed.add(i)
            stack += [a for a in refs(g, i) if g.ops[a][0] != "in" and a not in known]
    order = sorted(printed)
    uses: dict[int, int] = {}
    for i in order:
        for a in refs(g, i):
            uses[a] = uses.get(a, 0) + 1
    for i in out_ids:
        uses[i] = uses.get(i, 0) + (2 if name_outputs else 1)
    names = dict(known)
    named = [i for i in order if uses.get(i, 0) > 1]
    for i in named:
        names[i] = f"{prefix}{i}"
    stmts = [(names[i], expr_text(g, i, names, inname, lang)) for i in named]

    def ref(o) -> str:
        if isinstance(o, Node):
            o = o.i
        if isinstance(o, float):
            return repr(o) if lang == "py" else _c_float(o)
        op = g.ops[o]
        if op[0] == "in":
            return inname(op[1])
        return names[o] if o in names else expr_text(g, o, names, inname, lang)

    return stmts, ref


def _c_float(x: float) -> str:
    r = repr(float(x))
    if "e" not in r and "." not in r and "inf" not in r and "nan" not in r:
        r += ".0"
    return r


def _input_names(kinds):
    def inname(inp: Input) -> str:
        return inp.name

    return inname


def used_inputs(g: Graph, outputs) -> list[Input]:
    return [g.ops[i][1] for i in g.cone(outputs) if g.ops[i][0] == "in"]


def emit_python(g: Graph, fname: str, args, outputs, shape, kinds, batched: bool = True) -> str:
    """Straight-line Python for ``outputs`` (flattened, row-major into ``shape``).

    ``batched``: arguments are (N, n) arrays and every intermediate an (N,) array (numpy);
    else arguments are (n,) and the arithmetic runs on Python floats (fast for one call)."""
    order, names = schedule(g, outputs)
    inname = _input_names(kinds)
    ins = used_inputs(g, outputs)
    need_q = sorted({i.k for i in ins if i.kind in ("s", "c", "q")})
    lines = [f"def {fname}({', '.join(args)}):"]
    if batched:
        lines.append(f"    N = {args[0]}.shape[0]")
        for k in need_q:
            lines.append(f"    q{k} = q[:, {k}]")
        for i in ins:
            if i.kind in ("qd", "qdd"):
                lines.append(f"    {i.name} = {i.kind}[:, {i.k}]")
        sin, cos = "_np.sin", "_np.cos"
    else:
        n = len(kinds)
        for a in args:
            lines.append(
                f"    {', '.join(f'{a}{k}' for k in range(n))}{',' if n == 1 else ''} = "
                f"{a}.tolist()"
            )
        sin, cos = "_ssin", "_scos"
    for i in ins:
        if i.kind == "s":
            lines.append(f"    s{i.k} = {sin}(q{i.k})")
        elif i.kind == "c":
            lines.append(f"    c{i.k} = {cos}(q{i.k})")
    for i in order:
        lines.append(f"    {names[i]} = {expr_text(g, i, names, inname)}")

    def ref(o):
        if isinstance(o, float):
            return repr(o)
        op = g.ops[o.i]
        return inname(op[1]) if op[0] == "in" else names[o.i]

    if batched:
        if shape == ():
            o = outputs[0]
            lines.append(
                f"    return _np.broadcast_to(_np.asarray({ref(o)}, dtype=float), (N,)).copy()"
            )
        else:
            lines.append(f"    out = _np.empty((N, {', '.join(map(str, shape))}))")
            idx = np.ndindex(*shape)
            for o, ix in zip(outputs, idx):
                lines.append(f"    out[:, {', '.join(map(str, ix))}] = {ref(o)}")
            lines.append("    return out")
    else:
        if shape == ():
            lines.append(f"    return float({ref(outputs[0])})")
        else:
            vals = ", ".join(ref(o) for o in outputs)
            lines.append(f"    return _np.array([{vals}]).reshape({shape})")
    return "\n".join(lines)


def emit_c(g: Graph, fname: str, args, outputs, nout: int, n: int) -> str:
    """A C function ``void fname(long N, const double *q, [qd, qdd,] double *out)`` looping over
    a batch (row-major ``(N, n)`` inputs, ``(N, nout)`` output); one ``const double`` per node."""
    order = [i for i in g.cone(outputs) if g.ops[i][0] != "in"]
    names = {i: f"x{i}" for i in order}
    ins = used_inputs(g, outputs)

    def inname(inp: Input) -> str:
        return inp.name

    params = ", ".join(f"const double *restrict {a}_" for a in args)
    lines = [
        f"void {fname}(long N, {params}, double *restrict out_) {{",
        "  for (long r = 0; r < N; ++r) {",
    ]
    for a in args:
        lines.append(f"    const double *{a} = {a}_ + r * {n};")
    lines.append(f"    double *out = out_ + r * {nout};")
    need_q = sorted({i.k for i in ins if i.kind in ("s", "c", "q")})
    for k in need_q:
        lines.append(f"    const double q{k} = q[{k}];")
    for i in ins:
        if i.kind in ("qd", "qdd"):
            lines.append(f"    const double {i.name} = {i.kind}[{i.k}];")
        elif i.kind == "s":
            lines.append(f"    const double s{i.k} = sin(q{i.k});")
        elif i.kind == "c":
            lines.append(f"    const double c{i.k} = cos(q{i.k});")
    for i in order:
        lines.append(f"    const double {names[i]} = {expr_text(g, i, names, inname, lang='c')};")
    for k, o in enumerate(outputs):
        if isinstance(o, float):
            val = _c_float(o)
        else:
            op = g.ops[o.i]
            val = inname(op[1]) if op[0] == "in" else names[o.i]
        lines.append(f"    out[{k}] = {val};")
    lines += ["  }", "}"]
    return "\n".join(lines)
