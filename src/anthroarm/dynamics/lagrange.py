r"""Lagrange equations of a serial (or tree) arm: symbolic derivation and generated code.

Book Ch. 8 §8-1.  For generalized coordinates q (joint angles, rad; prismatic joints, m) the
Lagrange equations (8-8)/(8-13)

.. math::  \frac{d}{dt}\frac{\partial L}{\partial\dot q}-\frac{\partial L}{\partial q}=\tau,
           \qquad L = T(q,\dot q) - V(q)

with :math:`T=\tfrac12\dot q^T M(q)\dot q` give

.. math::  \tau = M(q)\ddot q + C(q,\dot q)\dot q + g(q),\quad
           (C\dot q)_i=\sum_{jk}\Gamma_{ijk}\dot q_j\dot q_k,\quad
           \Gamma_{ijk}=\tfrac12\Big(\frac{\partial M_{ij}}{\partial q_k}+\frac{\partial
           M_{ik}}{\partial q_j}-\frac{\partial M_{jk}}{\partial q_i}\Big), \quad g=\frac{\partial
           V}{\partial q}.

**Derivation.**  :func:`derive` reads ``robot.chain`` (:mod:`anthroarm.chain`: joint placements,
axes, link inertias, gravity, mimic relations) and writes T and V as exact expressions of
``s_k = sin θ_k``, ``c_k = cos θ_k`` (prismatic: ``θ_k``) of every joint and of the generalized
velocities ``q̇``.  A continuous (unbounded revolute) joint is a revolute joint without limits:
one angle θ, one velocity.  A mimic joint θ_j = a θ_i + b has no coordinate of its own: it
moves with θ̇_j = a q̇_i inside T and V and ∂/∂θ_i reaches it by the chain rule, so M, C q̇, g
and τ are in the independent (nv) coordinates, as Pinocchio's ``crba``/``rnea`` return them.
The derivation following the recursive link velocities
(each link's twist in its own frame, the form of Eq. (8-27)):

    ω_i = Rᵢᵀ ω_λ + a_i q̇_i,   v_i = Rᵢᵀ (v_λ + ω_λ × p_i) (+ a_i q̇_i for a prismatic joint),
    T = Σ ½ m_i |v_i + ω_i × c_i|² + ½ ω_iᵀ I_i ω_i                                  (8-24)
    V = -Σ m_i gᵀ (p_i⁰ + R_i⁰ c_i)                                                  (8-106)

where ``R_i, p_i`` is the placement of joint i in its parent's frame times the joint motion,
``c_i`` the centre of mass and ``I_i`` the rotational inertia about it (link frame, SI).  The
expressions live in a hash-consed graph (:mod:`anthroarm.codegen.graph`): exact symbolic algebra in
which equal subexpressions are shared, so the derivation of a 7-DOF arm takes well under a second
instead of the minutes a fully expanded sympy expression needs.  From T and V, by exact
symbolic differentiation only:

* momentum p = ∂T/∂q̇ (reverse-mode differentiation of T),
* M = ∂p/∂q̇ (the Hessian ∂²T/∂q̇², Eq. (8-105)),
* g = ∂V/∂q,
* C q̇ = Ṁ q̇ − ∂T/∂q = Σ Γ_ijk q̇_j q̇_k (the Christoffel contraction: Ṁq̇ = Σ_jk ∂_k M_ij q̇_j
  q̇_k and ∂T/∂q_i = ½ Σ_jk ∂_i M_jk q̇_j q̇_k, so their difference is exactly Σ Γ_ijk q̇_j q̇_k),
* the Christoffel matrix C_ij = Σ_k Γ_ijk q̇_k = ½(Ṁ_ij + ∂p_i/∂q_j − ∂p_j/∂q_i),
* τ = d/dt(∂T/∂q̇) − ∂T/∂q + ∂V/∂q, the Euler–Lagrange equation itself.

The explicit Christoffel symbols and fully written-out sympy matrices are available for small
models (:func:`sympy_matrices`, :func:`christoffel`, :func:`latex`).

**Generated code.**  The outputs are printed as straight-line numpy code (one line per graph
node: common subexpressions appear once), vectorised over a batch, plus a scalar variant for
single calls; optionally C compiled with the system compiler (``backend="c"``, :mod:`.ccode`).
The generated functions take the joint positions θ of every joint (``chain.angles(q)``);
:class:`LagrangeDynamics` takes q in the robot's layout (nq: a continuous joint's (cos, sin)
pair) and converts.  The code lives in the one disk cache (:mod:`anthroarm.cache`: the user
cache folder or ``$ANTHROARM_CACHE``), keyed by ``chain.key()`` and the generator version,
verified before it is executed, written atomically (deriving and generating the code of a
7-DOF arm takes ~0.1 s, so nothing needs to ship pre-generated).

>>> import anthroarm as aa
>>> from anthroarm.dynamics import lagrange
>>> dyn = lagrange.load(aa.load("planar2r"))
>>> M = dyn.mass_matrix([0.1, 0.2])              # (2, 2), kg m^2
"""

