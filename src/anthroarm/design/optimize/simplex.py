"""The book's accelerated simplex method (单纯形加速法, Nelder & Mead 1964), §4-4,
Eq. (4-48)–(4-64).

Step 1: values S_i at the n+1 vertices; best X_L, worst X_H, second worst X_G (4-48)–(4-50).
Step 2: centroid without X_H, ``X_F = (Σ X_i − X_H)/n`` (4-55); reflection ``X_R = 2X_F − X_H``.
Step 3: if S_R ≥ S_G compress: ``X_S = (1 − λ)X_H + λX_R``, 0 < λ < 1, λ ≠ ½ (4-59)/(4-60).
Step 4: if S_R < S_G expand: ``X_B = (1 − μ)X_H + μX_R``, μ > 1 (4-61); X_S = X_B if S_B < S_R
else X_R (the stricter test S_R < S_L is an option).
Step 5: if S_S < S_G replace X_H by X_S, else step 6: shrink towards X_L, ``X_i = (X_i + X_L)/2``.
Step 7: stop when ``Σ (S_i − S_L)² < ε1`` (4-63) or ``|(S_H − S_L)/S_L| < ε2`` (4-64).

Differences from SciPy's Nelder–Mead: one compression point (SciPy has inside and outside),
the comparisons are against S_G, and expansion is kept only if it beats the reflection.
λ = 0.25 is SciPy's inside contraction, μ = 1.5 its expansion (γ = 2).  The book gives no
numbers for λ, μ, ε: the defaults are ours.
"""

from __future__ import annotations

import numpy as np

from .result import MAX_COORD, Counted, OptimizeResult, as_vector, count, positive


def simplex_book(
    f,
    x0,
    step=1.0,
    lam: float = 0.25,
    mu: float = 1.5,
    eps1: float = 1e-14,
    eps2: float | None = None,
    maxiter: int = 5000,
    expand_if: str = "G",
    initial_simplex=None,
    xtol: float = 0.0,
) -> OptimizeResult:
    """Minimise ``f`` by the book's simplex variant.

    ``step`` (scalar or per-axis) builds the initial simplex ``x0 + step·e_i`` unless
    ``initial_simplex`` ((n+1, n)) is given; its edges must be linearly independent.
    ``expand_if="G"`` expands when S_R < S_G (book step 4), ``"L"`` when S_R < S_L.
    ``eps2=None`` disables (4-64) (it is ill-posed when S_L ≈ 0).  ``xtol`` > 0 also stops when
    the simplex diameter falls below it; ``eps1=0`` leaves the stop to
    ``eps2``/``xtol``/``maxiter``. ``f`` may return ``inf`` (e.g. an infeasible point for a barrier
    function).  ``eps1`` and ``xtol`` must be finite and >= 0, ``eps2`` (when given) finite and > 0,
    ``maxiter`` an integer >= 1, ``x0``, ``step`` and ``initial_simplex`` finite within ±1e150
    (``ValueError``).  If ``f`` was NaN somewhere the status is ``"nan"`` with the best finite
    point; an ``f`` that is never finite raises :class:`~anthroarm.errors.ObjectiveError`."""
    eps1 = positive("eps1", eps1, allow_zero=True)
    if eps2 is not None:
        eps2 = positive("eps2", eps2)
    xtol = positive("xtol", xtol, allow_zero=True)
    maxiter = count("maxiter", maxiter)
    if not (0 < lam < 1) or lam == 0.5:
        raise ValueError(
            f"compression factor must satisfy 0 < lam < 1, lam != 0.5 (4-60); got {lam!r}"
        )
    if not mu > 1:
        raise ValueError(f"expansion factor must be > 1 (4-61); got {mu!r}")
    if expand_if not in ("G", "L"):
        raise ValueError("expand_if must be 'G' or 'L'")
    fc = Counted(f)
    if initial_simplex is None:
        x0 = as_vector("x0", x0, limit=MAX_COORD)
        n = x0.size
        st = np.broadcast_to(np.asarray(step, dtype=float), (n,))
        if np.any(st == 0) or not np.all(np.isfinite(st)) or np.any(np.abs(st) > MAX_COORD):
            raise ValueError(
                f"simplex step must be finite, non-zero and within +-{MAX_COORD:g}, got {step!r}"
            )
        X = np.vstack([x0] + [x0 + st[i] * np.eye(n)[i] for i in range(n)])
    else:
        X = np.array(initial_simplex, dtype=float)
        n = X.shape[1]
        if X.shape != (n + 1, n) or not np.all(np.isfinite(X)) or np.any(np.abs(X) > MAX_COORD):
            raise ValueError(
                f"initial_simplex must be a finite (n+1, n) array within +-{MAX_COORD:g}, "
                f"got shape {X.shape}"
            )
    if np.linalg.matrix_rank(X[1:] - X[0]) < n:
        raise ValueError(
            "simplex edges X_i - X_0 are linearly dependent: the search would stay in a subspace"
        )
    S = np.array([fc(x) for x in X])
    hist = []
    status, msg = "maxiter", f"no convergence in {maxiter} iterations"
    it = 0
    for it in range(1, maxiter + 1):
        order = np.argsort(S, kind="stable")
        X, S = X[order], S[order]
        L, G, H = 0, n - 1, n  # best, second worst, worst
        hist.append(X[L].copy())
        if np.isfinite(S[L]):
            spread = np.sum((S - S[L]) ** 2) if np.all(np.isfinite(S)) else np.inf
            if spread < eps1:  # (4-63)
                status, msg = "converged", f"sum (S_i - S_L)^2 < {eps1:g} (4-63)"
                break
            if (
                eps2 is not None
                and S[L] != 0
                and np.isfinite(S[H])
                and abs((S[H] - S[L]) / S[L]) < eps2
            ):
                status, msg = "converged", f"|(S_H - S_L)/S_L| < {eps2:g} (4-64)"
                break
        if xtol > 0 and np.max(np.linalg.norm(X - X[L], axis=1)) < xtol:
            status, msg = "converged", f"simplex diameter < {xtol:g}"
            break
        XF = (X.sum(axis=0) - X[H]) / n  # (4-55)
        XR = 2 * XF - X[H]  # (4-56)-(4-58)
        SR = fc(XR)
        if SR >= S[G]:  # step 3: compress
            XS = (1 - lam) * X[H] + lam * XR
            SS = fc(XS)
        else:  # step 4: expand
            if expand_if == "G" or SR < S[L]:
                XB = (1 - mu) * X[H] + mu * XR
                SB = fc(XB)
                XS, SS = (XB, SB) if SB < SR else (XR, SR)
            else:
                XS, SS = XR, SR
        if SS < S[G]:  # step 5
            X[H], S[H] = XS, SS
        else:  # step 6: shrink towards X_L (4-62)
            X[1:] = 0.5 * (X[1:] + X[L])
            S[1:] = [fc(x) for x in X[1:]]
    order = np.argsort(S, kind="stable")
    X, S = X[order], S[order]
    if fc.saw_nan and not np.isfinite(S[0]):
        status, msg = "nan", "the objective returned NaN (x, fun: the best finite point)"
    return fc.result(
        X[0].copy(), float(S[0]), status, msg, it, fc.n, hist, {"simplex": X, "values": S}
    )
