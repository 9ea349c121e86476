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


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a