from __future__ import annotations

import os
import threading
import time
import types
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from .. import cache
from ..chain import CONTINUOUS, PRISMATIC, REVOLUTE, Chain
from ..codegen.graph import Graph, emit_python, snap
from ..errors import InertiaError, SingularMassMatrixError, UnsupportedModelError
from ..robot import load as load_robot
from .ccode import compiled
from .lagrange_sympy import _simp, christoffel, latex, symbols, sympy_matrices  # noqa: F401

#: bump when the generated code changes (part of the cache key); "3": code generated before the
#: graph told a constant 2.0 from node id 2 (issue 30, wrong C q̇ and τ) is never loaded again
GENERATOR_VERSION = "4"
#: forward dynamics refuses M(q) whose reciprocal condition number (estimated from the Cholesky
#: pivots) is below this: :class:`~anthroarm.errors.SingularMassMatrixError`
SINGULAR_RCOND = 1e-12
#: |q|, |q̇|, |q̈|, |τ| above this are a ValueError (their squares times masses and lengths
#: within the loader's physical bounds stay in the float range)
STATE_BOUND = 1e100
_FAST_BOUND = (STATE_BOUND * 1e-160) ** 2


# ====================================================================== model description
@dataclass(frozen=True, eq=False)
class ChainInfo:
    """The Lagrange view of a :class:`~anthroarm.chain.Chain` (``robot.chain``), inertias validated.

    Generalized coordinates are the independent joints' positions θ (rad or m) in velocity
    order (``chain.nv`` of them: a continuous joint is one angle, a mimic joint none).  Joint k
    (every joint of ``chain.joints``, mimic ones included) moves with θ̇_k = ``factor[k]`` ·
    v[``coord[k]``]: factor 1 for an independent joint, the multiplier for a mimic joint
    (θ_k = a θ_i + b)."""

    name: str
    chain: object
    coord: tuple  # per joint: index of its generalized coordinate (0..n-1)
    factor: tuple  # per joint: dθ_k / dv_coord
    source: (
        tuple  # per joint: joint index whose velocity input drives it (itself or its mimic source)
    )

    @property
    def joints(self):
        return self.chain.joints

    @property
    def gravity(self) -> np.ndarray:
        return self.chain.gravity

    @property
    def n(self) -> int:
        """Number of generalized coordinates (= ``chain.nv``)."""
        return self.chain.nv

    @property
    def njoints(self) -> int:
        return len(self.chain.joints)

    def key(self) -> str:
        """Cache key of the generated code: the generator version and ``chain.key()``."""
        return cache.key("lagrange", GENERATOR_VERSION, self.chain.key(), length=20)


def _check_inertias(chain) -> None:
    """:class:`InertiaError` for negative or non-finite masses, non-finite centres of mass,
    inertia tensors that are not positive semidefinite and massless chains."""
    name = chain.name
    for j in chain.joints:
        m, c, Ic = j.mass, j.com, j.inertia
        label = f"{name}: link of joint {j.name!r}"
        if not np.isfinite(m) or m < 0:
            raise InertiaError(f"{label} has mass {m}; masses must be finite and >= 0 kg")
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(Ic))):
            raise InertiaError(f"{label} has a non-finite centre of mass or inertia")
        ev = np.linalg.eigvalsh(Ic)
        scale = max(float(np.max(np.abs(ev))), 1e-300)
        if ev[0] < -1e-9 * scale:
            raise InertiaError(
                f"{label} has an inertia tensor that is not positive (semi)definite: eigenvalues "
                f"{ev.tolist()} kg m^2"
            )
        if m == 0 and np.max(np.abs(Ic)) > 0:
            raise InertiaError(f"{label} has zero mass but a non-zero rotational inertia")
    if not chain.joints:
        raise UnsupportedModelError(f"{name}: the model has no joints")
    if all(j.mass == 0 for j in chain.joints):
        raise InertiaError(f"{name}: massless chain (every link has zero mass); M(q) would be zero")


