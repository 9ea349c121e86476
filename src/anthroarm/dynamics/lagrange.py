r"""Lagrange equations of a serial (or tree) arm: symbolic derivation and generated code.

Book Ch. 8 §8-1.  For generalized coordinates q (joint angles, rad; prismatic joints, m) the
Lagrange equations (8-8)/(8-13)

.. math::  \frac{d}{dt}\frac{\partial L}{\partial\dot q}-\frac{\partial L}{\partial q}=\tau,
           \qquad L = T(q,\dot q) - V(q)

with :math:`T=\tfrac12\dot q^T M(q)\dot q` give

.. math::  \tau = M(q)\ddot q + C(q,\dot q)\dot q + g(q),\quad
           (C\dot q)_i=\sum_{jk}\Gamma_{ijk}\dot q_j\dot q_k,\quad
           \Gamma_{ijk}=\tfrac12\Big(\frac{\partial M_{ij}}{\partial q_k}+\frac{\partial M_{ik}}{\partial q_j}-\frac{\partial M_{jk}}{\partial q_i}\Big),
           \quad g=\frac{\partial V}{\partial q}.

**Derivation.**  :func:`derive` reads a Pinocchio model (joint placements, joint axes, link
inertias, gravity) and writes T and V as exact expressions of ``s_k = sin q_k``,
``c_k = cos q_k`` (prismatic: ``q_k``) and ``qd_k``, following the recursive link velocities
(each link's twist in its own frame, the form of Eq. (8-27)):

    ω_i = Rᵢᵀ ω_λ + a_i q̇_i,   v_i = Rᵢᵀ (v_λ + ω_λ × p_i) (+ a_i q̇_i for a prismatic joint),
    T = Σ ½ m_i |v_i + ω_i × c_i|² + ½ ω_iᵀ I_i ω_i                                  (8-24)
    V = -Σ m_i gᵀ (p_i⁰ + R_i⁰ c_i)                                                  (8-106)

where ``R_i, p_i`` is the placement of joint i in its parent's frame times the joint motion,
``c_i`` the centre of mass and ``I_i`` the rotational inertia about it (link frame, SI).  The
expressions live in a hash-consed graph (:mod:`._graph`): exact symbolic algebra in which
equal subexpressions are shared, so the derivation of a 7-DOF arm takes well under a second
instead of the minutes a fully expanded sympy expression needs.  From T and V, by exact
symbolic differentiation only:

* momentum p = ∂T/∂q̇ (reverse-mode differentiation of T),
* M = ∂p/∂q̇ (the Hessian ∂²T/∂q̇², Eq. (8-105)),
* g = ∂V/∂q,
* C q̇ = Ṁ q̇ − ∂T/∂q = Σ Γ_ijk q̇_j q̇_k (the Christoffel contraction: Ṁq̇ = Σ_jk ∂_k M_ij q̇_j q̇_k
  and ∂T/∂q_i = ½ Σ_jk ∂_i M_jk q̇_j q̇_k, so their difference is exactly Σ Γ_ijk q̇_j q̇_k),
* the Christoffel matrix C_ij = Σ_k Γ_ijk q̇_k = ½(Ṁ_ij + ∂p_i/∂q_j − ∂p_j/∂q_i),
* τ = d/dt(∂T/∂q̇) − ∂T/∂q + ∂V/∂q, the Euler–Lagrange equation itself.

The explicit Christoffel symbols and fully written-out sympy matrices are available for small
models (:func:`sympy_matrices`, :func:`christoffel`, :func:`latex`).

**Generated code.**  The outputs are printed as straight-line numpy code (one line per graph
node: common subexpressions appear once), vectorised over a batch ``(N, nq)``, plus a scalar
variant for single calls; optionally C compiled with the system compiler
(``backend="c"``).  The code is cached on disk under ``$ANTHROARM_CACHE`` (default
``~/.cache/anthroarm``) keyed by a hash of the model's dynamic parameters, written
atomically (deriving and generating the code of a 7-DOF arm takes ~0.1 s, so nothing needs to
ship pre-generated).

>>> import anthroarm as aa
>>> from anthroarm.dynamics import lagrange
>>> dyn = lagrange.load(aa.load("planar2r"))
>>> M = dyn.mass_matrix([0.1, 0.2])              # (2, 2), kg m^2
"""

