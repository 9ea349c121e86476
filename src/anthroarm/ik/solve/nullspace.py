"""Secondary objectives of :func:`anthroarm.ik.solve` in the null space of the task, for
redundant arms: the posture phase (nearest a reference posture) and the swivel phase (the
elbow at a swivel angle).

From a solution θ both iterate Δθ = J⁺e + N s with the damped pseudo-inverse of the kernel
(:func:`~anthroarm.ik.solve.kernel.solve_damped`, its Cholesky factor reused) and the projector
N = I − Jᵀ(JJᵀ + λI)⁻¹J, so the task error stays at zero while the secondary objective moves
(the book's redundancy resolution by a penalty on the configuration, Ch. 7 §7-6 (7-84)–(7-86),
as a projected gradient; Liégeois 1977).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dpotrs

from ..qp.tasks.swivel import swivel_from_points
from .kernel import clip, clock, damping, solve_damped

NULL_TOL = 1e-4  # posture / swivel secondary step norm (rad) under which it has settled
NULL_EXTRA = 60  # extra iterations allowed for the secondary objective
NULL_STEP = 1.0  # longest null-space step (rad)
SECANT_RANGE = (0.1, 10.0)  # accepted curvature estimates of the secant null-space step
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def posture(ws, tg, th, th_ref, deadline):
    """Minimise ½‖θ − θ_ref‖² along the self-motion (null space of the task) from θ (a
    solution, or a closed-form seed) while Gauss–Newton keeps the task error at zero.

    With a one-dimensional null space (a 7-DOF arm on a 6-D pose) the step along the
    self-motion t = Nz/‖Nz‖ is a secant (quasi-Newton) step on the posture cost, which converges
    superlinearly where the projected-gradient step s = θ_ref − θ converges linearly.  A joint at
    its limit that the step would push past it is frozen (its column of J and its share of the
    pull dropped) and the step recomputed: with a one-dimensional self-motion the optimum then
    lies where that joint sits at its limit.  A null-space move that would cross a limit is
    shortened so that the first joint to cross stops on it.  Continuous joints: the pull is the
    wrapped difference (−π, π].

    Returns (θ, pos_err², rot_err², iterations): the last iterate that meets the tolerances and
    its errors, or (None, …) if no iterate did."""
    sh = ws.sh
    m = tg.m
    AF = ws.lin[m][1]
    wrap = sh.continuous if sh.to_q is not None else None
    sec = Secant() if sh.dof - m == 1 else None
    good = None
    gpe2 = gre2 = math.inf
    it = 0
    residual, jacobian = tg.residual, tg.jacobian
    while it < NULL_EXTRA:
        e, E, pe2, re2 = residual(ws, th)
        J = jacobian(ws)
        it += 1
        ok = pe2 <= tg.tp2 and re2 <= tg.tr2
        if ok:
            good, gpe2, gre2 = th, pe2, re2
        elif not it & 3 and clock() > deadline:
            break
        move = _null_move(ws, AF, J, e, damping(E), th, th_ref, wrap, sec)
        if move is None:
            return good, gpe2, gre2, it
        tn, tc, p, g, s, n2 = move
        if ok and n2 < NULL_TOL:
            break
        if s != 0.0:
            clipped = tc.tobytes() != tn.tobytes()
            moved = sec.moved(p, g, p.dot(tc - th) / g if clipped else s)
            if ok and clipped and abs(moved) < 0.1 * n2:
                break  # a joint limit blocks the self-motion: constrained optimum
        elif sec is not None:
            sec.p = None  # the secant memory is void after a frozen step
        th = tc
    else:
        pe, re = tg.errors(ws, th)
        if tg.ok(pe * pe, re * re):
            good, gpe2, gre2 = th, pe * pe, re * re
    return good, gpe2, gre2, it


class Secant:
    """The memory of :func:`posture`'s secant step along a one-dimensional self-motion: the
    last null-space direction ``p`` (unnormalised, oriented like t), its g = tᵀ(θ_ref − θ) (minus
    the derivative of the cost ½‖θ − θ_ref‖² along t = p/‖p‖), the move ``s`` made along t and
    the curvature estimate ``h`` = −Δg/s, kept in :data:`SECANT_RANGE` (1 outside it)."""

    __slots__ = ("p", "g", "s", "h")

    def __init__(self):
        self.p, self.g, self.s, self.h = None, 0.0, 0.0, 1.0

    def length(self, p, g):
        """(g signed along the remembered direction, the step s = g/h along t = p/‖p‖, at most
        :data:`NULL_STEP` long) for the null-space direction ``p`` of norm ``g``."""
        if self.p is not None:
            if p.dot(self.p) < 0.0:
                g = -g
            if abs(self.s) > 1e-12:
                hk = (self.g - g) / self.s
                h_lo, h_hi = SECANT_RANGE
                self.h = min(hk, h_hi) if hk >= h_lo else 1.0
        s = g / self.h
        if abs(s) > NULL_STEP:
            s = math.copysign(NULL_STEP, s)
        return g, s

    def moved(self, p, g, s) -> float:
        """Remember the move ``s`` made along t = p/g (p of signed norm g); returns s."""
        self.p, self.g, self.s = (p if g > 0.0 else -p), g, s
        return s


def _null_move(ws, AF, J, e, lam, th, th_ref, wrap, sec):
    """One move of :func:`posture` from θ: Δθ = Jᵀ(JJᵀ + λI)⁻¹e (the Cholesky factor left in
    ``AF``) plus the pull p = N z, z = θ_ref − θ (wrapped for continuous joints), along p by the
    secant length (``sec``, a one-dimensional self-motion) or by ‖p‖ up to :data:`NULL_STEP`.
    Active set: joints at a limit that the move pushes past it are frozen (their columns of J
    and their share of z dropped) and the move recomputed once; a move that crosses a limit
    otherwise is shortened so that the first joint to cross stops on it (clipping the whole move
    would spoil the pose).

    Returns (θ + move, the same clipped into the limits, p, g = ±‖p‖, s, the move's length
    along p), or None for a singular system."""
    lo, hi = ws.lo, ws.hi
    frozen = None
    while True:
        x = solve_damped(ws, J, e, lam, step=False)  # AF now holds the Cholesky factor
        if x is None:
            return None
        dq = x.dot(J)
        z = th_ref - th  # N (θ_ref − θ − Δθ) = N (θ_ref − θ) + O(λ): Δθ lies in the row space
        if wrap is not None:
            z[wrap] = (z[wrap] + math.pi) % (2.0 * math.pi) - math.pi
        if frozen is not None:
            z[frozen] = 0.0
        p = z - dpotrs(AF, J.dot(z))[0].dot(J)  # N z: projection on the null space
        g = math.sqrt(p.dot(p))
        if sec is not None and frozen is None and g > 0.0:
            g, s = sec.length(p, g)
            n2 = abs(s)
            tn = th + dq + p * (s / g)
        else:
            s, n2 = 0.0, g
            # long moves leave the linearisation
            tn = th + dq + (p if g <= NULL_STEP else p * (NULL_STEP / g))
        tc = clip(tn, lo, hi)
        if frozen is not None or tc.tobytes() == tn.tobytes():
            return tn, tc, p, g, s, n2
        out = (tc != tn) & ((th == lo) | (th == hi))  # at a limit and pushed past it
        if not out.any():
            base = th + dq
            step = tn - th - dq
            sig = _to_limit(base, step, lo, hi)
            tn = base + sig * step
            return tn, clip(tn, lo, hi), p, g, s * sig, n2 * sig
        frozen = out  # active set: freeze, recompute once
        J = J * ~out


def _to_limit(base, step, lo, hi) -> float:
    """min over the joints of the σ at which base + σ·step reaches its limit, clamped to
    [0, 1]: the fraction of ``step`` that keeps every joint within [lo, hi]."""
    with np.errstate(divide="ignore", invalid="ignore"):
        sig = np.where(
            step > 0.0,
            (hi - base) / step,
            np.where(step < 0.0, (lo - base) / step, np.inf),
        )
    return min(max(float(sig.min()), 0.0), 1.0)


class Swivel:
    """Null-space step that moves the elbow swivel angle (:mod:`anthroarm.ik.qp.tasks.swivel`,
    Kreutz-Delgado et al. 1992) to ``target`` (rad); ``ids`` the Pinocchio ids of the
    (shoulder, elbow, wrist) frames."""

    def __init__(self, ids, target: float):
        self.ids = list(ids)
        self.target = target

    def step(self, ws, th, dq1, J, cfac):
        """N jᵀ (φ* − φ − j Δθ₁) / (j N jᵀ): the least null-space move that brings the swivel
        angle φ to its target to first order (j = ∂φ/∂θ, 1 × n); zero for a straight arm."""
        model, data = ws.model, ws.data
        pts = [pin.updateFramePlacement(model, data, i).translation for i in self.ids]
        try:
            phi, grads = swivel_from_points(*pts)
        except ValueError:  # straight arm: the swivel angle is undefined here
            return np.zeros_like(th)
        j = np.zeros(len(th))
        for g, i in zip(grads, self.ids):
            j += g @ pin.getFrameJacobian(model, data, i, LWA)[:3]
        d = self.target - phi
        d = math.atan2(math.sin(d), math.cos(d))
        nj = j - J.T @ dpotrs(cfac, J @ j)[0]  # N jᵀ
        den = float(j @ nj) + 1e-9
        return nj * ((d - float(j @ dq1)) / den)

    def offset(self, ws, th) -> float:
        """|wrapped φ(θ) − φ*| (rad); inf where the swivel angle is undefined (straight arm)."""
        ws.fk(th)
        pts = [ws.data.oMf[i].translation for i in self.ids]
        try:
            phi = swivel_from_points(*pts)[0]
        except ValueError:
            return float("inf")
        d = self.target - phi
        return abs(math.atan2(math.sin(d), math.cos(d)))


def swivel(ws, tg, th, sw: Swivel, deadline):
    """Move in the null space of the task toward the swivel angle, Gauss–Newton corrected (the
    pose error may grow in between and is driven back).  Returns the last iterate that meets
    the tolerances (the phase-1 solution θ if none does) and the iterations used."""
    good = th
    it = 0
    AF = ws.lin[tg.m][1]
    while it < NULL_EXTRA and clock() <= deadline:
        e, E, pe2, re2 = tg.residual(ws, th)
        J = tg.jacobian(ws)
        it += 1
        ok = tg.ok(pe2, re2)
        if ok:
            good = th
        x = solve_damped(ws, J, e, damping(E), step=False)
        if x is None:
            break
        dq = x.dot(J)
        dq2 = sw.step(ws, th, dq, J, AF)
        n2 = math.sqrt(dq2 @ dq2)
        if ok and n2 < NULL_TOL:
            break
        if n2 > NULL_STEP:  # long null-space moves leave the linearisation: shorten them
            dq2 *= NULL_STEP / n2
        th = clip(th + dq + dq2, ws.lo, ws.hi)
    else:
        pe, re = tg.errors(ws, th)
        if tg.ok(pe * pe, re * re):
            good = th
    return good, it