def chain_info(obj, name: str | None = None) -> ChainInfo:
    """:class:`ChainInfo` of a Robot (its ``robot.chain``), a :class:`~anthroarm.chain.Chain`,
    a ``pin.Model``, a catalog / example-robot-data name or a URDF path.

    Raises :class:`UnsupportedModelError` for joints the chain does not handle (free-flyer,
    spherical, planar, helical...) and :class:`InertiaError` for negative masses, indefinite
    inertia tensors and massless chains."""
    if isinstance(obj, ChainInfo):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        obj = load_robot(obj)
    chain = getattr(obj, "chain", None) if not isinstance(obj, Chain) else obj
    if chain is None:
        if not isinstance(obj, pin.Model):
            raise UnsupportedModelError(
                f"Lagrange dynamics need a Robot, a Chain, a pin.Model or a catalog name, "
                f"got {type(obj).__name__}"
            )
        # the tool frame does not matter to dynamics: the base frame keeps trees unambiguous
        chain = Chain.from_model(
            obj, tool=obj.frames[0].name, name=name or getattr(obj, "name", "") or "model"
        )
    _check_inertias(chain)
    coord, factor, source = [], [], []
    vindex = {i: chain.joints[i].idx_v for i in chain.independent}
    for j in chain.joints:
        src = j.mimic.source if j.is_mimic else j.index
        coord.append(vindex[src])
        factor.append(j.mimic.multiplier if j.is_mimic else 1.0)
        source.append(src)
    return ChainInfo(
        name=name or chain.name,
        chain=chain,
        coord=tuple(coord),
        factor=tuple(factor),
        source=tuple(source),
    )


# ====================================================================== symbolic derivation
def _rot_T(axis, s, c, w, g: Graph):
    """R(axis, q)ᵀ w for a unit axis, with s = sin q, c = cos q (Rodrigues)."""
    ax = [snap(a) for a in axis]
    nz = [k for k in range(3) if ax[k] != 0.0]
    if len(nz) == 1:  # coordinate axis ±e_k: a plane rotation
        k = nz[0]
        sg = ax[k]
        i, j = (k + 1) % 3, (k + 2) % 3
        ss = g.mul(sg, s)
        out = [0.0, 0.0, 0.0]
        out[k] = w[k]
        out[i] = g.add(g.mul(c, w[i]), g.mul(ss, w[j]))
        out[j] = g.add(g.mul(c, w[j]), g.mul(-1.0, g.mul(ss, w[i])))
        return out
    # general: Rᵀw = c w + s (w × a) + (1 - c)(a·w) a
    a = ax
    wxa = _cross_c(w, a, g)
    adw = g.sum(g.mul(a[k], w[k]) for k in range(3))
    omc = g.add(1.0, g.mul(-1.0, c))
    f = g.mul(omc, adw)
    return [g.sum([g.mul(c, w[k]), g.mul(s, wxa[k]), g.mul(a[k], f)]) for k in range(3)]


def _cross_c(u, v, g: Graph):
    return [
        g.add(g.mul(u[1], v[2]), g.mul(-1.0, g.mul(u[2], v[1]))),
        g.add(g.mul(u[2], v[0]), g.mul(-1.0, g.mul(u[0], v[2]))),
        g.add(g.mul(u[0], v[1]), g.mul(-1.0, g.mul(u[1], v[0]))),
    ]


def _matT_vec(R, w, g: Graph):
    """Rᵀ w for a constant matrix R (entries snapped, zeros skipped)."""
    return [g.sum(g.mul(snap(R[k, i]), w[k]) for k in range(3)) for i in range(3)]


def _dot(u, v, g: Graph):
    return g.sum(g.mul(a, b) for a, b in zip(u, v))


@dataclass
class Derivation:
    """The symbolic result of :func:`derive`: graph nodes of every quantity."""

    info: ChainInfo
    graph: Graph
    T: object
    V: object
    p: list  # ∂T/∂q̇
    dTdq: list  # ∂T/∂q
    g: list  # ∂V/∂q
    M: list  # n x n (full, symmetric; M[j][k] for j <= k derived, mirrored)
    Cqd: list
    tau: list
    Cmat: list | None = None
    seconds: float = 0.0
    inputs: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.info.n