from __future__ import annotations

import hashlib
import math
import importlib.util
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InertiaError, UnsupportedModelError
from ..codegen.graph import Graph, emit_python, snap

#: bump when the generated code changes (part of the cache key)
GENERATOR_VERSION = "1"


_AXES = {"x": 0, "y": 1, "z": 2}


# ====================================================================== model description
@dataclass
class JointInfo:
    """One 1-DOF joint of the chain, read from the Pinocchio model (SI units).

    ``R0, p0``: placement of the joint frame in the parent joint's frame (at q = 0);
    ``axis``: unit joint axis in the joint frame; ``kind``: "R" revolute or "P" prismatic;
    ``mass, com, inertia``: link inertia in the joint frame (inertia about the CoM)."""

    name: str
    parent: int  # index into the joint list, -1 = base
    kind: str
    axis: np.ndarray
    R0: np.ndarray
    p0: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass
class ChainInfo:
    name: str
    joints: list[JointInfo]
    gravity: np.ndarray

    @property
    def n(self) -> int:
        return len(self.joints)

    def key(self) -> str:
        """Hash of everything the equations depend on (exact float bits)."""
        h = hashlib.sha256()
        h.update(f"lagrange-v{GENERATOR_VERSION}|".encode())
        h.update(np.asarray(self.gravity, float).tobytes())
        for j in self.joints:
            h.update(f"|{j.parent}|{j.kind}|".encode())
            for a in (j.axis, j.R0, j.p0, np.array([j.mass]), j.com, j.inertia):
                h.update(np.ascontiguousarray(a, dtype=float).tobytes())
        return h.hexdigest()[:20]


