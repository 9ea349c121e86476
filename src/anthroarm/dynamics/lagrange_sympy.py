"""The sympy / LaTeX view of a Lagrange derivation (:func:`anthroarm.dynamics.lagrange.derive`):
the derived quantities as ordinary sympy expressions, the Christoffel symbols of a sympy mass
matrix, and the equations as LaTeX.  Re-exported by :mod:`anthroarm.dynamics.lagrange`.

The functions take a :class:`~anthroarm.dynamics.lagrange.Derivation` ``d`` (read through its
attributes only): this module imports nothing of :mod:`~anthroarm.dynamics.lagrange`, which
imports it."""

from __future__ import annotations


def _simp(e, simplify: bool, max_ops: int):
    import sympy as sp

    if not simplify:
        return e
    if sp.count_ops(e) > max_ops:
        return e
    e2 = sp.trigsimp(sp.expand(e))
    try:
        e3 = sp.simplify(e2) if sp.count_ops(e2) <= max_ops // 4 else e2
    except Exception:  # pragma: no cover - sympy corner cases
        e3 = e2
    return e3 if sp.count_ops(e3) <= sp.count_ops(e2) else e2


def sympy_matrices(
    d, which=("T", "V", "M", "Cqd", "g"), simplify: bool = True, max_ops: int = 300
) -> dict:
    """The derived quantities as sympy expressions in q_k, \\dot q_k (s_k -> sin q_k ...).

    ``simplify``: expand + trigsimp every entry whose operation count is at most
    ``max_ops`` (larger entries are returned as derived; full simplification of a 6-DOF mass
    matrix takes minutes).  Numbers are the model's floats (SI units)."""
    import sympy as sp

    n = d.n
    g = d.graph
    out = {}
    for w in which:
        if w == "T":
            out["T"] = _simp(g.to_sympy([d.T])[0], simplify, max_ops)
        elif w == "V":
            out["V"] = _simp(g.to_sympy([d.V])[0], simplify, max_ops)
        elif w == "M":
            flat = g.to_sympy([d.M[a][b] for a in range(n) for b in range(n)])
            out["M"] = sp.Matrix(n, n, [_simp(e, simplify, max_ops) for e in flat])
        elif w in ("Cqd", "g", "tau", "p", "dTdq"):
            vec = {"Cqd": d.Cqd, "g": d.g, "tau": d.tau, "p": d.p, "dTdq": d.dTdq}[w]
            out[w] = sp.Matrix([_simp(e, simplify, max_ops) for e in g.to_sympy(vec)])
        elif w == "C":
            flat = g.to_sympy([d.Cmat[a][b] for a in range(n) for b in range(n)])
            out["C"] = sp.Matrix(n, n, [_simp(e, simplify, max_ops) for e in flat])
        else:
            raise ValueError(
                f"unknown quantity {w!r}; choose from T, V, M, Cqd, C, g, tau, p, dTdq"
            )
    return out


def symbols(n: int):
    """(q, qd, qdd) sympy symbol lists used by :func:`sympy_matrices`."""
    import sympy as sp

    q = [sp.Symbol(f"q_{k + 1}", real=True) for k in range(n)]
    qd = [sp.Symbol(rf"\dot{{q}}_{k + 1}", real=True) for k in range(n)]
    qdd = [sp.Symbol(rf"\ddot{{q}}_{k + 1}", real=True) for k in range(n)]
    return q, qd, qdd


def christoffel(M, q):
    """Christoffel symbols of the first kind Γ[i][j][k] = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)
    of a sympy mass matrix (plain sympy differentiation: an independent path to C q̇)."""
    import sympy as sp

    n = M.shape[0]
    dM = [M.diff(q[k]) for k in range(n)]
    return [
        [
            [sp.Rational(1, 2) * (dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) for k in range(n)]
            for j in range(n)
        ]
        for i in range(n)
    ]


def latex(d, simplify: bool = True, max_ops: int = 300, which=("T", "V", "M", "Cqd", "g")) -> str:
    """LaTeX of the Lagrange equations ``τ = M(q) q̈ + C(q,q̇) q̇ + g(q)`` with each quantity
    written out (see :func:`sympy_matrices` for ``simplify``/``max_ops``)."""
    import sympy as sp

    mats = sympy_matrices(d, which=which, simplify=simplify, max_ops=max_ops)
    names = {
        "T": "T",
        "V": "V",
        "M": "M(q)",
        "Cqd": r"C(q,\dot q)\,\dot q",
        "C": r"C(q,\dot q)",
        "g": "g(q)",
        "tau": r"\tau",
        "p": r"\partial T/\partial\dot q",
        "dTdq": r"\partial T/\partial q",
    }
    parts = [r"\tau = M(q)\,\ddot q + C(q,\dot q)\,\dot q + g(q)"]
    for k, v in mats.items():
        parts.append(f"{names[k]} = {sp.latex(v)}")
    return (
        r"\begin{aligned}" + r"\\ ".join(p.replace("=", "&=", 1) for p in parts) + r"\end{aligned}"
    )