def derive(model_or_robot, name: str | None = None, coriolis_matrix: bool = True) -> Derivation:
    """Derive T, V, M(q), C(q,q̇)q̇, g(q) and τ symbolically (see the module docstring).

    ``model_or_robot``: anything :func:`chain_info` takes.  The graph's inputs are, per joint
    k (mimic joints included), ``s_k, c_k`` = sin, cos θ_k (revolute and continuous joints) or
    ``q_k`` = θ_k (prismatic), and ``qd_k, qdd_k`` for the independent joints; a mimic joint
    moves with θ̇_k = a θ̇_source.  Outputs are in the generalized coordinates (v order).
    """
    t0 = time.perf_counter()
    info = chain_info(model_or_robot, name)
    n, nj = info.n, info.njoints
    g = Graph()
    s, c, qv = [None] * nj, [None] * nj, [None] * nj
    rot = [j.kind != PRISMATIC for j in info.joints]
    for k in range(nj):
        if rot[k]:
            s[k], c[k] = g.input("s", k), g.input("c", k)
        else:
            qv[k] = g.input("q", k)
    ind = [k for k in range(nj) if info.source[k] == k]  # independent joints, v order
    qd = [g.input("qd", k) for k in ind]  # qd[i]: generalized velocity i
    qdd = [g.input("qdd", k) for k in ind]
    thd = [g.mul(info.factor[k], qd[info.coord[k]]) for k in range(nj)]  # θ̇_k
    grav = [snap(x) for x in info.gravity]

    w = [None] * nj  # angular velocity of link k, link frame
    v = [None] * nj  # linear velocity of the link-frame origin, link frame
    gam = [None] * nj  # gravity vector in link frame
    h = [None] * nj  # gᵀ p_k (world), the "height" of the link origin times |g|
    T_terms, V_terms = [], []
    for k, j in enumerate(info.joints):
        if j.parent >= 0:
            wl, vl, gl, hl = w[j.parent], v[j.parent], gam[j.parent], h[j.parent]
        else:
            wl, vl, gl, hl = [0.0] * 3, [0.0] * 3, grav, 0.0
        axis = [snap(x) for x in j.axis]
        p0 = [snap(x) for x in j.translation]
        R0 = j.rotation
        # position of the joint origin in the parent frame (prismatic joints move it)
        if not rot[k]:
            ax0 = [snap(x) for x in R0 @ j.axis]
            p = [g.add(p0[i], g.mul(ax0[i], qv[k])) for i in range(3)]
        else:
            p = p0
        vt = [g.add(vl[i], x) for i, x in enumerate(_cross_c(wl, p, g))]
        hk = g.add(hl, _dot(gl, p, g))
        wk = _matT_vec(R0, wl, g)
        vk = _matT_vec(R0, vt, g)
        gk = _matT_vec(R0, gl, g)
        if rot[k]:
            wk = _rot_T(axis, s[k], c[k], wk, g)
            vk = _rot_T(axis, s[k], c[k], vk, g)
            gk = _rot_T(axis, s[k], c[k], gk, g)
            wk = [g.add(wk[i], g.mul(axis[i], thd[k])) for i in range(3)]
        else:
            vk = [g.add(vk[i], g.mul(axis[i], thd[k])) for i in range(3)]
        w[k], v[k], gam[k], h[k] = wk, vk, gk, hk
        if j.mass > 0:
            m = j.mass
            cm = [snap(x) for x in j.com]
            vc = [g.add(vk[i], x) for i, x in enumerate(_cross_c(wk, cm, g))]
            I = j.inertia
            quad = g.sum(
                [
                    g.mul(snap(I[0, 0]), g.mul(wk[0], wk[0])),
                    g.mul(snap(I[1, 1]), g.mul(wk[1], wk[1])),
                    g.mul(snap(I[2, 2]), g.mul(wk[2], wk[2])),
                    g.mul(2 * snap(I[0, 1]), g.mul(wk[0], wk[1])),
                    g.mul(2 * snap(I[0, 2]), g.mul(wk[0], wk[2])),
                    g.mul(2 * snap(I[1, 2]), g.mul(wk[1], wk[2])),
                ]
            )
            T_terms.append(g.add(g.mul(0.5 * m, _dot(vc, vc, g)), g.mul(0.5, quad)))  # (8-24)
            V_terms.append(g.mul(-m, g.add(hk, _dot(gk, cm, g))))  # (8-106)
    T = g.sum(T_terms)
    V = g.sum(V_terms)

    def coord_seed(i):
        """∂/∂(generalized coordinate i) of the joint inputs: θ_k = a_k θ_i + b_k for every
        joint k driven by coordinate i (sin: a c_k, cos: −a s_k, position: a)."""
        seed = {}
        for k in range(nj):
            if info.coord[k] == i:
                a = info.factor[k]
                if rot[k]:
                    seed[s[k]] = g.mul(a, c[k])
                    seed[c[k]] = g.mul(-a, s[k])
                else:
                    seed[qv[k]] = a
        return seed

    def grad_q(adj):
        # d/dθ f(sin θ, cos θ) = f_s cos θ − f_c sin θ, times dθ/dq_i, summed over the joints q_i
        # drives
        out = [[] for _ in range(n)]
        for k in range(nj):
            a = info.factor[k]
            if rot[k]:
                a_s, a_c = adj.get(s[k].i, 0.0), adj.get(c[k].i, 0.0)
                d = g.add(g.mul(a_s, c[k]), g.mul(-1.0, g.mul(a_c, s[k])))
            else:
                d = adj.get(qv[k].i, 0.0)
            out[info.coord[k]].append(g.mul(a, d))
        return [g.sum(t) for t in out]

    adjT = g.reverse(T)
    p = [adjT.get(qd[i].i, 0.0) for i in range(n)]
    dTdq = grad_q(adjT)
    gvec = grad_q(g.reverse(V))
    # M = ∂p/∂q̇ (column by column, keep j <= k and mirror)
    M = [[0.0] * n for _ in range(n)]
    for k in range(n):
        col = g.forward(p, {qd[k]: 1.0})
        for jj in range(k + 1):
            M[jj][k] = col[jj]
            M[k][jj] = col[jj]
    # time derivative along q only (q̈ = 0): d/dt s_k = c_k θ̇_k, d/dt c_k = −s_k θ̇_k
    qseed = {}
    for k in range(nj):
        if rot[k]:
            qseed[s[k]] = g.mul(c[k], thd[k])
            qseed[c[k]] = g.mul(-1.0, g.mul(s[k], thd[k]))
        else:
            qseed[qv[k]] = thd[k]
    Mdot_qd = g.forward(p, qseed)  # Ṁ q̇
    Cqd = [g.add(Mdot_qd[i], g.mul(-1.0, dTdq[i])) for i in range(n)]
    full = dict(qseed)
    full.update({qd[i]: qdd[i] for i in range(n)})
    dpdt = g.forward(p, full)  # d/dt ∂T/∂q̇ = M q̈ + Ṁ q̇
    tau = [g.sum([dpdt[i], g.mul(-1.0, dTdq[i]), gvec[i]]) for i in range(n)]  # (8-13) with V
    Cmat = None
    if coriolis_matrix:
        Mflat = [M[a][b] for a in range(n) for b in range(n)]
        Mdot = g.forward(Mflat, qseed)
        dp = [g.forward(p, coord_seed(i)) for i in range(n)]  # dp[j][i] = ∂p_i/∂q_j
        Cmat = [
            [
                g.mul(0.5, g.sum([Mdot[a * n + b], dp[b][a], g.mul(-1.0, dp[a][b])]))
                for b in range(n)
            ]
            for a in range(n)
        ]
    d = Derivation(
        info=info,
        graph=g,
        T=T,
        V=V,
        p=p,
        dTdq=dTdq,
        g=gvec,
        M=M,
        Cqd=Cqd,
        tau=tau,
        Cmat=Cmat,
        inputs={"s": s, "c": c, "q": qv, "qd": qd, "qdd": qdd},
    )
    d.seconds = time.perf_counter() - t0
    return d


