"""The coupling map of an imported OpenSim model: from the independent coordinates q to the
Pinocchio configuration φ(q), with G = dφ/dq and the velocity-product term Ġq̇.

OpenSim moves a ``CustomJoint`` through six functions of its coordinates, and a
``CoordinateCouplerConstraint`` makes one coordinate a function of another.  The import gives
Pinocchio one joint per transform axis that moves, so the Pinocchio configuration is

    φ_k(q) = f_k(c_k(q)),    c(q): every coordinate, the dependent ones c_d = s · g(c_i)

and by the chain rule, with c' = dc/dq and the second-order term b = (d²c/dt²) − c' q̈,

    G_k = f_k'(c_k) · c'_k,    (Ġq̇)_k = f_k''(c_k) (c'_k q̇)² + f_k'(c_k) · b_k.

Then v = G q̇ and v̇ = G q̈ + Ġq̇ are the Pinocchio velocity and acceleration; a Jacobian is
J G, the mass matrix Gᵀ M G, the generalized forces Gᵀ τ (the principle of virtual work:
δφ = G δq), as in Jain, *Robot and Multibody Dynamics* (2011), §8 (constrained and
projected dynamics) and Seth et al., *OpenSim: Simulating musculoskeletal dynamics and
neuromuscular control to study human and animal movement*, PLoS Comput Biol (2018).
"""

from __future__ import annotations

from bisect import bisect_left
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Step:
    """c[target] = scale · function(c[source])."""

    target: int
    source: int
    function: object
    scale: float = 1.0


