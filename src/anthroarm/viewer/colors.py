"""The viewer's colours: the palette of the generated visuals, joint-limit proximity colours,
colour maps and their legends.

Colours are ``(r, g, b)`` with components in [0, 1] unless a name says otherwise
(:func:`rgb_hex`: meshcat's 0xRRGGBB integer).

Function-local import (a heavy dependency, only paid for by a colour map): matplotlib, in
:func:`colormaps`.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

#: Links, joint centres, joint axes, skin (palm, head) and torso of the generated skeleton.
LINK_RGB = (0.62, 0.68, 0.78)
JOINT_RGB = (0.90, 0.50, 0.20)
AXIS_RGB = (0.25, 0.25, 0.30)
SKIN_RGB = (0.93, 0.78, 0.66)
TORSO_RGB = (0.55, 0.60, 0.66)
#: Colour of a joint at its limit (joint-limit proximity).
LIMIT_RGB = (0.92, 0.12, 0.10)
#: Proximity above which a link starts to turn red: the last 15 % of the range on each side.
LIMIT_WARN = 0.7


def rgb_hex(rgb) -> int:
    """meshcat's ``0xRRGGBB`` of ``rgb`` (components clipped to [0, 1])."""
    r, g, b = (int(round(255 * max(0.0, min(1.0, float(c))))) for c in rgb[:3])
    return (r << 16) | (g << 8) | b


def limit_proximity(q, lower, upper) -> np.ndarray:
    """0 at the middle of each joint's range, 1 at (or beyond) a limit; 0 for unbounded joints.
    ``q``: joint positions θ (rad or m, :meth:`anthroarm.chain.Chain.angles`), one per limit."""
    q, lo, hi = (np.asarray(x, float) for x in (q, lower, upper))
    out = np.zeros_like(q)
    fin = np.isfinite(lo) & np.isfinite(hi) & (hi > lo)
    half = 0.5 * (hi[fin] - lo[fin])
    mid = 0.5 * (hi[fin] + lo[fin])
    out[fin] = np.clip(np.abs(q[fin] - mid) / half, 0.0, 1.0)
    return out


def limit_color(p: float, base=LINK_RGB) -> tuple[float, float, float]:
    """Link colour for proximity ``p``: the base colour up to :data:`LIMIT_WARN`, then a blend
    to :data:`LIMIT_RGB` at the limit."""
    w = float(np.clip((p - LIMIT_WARN) / (1.0 - LIMIT_WARN), 0.0, 1.0))
    return tuple((1 - w) * b + w * r for b, r in zip(base, LIMIT_RGB))


def colormaps():
    """matplotlib's registry of colour maps (imported on first use: matplotlib is heavy)."""
    from matplotlib import colormaps as registry

    return registry


def viridis(x: np.ndarray) -> np.ndarray:
    """RGB (N, 3) in [0, 1] of the viridis colour map at ``x`` in [0, 1]."""
    return np.asarray(colormaps()["viridis"](np.clip(x, 0, 1)))[:, :3]


def colormap_rgb(values, colormap: str = "viridis", vmin=None, vmax=None):
    """RGB (N, 3) in [0, 1] of ``values`` (N,) through the matplotlib colour map ``colormap``,
    scaled from ``vmin`` (default: the smallest finite value) to ``vmax`` (the largest).
    Returns ``(rgb, vmin, vmax)``.  NaN or inf values, an unknown map or ``vmax < vmin`` raise
    :class:`~anthroarm.errors.ParameterError`."""
    maps = colormaps()
    v = np.asarray(values, dtype=float)
    if v.ndim != 1 or not np.all(np.isfinite(v)):
        raise ParameterError(
            f"values must be a 1-D array of finite numbers, got shape {v.shape}"
            + ("" if v.ndim != 1 else " with NaN or inf")
        )
    if not isinstance(colormap, str) or colormap not in maps:
        raise ParameterError(
            f"colormap must be a matplotlib colour map name (viridis, viridis_r, plasma, "
            f"coolwarm, ...), got {colormap!r}"
        )
    lo = float(v.min()) if vmin is None and v.size else (0.0 if vmin is None else float(vmin))
    hi = float(v.max()) if vmax is None and v.size else (1.0 if vmax is None else float(vmax))
    if not (math.isfinite(lo) and math.isfinite(hi) and hi >= lo):
        raise ParameterError(f"vmin, vmax must be finite with vmin <= vmax, got {lo}, {hi}")
    x = (v - lo) / (hi - lo) if hi > lo else np.full_like(v, 0.5)
    return np.asarray(maps[colormap](np.clip(x, 0.0, 1.0)))[:, :3], lo, hi


def colormap_legend(title: str, colormap: str, vmin: float, vmax: float, n: int = 9) -> dict:
    """The ``anthroarm_ui`` spec of a colour-bar legend: ``n`` colours of ``colormap`` from
    ``vmin`` to ``vmax`` and three tick labels (min, middle, max)."""
    stops = np.asarray(colormaps()[colormap](np.linspace(0.0, 1.0, n)))[:, :3]
    ticks = [f"{v:.3g}" for v in (vmin, 0.5 * (vmin + vmax), vmax)]
    return {
        "kind": "legend",
        "title": str(title),
        "stops": [[round(float(c), 4) for c in rgb] for rgb in stops],
        "ticks": ticks,
    }


def limits_legend() -> dict:
    """The ``anthroarm_ui`` spec of the joint-limit proximity legend (:func:`limit_color`)."""
    return {
        "kind": "legend",
        "title": "joint-limit proximity (0: mid-range, 1: at a limit)",
        "stops": [list(limit_color(v)) for v in np.linspace(0.0, 1.0, 11)],
        "ticks": ["0", "0.5", "1"],
    }