# ====================================================================== code generation
def _outputs(d: Derivation) -> dict:
    """function name -> (arguments, output nodes (row-major), output shape)."""
    n = d.n
    out = {
        "mass_matrix": (("q",), [d.M[a][b] for a in range(n) for b in range(n)], (n, n)),
        "coriolis": (("q", "qd"), d.Cqd, (n,)),
        "gravity": (("q",), d.g, (n,)),
        "tau": (("q", "qd", "qdd"), d.tau, (n,)),
        "kinetic_energy": (("q", "qd"), [d.T], ()),
        "potential_energy": (("q",), [d.V], ()),
        "momentum": (("q", "qd"), d.p, (n,)),
    }
    if d.Cmat is not None:
        out["coriolis_matrix"] = (
            ("q", "qd"),
            [d.Cmat[a][b] for a in range(n) for b in range(n)],
            (n, n),
        )
    return out


def _kinds(info: ChainInfo) -> str:
    """One letter per joint: R revolute, C continuous, P prismatic; lower case for a mimic joint."""
    letters = {REVOLUTE: "R", CONTINUOUS: "C", PRISMATIC: "P"}
    return "".join(letters[j.kind].lower() if j.is_mimic else letters[j.kind] for j in info.joints)


def generate_python(d: Derivation, only=None) -> str:
    """Python module text with numpy (batched) and scalar versions of every function (of those
    named in ``only``, if given).

    Every function takes the joint positions θ of all joints (``q``, mimic joints included,
    as :meth:`~anthroarm.chain.Chain.angles` returns them) and their velocities and
    accelerations (``qd``, ``qdd``, one entry per joint; a mimic joint's entry is not read:
    it moves with its source), and returns quantities in the generalized coordinates."""
    kinds = _kinds(d.info)
    head = [
        f'"""Generated by anthroarm.dynamics.lagrange (generator v{GENERATOR_VERSION}); do not '
        "edit.",
        "",
        f"Key {d.info.key()}: {d.info.njoints} joints ({kinds}), {d.n} generalized coordinates.",
        "Lagrange equations tau = M(q) qdd + C(q, qd) qd + g(q) in SI units; see lagrange.py.",
        '"""',
        "from math import sin as _ssin, cos as _scos",
        "import numpy as _np",
        "",
        f"NQ = {d.n}",
        f"NJ = {d.info.njoints}",
        f"KEY = {d.info.key()!r}",
        f"KINDS = {kinds!r}",
        f"GENERATOR_VERSION = {GENERATOR_VERSION!r}",
        "",
    ]
    body = []
    for fname, (args, outs, shape) in _outputs(d).items():
        if only is not None and fname not in only:
            continue
        body.append(emit_python(d.graph, fname, args, outs, shape, kinds, batched=True))
        body.append(emit_python(d.graph, fname + "_1", args, outs, shape, kinds, batched=False))
    return "\n".join(head) + "\n" + "\n\n".join(body) + "\n"