class Coupling:
    """φ(q), G(q) and Ġq̇ of an imported OpenSim model (see the module docstring).

    Attributes
    ----------
    names : tuple of str
        The independent coordinates, in q order.
    coordinates : tuple of str
        Every coordinate of the model (dependent ones included).
    nq, nq_full : int
        len(names) and the Pinocchio model's nq.
    lower, upper, default : ndarray
        The independent coordinates' ranges and default values (rad or m).
    """

    def __init__(
        self,
        names,
        coordinates,
        independent,
        dependent_steps,
        joint_steps,
        nq_full,
        lower,
        upper,
        default,
        joint_names,
    ):
        self.names = tuple(names)
        self.coordinates = tuple(coordinates)
        self.independent = np.asarray(independent, dtype=np.int64)  # q index -> coordinate index
        self.dependent_steps = tuple(dependent_steps)  # Step over coordinate indices
        self.joint_steps = tuple(joint_steps)  # Step: target = Pinocchio q index
        self.nq = len(self.names)
        self.nq_full = int(nq_full)
        self.lower = _frozen(lower)
        self.upper = _frozen(upper)
        self.default = _frozen(default)
        self.joint_names = tuple(joint_names)  # Pinocchio joint name per q index

    def __repr__(self) -> str:
        return f"Coupling({self.nq} coordinates -> {self.nq_full} joints)"

    def coordinate_values(self, q) -> np.ndarray:
        """Every coordinate's value (dependent ones from their couplers), ``(..., ncoords)``."""
        return self._run(np.asarray(q, dtype=float), None, order=0)[0]

    def full(self, q) -> np.ndarray:
        """φ(q): the Pinocchio configuration, ``(nq,)`` → ``(nq_full,)``, ``(N, nq)`` →
        ``(N, nq_full)``."""
        return self._run(np.asarray(q, dtype=float), None, order=0)[1]

    def jacobian(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(φ(q), G(q) = dφ/dq): ``(..., nq_full)`` and ``(..., nq_full, nq)``."""
        _, phi, G, _ = self._run(np.asarray(q, dtype=float), None, order=1)
        return phi, G

    def second(self, q, qd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(φ, G, Ġq̇) at ``(q, q̇)``."""
        _, phi, G, b = self._run(np.asarray(q, dtype=float), np.asarray(qd, dtype=float), 2)
        return phi, G, b

    # ------------------------------------------------------------------
    def _run(self, q, qd, order):
        one = q.ndim == 1
        q2 = q.reshape(1, -1) if one else q.reshape(-1, q.shape[-1])
        n, nc = q2.shape[0], len(self.coordinates)
        c = np.zeros((n, nc))
        c[:, self.independent] = q2
        dc = db = None
        if order >= 1:
            dc = np.zeros((n, nc, self.nq))
            dc[:, self.independent, np.arange(self.nq)] = 1.0
        if order >= 2:
            qd2 = qd.reshape(n, self.nq)
            db = np.zeros((n, nc))
        for s in self.dependent_steps:
            f, f1, f2 = s.function.eval(c[:, s.source])
            c[:, s.target] = s.scale * f
            if order >= 1:
                if order >= 2:
                    rate = np.einsum("ij,ij->i", dc[:, s.source], qd2)
                    db[:, s.target] = s.scale * (f2 * rate * rate + f1 * db[:, s.source])
                dc[:, s.target] = (s.scale * f1)[:, None] * dc[:, s.source]
        phi = np.zeros((n, self.nq_full))
        G = b = None
        if order >= 1:
            G = np.zeros((n, self.nq_full, self.nq))
        if order >= 2:
            b = np.zeros((n, self.nq_full))
        for s in self.joint_steps:
            f, f1, f2 = s.function.eval(c[:, s.source])
            phi[:, s.target] = s.scale * f
            if order >= 1:
                G[:, s.target] = (s.scale * f1)[:, None] * dc[:, s.source]
            if order >= 2:
                rate = np.einsum("ij,ij->i", dc[:, s.source], qd2)
                b[:, s.target] = s.scale * (f2 * rate * rate + f1 * db[:, s.source])
        lead = q.shape[:-1]
        c = c.reshape(lead + (nc,))
        phi = phi.reshape(lead + (self.nq_full,))
        if G is not None:
            G = G.reshape(lead + (self.nq_full, self.nq))
        if b is not None:
            b = b.reshape(lead + (self.nq_full,))
        return c, phi, G, b


class FastCoupling:
    """φ(q) and G = dφ/dq of one configuration, the first-order part of
    :meth:`anthroarm.osim.coupling.Coupling.jacobian` without its batch bookkeeping: the
    steps whose function is the identity (``function.identity``: most transform axes) are
    copied as arrays, the others (splines, scaled axes, couplers) call their function's
    ``eval`` (the one implementation of OpenSim's functions).  Tested equal to
    ``Coupling.jacobian`` (tests/osim_recordings).  Used by the marker IK
    (:mod:`anthroarm.motion.osim_ik`), ``aa.ik.solve`` and the QP layer on a coupled model."""

    def __init__(self, coupling):
        self.coupling = coupling
        self.nq, self.nq_full = coupling.nq, coupling.nq_full
        self.nc = len(coupling.coordinates)
        self.independent = np.asarray(coupling.independent, dtype=int)
        self.dependent = tuple(coupling.dependent_steps)
        ident = [s for s in coupling.joint_steps if s.function.identity]
        self.other = tuple(s for s in coupling.joint_steps if not s.function.identity)
        self.id_target = np.array([s.target for s in ident], dtype=int)
        self.id_source = np.array([s.source for s in ident], dtype=int)
        self.id_scale = np.array([s.scale for s in ident], dtype=float)
        self.linear = None
        if not self.dependent:  # every source is an independent coordinate: φ = A q + splines
            self.q_of = {int(c): i for i, c in enumerate(self.independent)}
            A = np.zeros((self.nq_full, self.nq))
            for t, src, sc in zip(self.id_target, self.id_source, self.id_scale):
                A[t, self.q_of[int(src)]] = sc
            self.linear = A
            # (Pinocchio q index, coordinate's q index, scale, function) of the other steps; their
            # rows of A are zero, so G's row is the one entry set per call
            self.scalar_steps = tuple(
                (int(st.target), self.q_of[int(st.source)], float(st.scale), st.function)
                for st in self.other
            )

    def jacobian(self, q) -> tuple[np.ndarray, np.ndarray]:
        """(φ(q) (nq_full,), G (nq_full, nq)) for one configuration ``q`` (nq,)."""
        c = np.zeros(self.nc)
        c[self.independent] = q
        dc = np.zeros((self.nc, self.nq))
        dc[self.independent, np.arange(self.nq)] = 1.0
        for s in self.dependent:
            f, f1, _ = s.function.eval(c[s.source : s.source + 1])
            c[s.target] = s.scale * f[0]
            dc[s.target] = (s.scale * f1[0]) * dc[s.source]
        if self.linear is not None:  # no couplers: the identity steps are one matrix
            phi = self.linear @ q
            G = self.linear.copy()
            for t, i, sc, fn in self.scalar_steps:
                f, f1 = _value_slope(fn, float(q[i]))
                phi[t] = sc * f
                G[t, i] = sc * f1
            return phi, G
        phi = np.zeros(self.nq_full)
        G = np.zeros((self.nq_full, self.nq))
        phi[self.id_target] = self.id_scale * c[self.id_source]
        G[self.id_target] = self.id_scale[:, None] * dc[self.id_source]
        for s in self.other:
            f, f1 = _value_slope(s.function, float(c[s.source]))
            phi[s.target] = s.scale * f
            G[s.target] = (s.scale * f1) * dc[s.source]
        return phi, G


def _value_slope(function, x: float) -> tuple[float, float]:
    """(f(x), f'(x)) of one of OpenSim's functions at the number ``x``.  A ``MultiplierFunction``
    is its factor times its inner function's; a ``SimmSpline``
    strictly inside its knots (and 1e-12 away from them) is evaluated here as the cubic of its
    interval from the spline's own coefficients ``b, c, d`` (what its ``eval`` computes
    there, without the array bookkeeping: 5 µs instead of 60); anything else, and the ends,
    by the function's ``eval``."""
    kind = getattr(function, "kind", "")
    if kind == "MultiplierFunction":  # scale · inner(x)
        f, f1 = _value_slope(function.inner, x)
        return function.scale * f, function.scale * f1
    if kind == "SimmSpline":
        xs = function.x
        if xs[0] + 1e-12 < x < xs[-1] - 1e-12:
            k = bisect_left(xs, x) - 1
            dx = x - xs[k]
            b, cc, d = function.b[k], function.c[k], function.d[k]
            return (
                function.y[k] + dx * (b + dx * (cc + dx * d)),
                b + dx * (2.0 * cc + 3.0 * dx * d),
            )
    f, f1, _ = function.eval(np.array([x]))
    return float(f[0]), float(f1[0])


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a