def chain_info(model, name: str | None = None) -> ChainInfo:
    """Extract joints, axes, placements and inertias from a ``pin.Model``.

    Raises :class:`UnsupportedModelError` for joints that are not 1-DOF revolute/prismatic
    (free-flyer, spherical, planar, unbounded revolute with nq = 2, helical...) and
    :class:`InertiaError` for negative masses, non-symmetric or indefinite inertia tensors and
    massless chains."""
    import pinocchio as pin

    name = name or getattr(model, "name", "model")
    data = model.createData()
    q0 = pin.neutral(model)
    pin.forwardKinematics(model, data, q0)
    joints: list[JointInfo] = []
    for jid in range(1, model.njoints):
        jm = model.joints[jid]
        jname = model.names[jid]
        short = jm.shortname()
        if jm.nq != 1 or jm.nv != 1:
            raise UnsupportedModelError(
                f"{name}: joint {jname!r} is {short} (nq={jm.nq}, nv={jm.nv}); the symbolic Lagrange "
                "engine supports 1-DOF revolute and prismatic joints only (no free-flyer, spherical, "
                "planar or unbounded joints)")
        if "Mimic" in short or "Helical" in short or "Universal" in short:
            raise UnsupportedModelError(f"{name}: joint {jname!r} of type {short} is not supported")
        S = np.asarray(data.joints[jid].S).reshape(6)
        lin, ang = S[:3], S[3:]
        if np.linalg.norm(ang) > 1e-12 and np.linalg.norm(lin) < 1e-12:
            kind, axis = "R", ang
        elif np.linalg.norm(lin) > 1e-12 and np.linalg.norm(ang) < 1e-12:
            kind, axis = "P", lin
        else:
            raise UnsupportedModelError(f"{name}: joint {jname!r} ({short}) is neither revolute nor prismatic")
        axis = np.array([snap(a) for a in axis / np.linalg.norm(axis)])
        pl = model.jointPlacements[jid]
        Y = model.inertias[jid]
        m = float(Y.mass)
        c = np.array(Y.lever, dtype=float)
        Ic = np.array(Y.inertia, dtype=float)
        label = f"{name}: link of joint {jname!r}"
        if not np.isfinite(m) or m < 0:
            raise InertiaError(f"{label} has mass {m}; masses must be finite and >= 0 kg")
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(Ic))):
            raise InertiaError(f"{label} has a non-finite centre of mass or inertia")
        if np.max(np.abs(Ic - Ic.T)) > 1e-9 * max(1.0, np.max(np.abs(Ic))):
            raise InertiaError(f"{label} has a non-symmetric inertia tensor {Ic.tolist()}")
        ev = np.linalg.eigvalsh(0.5 * (Ic + Ic.T))
        scale = max(float(np.max(np.abs(ev))), 1e-300)
        if ev[0] < -1e-9 * scale:
            raise InertiaError(
                f"{label} has an inertia tensor that is not positive (semi)definite: eigenvalues {ev.tolist()} kg m^2")
        if m == 0 and np.max(np.abs(Ic)) > 0:
            raise InertiaError(f"{label} has zero mass but a non-zero rotational inertia")
        joints.append(JointInfo(
            name=jname, parent=int(model.parents[jid]) - 1, kind=kind, axis=axis,
            R0=np.array(pl.rotation, dtype=float), p0=np.array(pl.translation, dtype=float),
            mass=m, com=c, inertia=0.5 * (Ic + Ic.T)))
    if not joints:
        raise UnsupportedModelError(f"{name}: the model has no joints")
    if all(j.mass == 0 for j in joints):
        raise InertiaError(f"{name}: massless chain (every link has zero mass); M(q) would be zero")
    return ChainInfo(name=name, joints=joints, gravity=np.array(model.gravity.linear, dtype=float))


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
    return [g.add(g.mul(u[1], v[2]), g.mul(-1.0, g.mul(u[2], v[1]))),
            g.add(g.mul(u[2], v[0]), g.mul(-1.0, g.mul(u[0], v[2]))),
            g.add(g.mul(u[0], v[1]), g.mul(-1.0, g.mul(u[1], v[0])))]


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

    ``model_or_robot``: an :class:`anthroarm.Robot`, a ``pin.Model`` or a :class:`ChainInfo`.
    """
    t0 = time.perf_counter()
    info = _as_info(model_or_robot, name)
    n = info.n
    g = Graph()
    s = [None] * n
    c = [None] * n
    qv = [None] * n
    for k, j in enumerate(info.joints):
        if j.kind == "R":
            s[k], c[k] = g.input("s", k), g.input("c", k)
        else:
            qv[k] = g.input("q", k)
    qd = [g.input("qd", k) for k in range(n)]
    qdd = [g.input("qdd", k) for k in range(n)]
    grav = [snap(x) for x in info.gravity]

    w = [None] * n  # angular velocity of link k, link frame
    v = [None] * n  # linear velocity of the link-frame origin, link frame
    gam = [None] * n  # gravity vector in link frame
    h = [None] * n  # gᵀ p_k (world), the "height" of the link origin times |g|
    T_terms, V_terms = [], []
    for k, j in enumerate(info.joints):
        if j.parent >= 0:
            wl, vl, gl, hl = w[j.parent], v[j.parent], gam[j.parent], h[j.parent]
        else:
            wl, vl, gl, hl = [0.0] * 3, [0.0] * 3, grav, 0.0
        p0 = [snap(x) for x in j.p0]
        R0 = j.R0
        # position of the joint origin in the parent frame (prismatic joints move it)
        if j.kind == "P":
            ax0 = [snap(x) for x in R0 @ j.axis]
            p = [g.add(p0[i], g.mul(ax0[i], qv[k])) for i in range(3)]
        else:
            p = p0
        vt = [g.add(vl[i], x) for i, x in enumerate(_cross_c(wl, p, g))]
        hk = g.add(hl, _dot(gl, p, g))
        wk = _matT_vec(R0, wl, g)
        vk = _matT_vec(R0, vt, g)
        gk = _matT_vec(R0, gl, g)
        if j.kind == "R":
            wk = _rot_T(j.axis, s[k], c[k], wk, g)
            vk = _rot_T(j.axis, s[k], c[k], vk, g)
            gk = _rot_T(j.axis, s[k], c[k], gk, g)
            wk = [g.add(wk[i], g.mul(snap(j.axis[i]), qd[k])) for i in range(3)]
        else:
            vk = [g.add(vk[i], g.mul(snap(j.axis[i]), qd[k])) for i in range(3)]
        w[k], v[k], gam[k], h[k] = wk, vk, gk, hk
        if j.mass > 0:
            m = j.mass
            cm = [snap(x) for x in j.com]
            vc = [g.add(vk[i], x) for i, x in enumerate(_cross_c(wk, cm, g))]
            I = j.inertia
            quad = g.sum([g.mul(snap(I[0, 0]), g.mul(wk[0], wk[0])), g.mul(snap(I[1, 1]), g.mul(wk[1], wk[1])),
                          g.mul(snap(I[2, 2]), g.mul(wk[2], wk[2])),
                          g.mul(2 * snap(I[0, 1]), g.mul(wk[0], wk[1])), g.mul(2 * snap(I[0, 2]), g.mul(wk[0], wk[2])),
                          g.mul(2 * snap(I[1, 2]), g.mul(wk[1], wk[2]))])
            T_terms.append(g.add(g.mul(0.5 * m, _dot(vc, vc, g)), g.mul(0.5, quad)))  # (8-24)
            V_terms.append(g.mul(-m, g.add(hk, _dot(gk, cm, g))))  # (8-106)
    T = g.sum(T_terms)
    V = g.sum(V_terms)

    def grad_q(adj):
        out = []
        for k, j in enumerate(info.joints):
            if j.kind == "R":
                a_s, a_c = adj.get(s[k].i, 0.0), adj.get(c[k].i, 0.0)
                # d/dq f(sin q, cos q) = f_s cos q - f_c sin q
                out.append(g.add(g.mul(a_s, c[k]), g.mul(-1.0, g.mul(a_c, s[k]))))
            else:
                out.append(adj.get(qv[k].i, 0.0))
        return out

    adjT = g.reverse(T)
    p = [adjT.get(qd[k].i, 0.0) for k in range(n)]
    dTdq = grad_q(adjT)
    gvec = grad_q(g.reverse(V))
    # M = ∂p/∂q̇ (column by column, keep j <= k and mirror)
    M = [[0.0] * n for _ in range(n)]
    for k in range(n):
        col = g.forward(p, {qd[k]: 1.0})
        for jj in range(k + 1):
            M[jj][k] = col[jj]
            M[k][jj] = col[jj]
    # time derivative along q only (q̈ = 0): d/dt s = c q̇, d/dt c = -s q̇
    qseed = {}
    for k, j in enumerate(info.joints):
        if j.kind == "R":
            qseed[s[k]] = g.mul(c[k], qd[k])
            qseed[c[k]] = g.mul(-1.0, g.mul(s[k], qd[k]))
        else:
            qseed[qv[k]] = qd[k]
    Mdot_qd = g.forward(p, qseed)  # Ṁ q̇
    Cqd = [g.add(Mdot_qd[i], g.mul(-1.0, dTdq[i])) for i in range(n)]
    full = dict(qseed)
    full.update({qd[k]: qdd[k] for k in range(n)})
    dpdt = g.forward(p, full)  # d/dt ∂T/∂q̇ = M q̈ + Ṁ q̇
    tau = [g.sum([dpdt[i], g.mul(-1.0, dTdq[i]), gvec[i]]) for i in range(n)]  # (8-13) with V
    Cmat = None
    if coriolis_matrix:
        Mflat = [M[a][b] for a in range(n) for b in range(n)]
        Mdot = g.forward(Mflat, qseed)
        dp = []  # dp[j][i] = ∂p_i/∂q_j
        for k, j in enumerate(info.joints):
            if j.kind == "R":
                seed = {s[k]: c[k], c[k]: g.mul(-1.0, s[k])}
            else:
                seed = {qv[k]: 1.0}
            dp.append(g.forward(p, seed))
        Cmat = [[g.mul(0.5, g.sum([Mdot[a * n + b], dp[b][a], g.mul(-1.0, dp[a][b])])) for b in range(n)]
                for a in range(n)]
    d = Derivation(info=info, graph=g, T=T, V=V, p=p, dTdq=dTdq, g=gvec, M=M, Cqd=Cqd, tau=tau, Cmat=Cmat,
                   inputs={"s": s, "c": c, "q": qv, "qd": qd, "qdd": qdd})
    d.seconds = time.perf_counter() - t0
    return d


def _as_info(obj, name=None) -> ChainInfo:
    """ChainInfo of a ChainInfo, a Robot, a ``pin.Model``, or a catalog name / URDF path."""
    import pinocchio as pin

    if isinstance(obj, ChainInfo):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        from ..robot import load as load_robot

        obj = load_robot(obj)
    if hasattr(obj, "model") and hasattr(obj, "joint_names"):  # Robot
        return chain_info(obj.model, name or obj.name)
    if not isinstance(obj, pin.Model):
        raise UnsupportedModelError(f"Lagrange dynamics need a Robot, a pin.Model or a catalog name, got {type(obj).__name__}")
    return chain_info(obj, name)


# ====================================================================== code generation
#: function name -> (arguments, outputs attribute, output shape kind)
FUNCTIONS = ("mass_matrix", "coriolis", "gravity", "tau", "kinetic_energy", "potential_energy",
             "momentum", "coriolis_matrix")


def _outputs(d: Derivation) -> dict:
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
        out["coriolis_matrix"] = (("q", "qd"), [d.Cmat[a][b] for a in range(n) for b in range(n)], (n, n))
    return out


def generate_python(d: Derivation) -> str:
    """Python module text with numpy (batched) and scalar versions of every function."""
    kinds = [j.kind for j in d.info.joints]
    head = [
        f'"""Generated by anthroarm.dynamics.lagrange (generator v{GENERATOR_VERSION}); do not edit.',
        "",
        f"Model {d.info.name!r}, key {d.info.key()}, {d.n} joints ({''.join(kinds)}).",
        "Lagrange equations tau = M(q) qdd + C(q, qd) qd + g(q) in SI units; see lagrange.py.",
        '"""',
        "from math import sin as _ssin, cos as _scos",
        "import numpy as _np",
        "",
        f"NQ = {d.n}",
        f"KEY = {d.info.key()!r}",
        f"KINDS = {''.join(kinds)!r}",
        f"GENERATOR_VERSION = {GENERATOR_VERSION!r}",
        "",
    ]
    body = []
    for fname, (args, outs, shape) in _outputs(d).items():
        body.append(emit_python(d.graph, fname, args, outs, shape, kinds, batched=True))
        body.append(emit_python(d.graph, fname + "_1", args, outs, shape, kinds, batched=False))
    return "\n".join(head) + "\n" + "\n\n".join(body) + "\n"