# ====================================================================== cache
_LOCK = threading.Lock()
_MEMO: dict[str, object] = {}  # key (coriolis:key) -> generated module (holds no Robot)


def generated_module(
    model_or_robot, name: str | None = None, use_cache: bool = True, coriolis_matrix: bool = False
):
    """The generated Python module of a model: from memory, the disk cache
    (:mod:`anthroarm.cache`, ``lagrange/lagrange_<key>.py``, verified before it is executed) or
    a fresh derivation (then stored).  Returns ``(module, origin)`` with origin "memory",
    "cache" or "derived".  Raises :class:`InertiaError` if M(q) is not positive definite (a
    joint that moves no mass).

    The Christoffel matrix C(q, q̇) has n² entries, two thirds of the generated code of a
    27-joint limb (2 s of its 4 s of derivation, generation and compilation): it is a module of
    its own (``coriolis_matrix=True``, ``lagrange/coriolis_<key>.py``), made on first use."""
    info = chain_info(model_or_robot, name)
    key = info.key()
    stem = "coriolis" if coriolis_matrix else "lagrange"
    memo = f"coriolis:{key}" if coriolis_matrix else key
    with _LOCK:
        if memo in _MEMO:
            return _MEMO[memo], "memory"
        modname = f"anthroarm_{stem}_{key}"
        if coriolis_matrix:
            make = lambda: generate_python(derive(info), only=("coriolis_matrix",))  # noqa: E731
        else:
            make = lambda: generate_python(derive(info, coriolis_matrix=False))  # noqa: E731
        if use_cache:
            mod, origin = cache.python_module("lagrange", f"{stem}_{key}.py", make, modname)
        else:
            mod, origin = types.ModuleType(modname), "derived"
            exec(compile(make(), f"<{modname}>", "exec"), mod.__dict__)
        if not coriolis_matrix:
            _check_pd(mod, info)
        _MEMO[memo] = mod
        return mod, origin


def _check_pd(mod, info: ChainInfo) -> None:
    """M(q) must be positive definite: at θ = 0 and at two random configurations."""
    chain = info.chain
    rng = np.random.default_rng(12345)
    Q = chain.angles(
        chain.configuration(np.vstack([np.zeros(info.n), rng.uniform(-np.pi, np.pi, (2, info.n))]))
    )
    for th in Q:
        M = mod.mass_matrix_1(th)
        ev = np.linalg.eigvalsh(M)
        if not ev[0] > 1e-12 * max(ev[-1], 1e-300):
            weak = info.chain.independent[int(np.argmin(np.diag(M)))]
            raise InertiaError(
                f"{info.name}: the mass matrix is not positive definite at θ = "
                f"{np.round(th, 3).tolist()} (eigenvalues {ev.tolist()}); joint "
                f"{info.joints[weak].name!r} moves (almost) no mass or inertia — a massless chain "
                "or zero inertia has no forward dynamics"
            )


