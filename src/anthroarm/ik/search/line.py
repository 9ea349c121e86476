"""The 1-D search of one pose: the grid, the finer looks where roots fold or jump, and the Newton
seeds next to a fold (:func:`_search_1d_pose`)."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..classes import search_assemble as _assemble
from ..vec3 import mv, sub
from .brackets import _brackets, _interval, _nearest, _sample
from .constants import _DEPTH, _JUMP, _MAX_SEEDS, _POLISH_1D, _SEED, _SUB
from .dips import _dips
from .polish import _push, polish, workspace


@kernel
def _copy_sample(RS, ES, CS, i, RD, ED, CD, j):
    """Copy sample ``i`` of RS, ES, CS into slot ``j`` of RD, ED, CD."""
    CD[j] = CS[i]
    for r in range(4):
        ED[j, r] = ES[i, r]
        for c in range(3):
            RD[j, r, c] = RS[i, r, c]


# long: a compiled kernel whose 37 arguments, and those of the kernels it calls, take a line each
@kernel
def _look(
    cls,
    h,
    PP,
    R06,
    p,
    p16,
    xa,
    xb,
    u,
    deeper,
    X2,
    RS2,
    ES2,
    CS2,
    FL,
    NR,
    NE,
    NC,
    NX,
    S1,
    DM,
    FM,
    SX,
    SR,
    ns,
    th,
    e,
    t2,
    out,
    q,
    q2,
    pol,
    Q,
    V,
    E,
    n,
):
    """A finer look at the interval [xa, xb]: its samples X2 = xa + (xb − xa) ``u`` (roots RS2,
    errors ES2, counts CS2), the brackets and dips of them, the dips at both ends (with the
    samples next to the interval: slot 0 (left, angle NX[0]) and 1 (right, NX[1]) of NR, NE,
    NC) and the fold seeds (appended to SX, SR, ``ns`` of them).  Where ``deeper``, an interval
    of it where the number of roots is unchanged but a followed root moves by more than
    :data:`_JUMP` (the finer samples still do not resolve the roots there: two folds of the inner
    subproblem inside it, the root running back and forth, or a root turning fast past a near
    singularity) is flagged in FL for a finer look again, and its brackets and the dips at its
    ends are left to that.  Returns (the new branch count, the new seed count)."""
    L2 = len(u)
    for i in range(L2):
        X2[i] = xa + (xb - xa) * u[i]
    X2[L2 - 1] = xb
    _sample(cls, h, PP, R06, p16, X2, RS2, ES2, CS2, t2)
    for g2 in range(L2 - 1):
        _interval(RS2, CS2, g2, S1, DM)
        fast = False
        if deeper and CS2[g2] == CS2[g2 + 1]:
            for s in range(CS2[g2]):
                fast = fast or DM[s] > _JUMP
        FL[g2] = fast
        if not fast:
            n = _brackets(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                X2,
                RS2,
                ES2,
                CS2,
                g2,
                S1,
                DM,
                th,
                e,
                t2,
                out,
                q,
                q2,
                pol,
                Q,
                V,
                E,
                n,
            )
        if g2 > 0 and not FL[g2 - 1] and not fast:
            n = _dips(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                RS2,
                ES2,
                CS2,
                g2 - 1,
                X2[g2 - 1],
                RS2,
                ES2,
                CS2,
                g2,
                X2[g2],
                RS2,
                ES2,
                CS2,
                g2 + 1,
                X2[g2 + 1],
                th,
                e,
                t2,
                out,
                q,
                q2,
                pol,
                Q,
                V,
                E,
                n,
            )
        if CS2[g2] != CS2[g2 + 1]:
            # fold seeds: on the side with more roots, those with a small error, and all those
            # nearest to no root of the other side (the pair that meets at the fold) where
            # their errors differ in sign (a root on the arc through the fold)
            side = g2 if CS2[g2] > CS2[g2 + 1] else g2 + 1
            other = g2 + 1 if side == g2 else g2
            for j in range(4):
                FM[j] = True
            for t in range(CS2[other]):
                k, _ = _nearest(
                    RS2, CS2, side, (RS2[other, t, 0], RS2[other, t, 1], RS2[other, t, 2])
                )
                FM[k] = False
            pos = neg_ = False
            for j in range(CS2[side]):
                if FM[j]:
                    pos = pos or ES2[side, j] > 0.0
                    neg_ = neg_ or ES2[side, j] < 0.0
            for j in range(CS2[side]):
                if (abs(ES2[side, j]) < _SEED or (FM[j] and pos and neg_)) and ns < _MAX_SEEDS:
                    SX[ns] = X2[side]
                    SR[ns, 0], SR[ns, 1], SR[ns, 2] = (
                        RS2[side, j, 0],
                        RS2[side, j, 1],
                        RS2[side, j, 2],
                    )
                    ns += 1
    # the ends of the finer look, between its next samples and the samples beyond it
    if not FL[0]:
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            NR,
            NE,
            NC,
            0,
            NX[0],
            RS2,
            ES2,
            CS2,
            0,
            X2[0],
            RS2,
            ES2,
            CS2,
            1,
            X2[1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            pol,
            Q,
            V,
            E,
            n,
        )
    if not FL[L2 - 2]:
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            RS2,
            ES2,
            CS2,
            L2 - 2,
            X2[L2 - 2],
            RS2,
            ES2,
            CS2,
            L2 - 1,
            X2[L2 - 1],
            NR,
            NE,
            NC,
            1,
            NX[1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            pol,
            Q,
            V,
            E,
            n,
        )
    return n, ns


# long: one compiled body per pose: the grid, its finer looks level by level, the fold seeds
@kernel
def _search_1d_pose(cls, h, PP, A, R06, p, Q, V, E, grid):
    """Every branch of one pose of a 1-D search class into Q (16, 6), V, E; returns their
    number.  ``A``: the arm's frames for the Newton polish (:func:`.polish.geo_frames`)."""
    p16 = sub(sub(p, mv(R06, PP[6])), PP[0])
    L = grid + 1
    step = 2.0 * math.pi / grid
    X = np.empty(L)
    for i in range(L):
        X[i] = i * step - math.pi
    X[L - 1] = math.pi
    RS, ES, CS = np.zeros((L, 4, 3)), np.full((L, 4), math.nan), np.zeros(L, dtype=np.int64)
    t2, th, e = np.empty((4, 2)), np.empty((4, 3)), np.empty(4)
    S1, DM = np.zeros(4, dtype=np.int64), np.zeros(4)
    out, q, q2 = np.empty(5), np.empty(6), np.empty(6)
    pol = workspace(A)
    _sample(cls, h, PP, R06, p16, X, RS, ES, CS, t2)
    fine = np.zeros(grid, dtype=np.bool_)
    n = 0
    for g in range(grid):
        fine[g] = _interval(RS, CS, g, S1, DM)
        if fine[g]:
            continue  # its brackets come from the finer look
        n = _brackets(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            X,
            RS,
            ES,
            CS,
            g,
            S1,
            DM,
            th,
            e,
            t2,
            out,
            q,
            q2,
            pol,
            Q,
            V,
            E,
            n,
        )
    # dips at the samples between two plain intervals (sample 0 ≡ L − 1: its left neighbour is L − 2)
    for g in range(grid):
        gl = g - 1 if g > 0 else grid - 1
        if fine[gl] or fine[g]:
            continue
        il, xl = (g - 1, X[g - 1]) if g > 0 else (L - 2, X[L - 2] - 2.0 * math.pi)
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            RS,
            ES,
            CS,
            il,
            xl,
            RS,
            ES,
            CS,
            g,
            X[g],
            RS,
            ES,
            CS,
            g + 1,
            X[g + 1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            pol,
            Q,
            V,
            E,
            n,
        )
    # the finer looks: 2 _SUB + 1 points crowded quadratically towards both ends, at up to
    # _DEPTH levels (level d + 1 looks again at the flagged intervals of level d, depth first)
    L2 = 2 * _SUB + 1
    u = np.empty(L2)
    for i in range(_SUB + 1):
        u[i] = (i / _SUB) ** 2 / 2.0
    for i in range(_SUB):
        u[_SUB + 1 + i] = 1.0 - u[_SUB - 1 - i]
    XL = np.empty((_DEPTH, L2))
    RSL, ESL = np.zeros((_DEPTH, L2, 4, 3)), np.full((_DEPTH, L2, 4), math.nan)
    CSL, FL = np.zeros((_DEPTH, L2), dtype=np.int64), np.zeros((_DEPTH, L2 - 1), dtype=np.bool_)
    # the samples next to each level's interval (0: left, 1: right), copied from its parent
    NR, NE = np.zeros((_DEPTH, 2, 4, 3)), np.full((_DEPTH, 2, 4), math.nan)
    NC, NX = np.zeros((_DEPTH, 2), dtype=np.int64), np.empty((_DEPTH, 2))
    pos = np.zeros(_DEPTH, dtype=np.int64)
    SX, SR, FM = np.empty(_MAX_SEEDS), np.empty((_MAX_SEEDS, 3)), np.empty(4, dtype=np.bool_)
    ns = 0
    for g in range(grid):
        if not fine[g]:
            continue
        il, xl = (g - 1, X[g - 1]) if g > 0 else (L - 2, X[L - 2] - 2.0 * math.pi)
        ir, xr = (g + 2, X[g + 2]) if g + 2 < L else (1, X[1] + 2.0 * math.pi)
        _copy_sample(RS, ES, CS, il, NR[0], NE[0], NC[0], 0)
        _copy_sample(RS, ES, CS, ir, NR[0], NE[0], NC[0], 1)
        NX[0, 0], NX[0, 1] = xl, xr
        n, ns = _look(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            X[g],
            X[g + 1],
            u,
            _DEPTH > 1,
            XL[0],
            RSL[0],
            ESL[0],
            CSL[0],
            FL[0],
            NR[0],
            NE[0],
            NC[0],
            NX[0],
            S1,
            DM,
            FM,
            SX,
            SR,
            ns,
            th,
            e,
            t2,
            out,
            q,
            q2,
            pol,
            Q,
            V,
            E,
            n,
        )
        d = 0
        pos[0] = 0
        while d >= 0:
            k = pos[d]
            while k < L2 - 1 and not FL[d, k]:
                k += 1
            if k >= L2 - 1:
                d -= 1  # every flagged interval of level d done
                continue
            pos[d] = k + 1
            if k > 0:
                _copy_sample(RSL[d], ESL[d], CSL[d], k - 1, NR[d + 1], NE[d + 1], NC[d + 1], 0)
                NX[d + 1, 0] = XL[d, k - 1]
            else:
                _copy_sample(NR[d], NE[d], NC[d], 0, NR[d + 1], NE[d + 1], NC[d + 1], 0)
                NX[d + 1, 0] = NX[d, 0]
            if k + 2 < L2:
                _copy_sample(RSL[d], ESL[d], CSL[d], k + 2, NR[d + 1], NE[d + 1], NC[d + 1], 1)
                NX[d + 1, 1] = XL[d, k + 2]
            else:
                _copy_sample(NR[d], NE[d], NC[d], 1, NR[d + 1], NE[d + 1], NC[d + 1], 1)
                NX[d + 1, 1] = NX[d, 1]
            d += 1
            n, ns = _look(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                XL[d - 1, k],
                XL[d - 1, k + 1],
                u,
                d + 1 < _DEPTH,
                XL[d],
                RSL[d],
                ESL[d],
                CSL[d],
                FL[d],
                NR[d],
                NE[d],
                NC[d],
                NX[d],
                S1,
                DM,
                FM,
                SX,
                SR,
                ns,
                th,
                e,
                t2,
                out,
                q,
                q2,
                pol,
                Q,
                V,
                E,
                n,
            )
            pos[d] = 0
    for k in range(ns):
        _assemble(cls, h, PP, R06, p16, SX[k], SR[k, 0], SR[k, 1], SR[k, 2], q)
        if polish(pol, R06, p, q, _POLISH_1D):
            n = _push(Q, V, E, n, q, True)
    return n