# ====================================================================== cache
def cache_dir() -> Path:
    """``$ANTHROARM_CACHE/lagrange`` or ``~/.cache/anthroarm/lagrange``."""
    from .._cbuild import cache_dir as _cache_dir

    return _cache_dir("lagrange")


def _atomic_write(path: Path, text: str | bytes) -> None:
    """Create the cache folder if needed, then :func:`anthroarm.urdf_io.atomic_write_text`."""
    from ..urdf_io import atomic_write_text

    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, text)


def _import_file(path: Path, modname: str):
    spec = importlib.util.spec_from_file_location(modname, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_LOCK = threading.Lock()
_MEMO: dict[str, object] = {}


def generated_module(model_or_robot, name: str | None = None, use_cache: bool = True):
    """The generated Python module of a model: from memory, the disk
    cache, or a fresh derivation (written to the cache).  Returns ``(module, source)`` where
    source is "memory", "cache" or "derived".  Raises :class:`InertiaError` if M(q) is not
    positive definite (a joint that moves no mass)."""
    info = _as_info(model_or_robot, name)
    key = info.key()
    with _LOCK:
        if key in _MEMO:
            return _MEMO[key], "memory"
        modname = f"anthroarm_lagrange_{key}"
        cached = cache_dir() / f"lagrange_{key}.py"
        mod = None
        if use_cache and cached.is_file():
            try:
                mod, src = _import_file(cached, modname), "cache"
                if getattr(mod, "KEY", None) != key or getattr(mod, "GENERATOR_VERSION", None) != GENERATOR_VERSION:
                    mod = None
            except Exception:  # a corrupt or foreign file: derive again and overwrite it
                mod = None
        if mod is None:
            mod, src = _derive_and_store(info, cached, modname, use_cache), "derived"
        _check_pd(mod, info)
        _MEMO[key] = mod
        return mod, src


def _check_pd(mod, info: ChainInfo) -> None:
    """M(q) must be positive definite: at q = 0 and at two random configurations."""
    rng = np.random.default_rng(12345)
    Q = np.vstack([np.zeros(info.n), rng.uniform(-np.pi, np.pi, (2, info.n))])
    for q in Q:
        M = mod.mass_matrix_1(q)
        ev = np.linalg.eigvalsh(M)
        if not ev[0] > 1e-12 * max(ev[-1], 1e-300):
            weak = int(np.argmin(np.diag(M)))
            raise InertiaError(
                f"{info.name}: the mass matrix is not positive definite at q = {np.round(q, 3).tolist()} "
                f"(eigenvalues {ev.tolist()}); joint {info.joints[weak].name!r} moves (almost) no mass or "
                "inertia — a massless chain or zero inertia has no forward dynamics")


def _derive_and_store(info, path: Path, modname: str, write: bool):
    text = generate_python(derive(info))
    if write:
        try:
            _atomic_write(path, text)
            return _import_file(path, modname)
        except OSError:
            pass
    ns: dict = {"__name__": modname}
    exec(compile(text, f"<{modname}>", "exec"), ns)
    import types

    mod = types.ModuleType(modname)
    mod.__dict__.update(ns)
    return mod


# ====================================================================== user-facing object
class LagrangeDynamics:
    """Numeric Lagrange dynamics of one model, from generated code.

    Every method accepts one state ``(nq,)`` or a batch ``(N, nq)`` (then returns a leading
    ``N`` axis).  SI units: q in rad (m for prismatic joints), torques in N m (N)."""

    def __init__(self, model_or_robot, name: str | None = None, use_cache: bool = True, backend: str = "numpy"):
        self.info = _as_info(model_or_robot, name)
        self.n = self.info.n
        self.joint_names = [j.name for j in self.info.joints]
        self.module, self.source = generated_module(self.info, use_cache=use_cache)
        self.backend = backend
        self._c = None
        if backend == "c":
            from .ccode import compiled

            self._c = compiled(self.info)
        elif backend != "numpy":
            raise ValueError(f"backend must be 'numpy' or 'c', got {backend!r}")

    def __repr__(self) -> str:
        return f"LagrangeDynamics({self.info.name!r}, n={self.n}, backend={self.backend!r}, from {self.source})"

    # -- input checking
    def _arr(self, x, what: str):
        a = np.asarray(x, dtype=float)
        if a.ndim not in (1, 2) or a.shape[-1] != self.n:
            raise ValueError(f"{self.info.name}: {what} must have shape ({self.n},) or (N, {self.n}), got {a.shape}")
        if not np.all(np.isfinite(a)):
            bad = np.argwhere(~np.isfinite(a))[0]
            j = int(bad[-1])
            raise ValueError(f"{self.info.name}: {what}[{j}] (joint {self.joint_names[j]!r}) is {a[tuple(bad)]}; "
                             "states must be finite")
        return a

    def _call(self, fname, *arrays):
        # fast path: one state, contiguous float64 vectors of the right length
        n = self.n
        ok = True
        tot = 0.0
        for a in arrays:
            if type(a) is not np.ndarray or a.shape != (n,) or a.dtype != np.float64:
                ok = False
                break
            tot += a.sum()
        if ok and math.isfinite(tot):
            if self._c is not None:
                return self._c.one(fname, arrays)
            return getattr(self.module, fname + "_1")(*arrays)
        names = ("q", "qd", "qdd")
        arrs = [self._arr(a, names[i]) for i, a in enumerate(arrays)]
        single = all(a.ndim == 1 for a in arrs)
        if not single:
            N = max(a.shape[0] if a.ndim == 2 else 1 for a in arrs)
            arrs = [np.broadcast_to(a, (N, self.n)) if a.ndim == 1 else a for a in arrs]
            if any(a.shape[0] != N for a in arrs):
                raise ValueError(f"{self.info.name}: batch sizes differ: {[a.shape for a in arrs]}")
        if self._c is not None:
            return self._c(fname, arrs, single)
        if single:
            return getattr(self.module, fname + "_1")(*arrs)
        return getattr(self.module, fname)(*[np.ascontiguousarray(a) for a in arrs])

    def mass_matrix(self, q):
        """M(q), Eq. (8-105): (n, n) or (N, n, n), kg m² (kg for prismatic rows)."""
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
        """Forward dynamics q̈ = M⁻¹(τ − C q̇ − g) (Cholesky solve), rad/s²."""
        M = self.mass_matrix(q)
        rhs = self._arr(tau, "tau") - self.coriolis(q, qd) - self.gravity(q)
        if M.ndim == 2:
            L = np.linalg.cholesky(M)
            return np.linalg.solve(L.T, np.linalg.solve(L, rhs))
        if rhs.ndim == 1:
            rhs = np.broadcast_to(rhs, (M.shape[0], self.n))
        return np.linalg.solve(M, rhs[..., None])[..., 0]


def load(model_or_robot, name: str | None = None, use_cache: bool = True, backend: str = "numpy") -> LagrangeDynamics:
    """:class:`LagrangeDynamics` of a Robot / pin.Model (derivation cached on disk)."""
    return LagrangeDynamics(model_or_robot, name=name, use_cache=use_cache, backend=backend)


# ====================================================================== sympy / LaTeX view
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


def sympy_matrices(d: Derivation, which=("T", "V", "M", "Cqd", "g"), simplify: bool = True, max_ops: int = 300) -> dict:
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
            raise ValueError(f"unknown quantity {w!r}; choose from T, V, M, Cqd, C, g, tau, p, dTdq")
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
    return [[[sp.Rational(1, 2) * (dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) for k in range(n)] for j in range(n)]
            for i in range(n)]


def latex(d: Derivation, simplify: bool = True, max_ops: int = 300, which=("T", "V", "M", "Cqd", "g")) -> str:
    """LaTeX of the Lagrange equations ``τ = M(q) q̈ + C(q,q̇) q̇ + g(q)`` with each quantity
    written out (see :func:`sympy_matrices` for ``simplify``/``max_ops``)."""
    import sympy as sp

    mats = sympy_matrices(d, which=which, simplify=simplify, max_ops=max_ops)
    names = {"T": "T", "V": "V", "M": "M(q)", "Cqd": r"C(q,\dot q)\,\dot q", "C": r"C(q,\dot q)", "g": "g(q)",
             "tau": r"\tau", "p": r"\partial T/\partial\dot q", "dTdq": r"\partial T/\partial q"}
    parts = [r"\tau = M(q)\,\ddot q + C(q,\dot q)\,\dot q + g(q)"]
    for k, v in mats.items():
        parts.append(f"{names[k]} = {sp.latex(v)}")
    return r"\begin{aligned}" + r"\\ ".join(p.replace("=", "&=", 1) for p in parts) + r"\end{aligned}"