# ====================================================================== user-facing object
class LagrangeDynamics:
    """Numeric Lagrange dynamics of one model, from generated code.

    States are in the robot's layout: q ``(nq,)`` as Pinocchio has it (a continuous joint's
    (cos θ, sin θ) pair, no entry for a mimic joint), q̇ and q̈ ``(nv,)``; or batches
    ``(N, nq)``/``(N, nv)`` (then results have a leading ``N`` axis).  Results are in the nv
    generalized coordinates, so they compare with ``pin.crba``/``rnea``/``aba`` directly.  SI
    units: rad (m for prismatic joints), N m (N).  Thread-safe."""

    def __init__(
        self,
        model_or_robot,
        name: str | None = None,
        use_cache: bool = True,
        backend: str = "numpy",
    ):
        self.info = chain_info(model_or_robot, name)
        chain = self.chain = self.info.chain
        self.n, self.nq = self.info.n, chain.nq
        self.joint_names = [chain.joints[i].name for i in chain.independent]
        self.module, self.source = generated_module(self.info, use_cache=use_cache)
        self._use_cache = use_cache
        self._coriolis = None  # the Coriolis matrix's module, on first use (:meth:`_module`)
        # θ = q and θ̇ = q̇ when every joint is a plain revolute / prismatic joint in q order
        self._plain_q = all(
            j.kind != CONTINUOUS and not j.is_mimic and j.idx_q == j.index for j in chain.joints
        )
        self._plain_v = not chain.has_mimic
        self._cos = np.array(
            [j.idx_q for j in chain.joints if j.kind == CONTINUOUS and not j.is_mimic], dtype=int
        )
        self._vsel = np.array(self.info.coord)
        self._vscale = np.array(self.info.factor)
        self.backend = backend
        self._c = None
        if backend == "c":
            self._c = compiled(self.info.key(), self._c_inputs)
        elif backend != "numpy":
            raise ValueError(f"backend must be 'numpy' or 'c', got {backend!r}")

    def _module(self, fname: str):
        """The generated module holding ``fname`` (the Coriolis matrix's is made on first use:
        :func:`generated_module`)."""
        if fname != "coriolis_matrix":
            return self.module
        if self._coriolis is None:  # kept: its cache key is a ~30 µs hash, a call's worth
            self._coriolis = generated_module(
                self.info, use_cache=self._use_cache, coriolis_matrix=True
            )[0]
        return self._coriolis

    def _c_inputs(self):
        d = derive(self.info)
        return d.graph, _outputs(d), self.info.njoints

    def __repr__(self) -> str:
        return (
            f"LagrangeDynamics({self.info.name!r}, nq={self.nq}, nv={self.n}, "
            f"backend={self.backend!r}, from {self.source})"
        )

    # -- robot layout -> the generated code's joint positions and rates
    def _theta(self, q):
        if self._plain_q:
            return q
        if self._cos.size:
            c, s = q[..., self._cos], q[..., self._cos + 1]
            if np.any(np.abs(c * c + s * s - 1.0) > 2e-6):
                self.chain.check_unit(q)  # raises, naming the joint
        return self.chain.angles(q)

    def _rates(self, v):
        return v if self._plain_v else v[..., self._vsel] * self._vscale

    # -- input checking
    def _arr(self, x, what: str):
        a = np.asarray(x, dtype=float)
        size, names = (self.nq, self.chain.q_names) if what == "q" else (self.n, self.joint_names)
        if a.ndim not in (1, 2) or a.shape[-1] != size:
            raise ValueError(
                f"{self.info.name}: {what} must have shape ({size},) or (N, {size}), got {a.shape}"
            )
        if not np.all(np.isfinite(a)):
            bad = np.argwhere(~np.isfinite(a))[0]
            j = int(bad[-1])
            raise ValueError(
                f"{self.info.name}: {what}[{j}] (joint {names[j]!r}) is {a[tuple(bad)]}; "
                "states must be finite"
            )
        if a.size and np.max(np.abs(a)) > STATE_BOUND:
            bad = np.argwhere(np.abs(a) > STATE_BOUND)[0]
            j = int(bad[-1])
            raise ValueError(
                f"{self.info.name}: {what}[{j}] (joint {names[j]!r}) is {a[tuple(bad)]:.3g}; "
                f"states and torques must be within +-{STATE_BOUND:.0e} (their squares and "
                "products with the inertias must stay in the float range)"
            )
        return a

    def _call(self, fname, q, *rates):
        # fast path: one state, contiguous float64 vectors of the right lengths
        tot = 0.0
        ok = type(q) is np.ndarray and q.shape == (self.nq,) and q.dtype == np.float64
        if ok:
            s = q * 1e-160  # squares of the scaled entries cannot overflow
            tot = s.dot(s)
            for a in rates:
                if type(a) is not np.ndarray or a.shape != (self.n,) or a.dtype != np.float64:
                    ok = False
                    break
                s = a * 1e-160
                tot += s.dot(s)
        if ok and tot < _FAST_BOUND:  # finite (NaN compares False) and every entry within the bound
            arrs = (self._theta(q),) + (
                rates if self._plain_v else tuple(self._rates(a) for a in rates)
            )
            if self._c is not None:
                return self._c.one(fname, arrs)
            return getattr(self._module(fname), fname + "_1")(*arrs)
        names = ("q", "qd", "qdd")
        arrs = [self._arr(a, names[i]) for i, a in enumerate((q, *rates))]
        single = all(a.ndim == 1 for a in arrs)
        if not single:
            N = max(a.shape[0] if a.ndim == 2 else 1 for a in arrs)
            arrs = [np.broadcast_to(a, (N, a.shape[-1])) if a.ndim == 1 else a for a in arrs]
            if any(a.shape[0] != N for a in arrs):
                raise ValueError(f"{self.info.name}: batch sizes differ: {[a.shape for a in arrs]}")
        arrs = [self._theta(arrs[0]), *(self._rates(a) for a in arrs[1:])]
        if self._c is not None:
            return self._c(fname, arrs, single)
        if single:
            return getattr(self._module(fname), fname + "_1")(*arrs)
        return getattr(self._module(fname), fname)(*[np.ascontiguousarray(a) for a in arrs])

    def mass_matrix(self, q):
        """M(q), Eq. (8-105): (nv, nv) or (N, nv, nv), kg m² (kg for prismatic rows)."""
        return self._call("mass_matrix", q)

    def coriolis(self, q, qd):
        """C(q, q̇) q̇ = Σ_jk Γ_ijk q̇_j q̇_k (Christoffel form), N m."""
        return self._call("coriolis", q, qd)

    def coriolis_matrix(self, q, qd):
        """Christoffel Coriolis matrix C_ij = Σ_k Γ_ijk q̇_k (then Ṁ − 2C is skew)."""
        return self._call("coriolis_matrix", q, qd)

    def gravity(self, q):
        """g(q) = ∂V/∂q, N m."""
        return self._call("gravity", q)

    def tau(self, q, qd, qdd):
        """Inverse dynamics τ = M q̈ + C q̇ + g (Euler–Lagrange (8-13)), N m."""
        return self._call("tau", q, qd, qdd)

    def kinetic_energy(self, q, qd):
        """T = ½ q̇ᵀ M q̇, J."""
        return self._call("kinetic_energy", q, qd)

    def potential_energy(self, q):
        """V = −Σ m_i gᵀ c_i (world CoM positions; same zero as Pinocchio), J."""
        return self._call("potential_energy", q)

    def momentum(self, q, qd):
        """Generalized momentum p = ∂T/∂q̇ = M q̇."""
        return self._call("momentum", q, qd)

    def forward(self, q, qd, tau):
        """Forward dynamics q̈ = M⁻¹(τ − C q̇ − g) (Cholesky solve), rad/s².

        Raises :class:`~anthroarm.errors.SingularMassMatrixError` (an :class:`InertiaError`,
        so a :class:`ValueError`) naming q, the condition number and the joint that moves least
        when M(q) is singular or its estimated condition number exceeds ``1 / SINGULAR_RCOND``
        (= 1e12: fewer than ~4 significant digits would be left in q̈) — e.g. a point mass on
        the axis of the joint above it.  No regularised answer is returned: there the
        acceleration of that joint is not determined by the model (Pinocchio's ``aba`` returns
        ~1e30 rad/s² without a warning on the same model).  A ``ValueError`` when finite inputs
        give accelerations beyond the float range."""
        M = self.mass_matrix(q)
        rhs = self._arr(tau, "tau") - self.coriolis(q, qd) - self.gravity(q)
        if M.ndim == 3 and rhs.ndim == 1:
            rhs = np.broadcast_to(rhs, (M.shape[0], self.n))
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            L = None
        if L is None or not self._well_conditioned(L):
            self._raise_singular(q, M, L)
        if M.ndim == 2:
            a = _tri_solve(L, rhs)
        else:
            a = np.linalg.solve(M, rhs[..., None])[..., 0]
        if not np.all(np.isfinite(a)):
            raise ValueError(
                f"{self.info.name}: forward dynamics overflows for tau = "
                f"{np.asarray(tau).tolist()} (accelerations beyond the float range); use torques "
                "of a physical size"
            )
        return a

    @staticmethod
    def _well_conditioned(L) -> bool:
        # cond(M) >= (max L_ii / min L_ii)^2: the pivots of the Cholesky factor give a cheap
        # lower bound; the exact value is computed only for the message
        d = np.diagonal(L, axis1=-2, axis2=-1)
        lo, hi = d.min(axis=-1), d.max(axis=-1)
        return bool(np.all(lo * lo > SINGULAR_RCOND * hi * hi))

    def _raise_singular(self, q, M, L):
        q = np.asarray(q, dtype=float)
        Ms, Qs = (
            (M[None], q[None]) if M.ndim == 2 else (M, np.broadcast_to(q, (M.shape[0], self.nq)))
        )
        ev_all = np.linalg.eigvalsh(Ms)
        rc = ev_all[:, 0] / np.maximum(ev_all[:, -1], 1e-300)
        k = int(np.argmin(rc))
        w, V = np.linalg.eigh(Ms[k])
        cond = float("inf") if w[0] <= 0 else float(w[-1] / w[0])
        joint = self.joint_names[int(np.argmax(np.abs(V[:, 0])))]
        where = "" if M.ndim == 2 else f" (batch item {k})"
        raise SingularMassMatrixError(
            f"{self.info.name}: the mass matrix is singular at q = {Qs[k].tolist()}{where}: "
            f"condition number {cond:.3g} (limit {1 / SINGULAR_RCOND:.0e}); joint {joint!r} moves "
            "(almost) no mass or inertia there, so its acceleration is not determined. Give the "
            "links beyond it mass or rotational inertia about that joint's axis, or avoid this "
            "configuration",
            q=Qs[k].copy(),
            cond=cond,
            joint=joint,
        )


def _tri_solve(L, b):
    """x with L Lᵀ x = b (the two solves on the Cholesky factor)."""
    return np.linalg.solve(L.T, np.linalg.solve(L, b))


def load(
    model_or_robot, name: str | None = None, use_cache: bool = True, backend: str = "numpy"
) -> LagrangeDynamics:
    """:class:`LagrangeDynamics` of a Robot / Chain / pin.Model / catalog name / URDF path
    (generated code cached on disk, :mod:`anthroarm.cache`)."""
    return LagrangeDynamics(model_or_robot, name=name, use_cache=use_cache, backend=backend)
