"""Plots of batch results (matplotlib): slices of voxel maps, population curves.

Figures are returned, never shown or saved: the caller (CLI, notebook) decides."""

from __future__ import annotations

import numpy as np

from .result import BatchResult

#: The voxel map a job's result is drawn by (``slice_plot``, ``Viewer.show_map``): job -> variable.
MAP_VARIABLES = {"reachability_map": "counts", "comfort_map": "discomfort"}


def slice_plot(
    result: BatchResult,
    var: str | None = None,
    axis: str = "z",
    value: float | None = None,
    ax=None,
):
    """One slice of a voxel map (``reachability_map`` / ``comfort_map``) normal to ``axis``
    ("x", "y" or "z") at the coordinate nearest ``value`` m (default: the slice through the
    base origin); unreached voxels are blank.  Returns the matplotlib Figure."""
    import matplotlib.pyplot as plt

    var = var or MAP_VARIABLES.get(result.job)
    if var is None or var not in result.variables:
        raise ValueError(
            f"{result.job}: no voxel map to slice; variables: {list(result.variables)}"
        )
    dims = list(result.dims(var))
    if axis not in dims:
        raise ValueError(f"axis must be one of {dims}, got {axis!r}")
    c = result.coords[axis]
    k = int(np.argmin(np.abs(c - (0.0 if value is None else value))))
    a = np.take(result[var], k, axis=dims.index(axis)).astype(float)
    if var == "counts":
        a[a == 0] = np.nan
    u, v = [d for d in dims if d != axis]
    if ax is None:
        fig, ax = plt.subplots(figsize=(5.5, 4.5))
    else:
        fig = ax.figure
    cu, cv = result.coords[u], result.coords[v]
    h = ax.pcolormesh(
        cu, cv, a.T, shading="nearest", cmap="viridis_r" if var == "discomfort" else "viridis"
    )
    fig.colorbar(
        h,
        ax=ax,
        label=var + (" (configurations per voxel)" if var == "counts" else " (0 = comfortable)"),
    )
    ax.set_xlabel(f"{u} (m)")
    ax.set_ylabel(f"{v} (m)")
    ax.set_aspect("equal")
    ax.set_title(f"{result.attrs.get('robot', '')} {result.job}: {axis} = {c[k]:.3f} m")
    return fig


def population_plot(result: BatchResult, ax=None):
    """Workspace volume (m³) against height, one line per (mass, sex)."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(5.5, 4))
    else:
        fig = ax.figure
    vol = result["volume"]
    for j, m in enumerate(result.coords["mass"]):
        for k, s in enumerate(result.coords["sex"]):
            ax.plot(result.coords["height"], vol[:, j, k], "o-", label=f"{m:g} kg, {s}")
    ax.set_xlabel("height (m)")
    ax.set_ylabel("workspace volume (m³)")
    ax.legend()
    ax.grid(alpha=0.3)
    return fig


def occupied_points(result: BatchResult, var: str | None = None):
    """Centres (K, 3) m of the reached voxels of a voxel map and their values (K,): the point
    cloud to draw in a 3D viewer."""
    var = var or MAP_VARIABLES.get(result.job)
    a = result[var]
    mask = np.isfinite(a) & (a != 0) if var != "discomfort" else np.isfinite(a)
    i, j, k = np.nonzero(mask)
    P = np.stack([result.coords["x"][i], result.coords["y"][j], result.coords["z"][k]], 1)
    return P, a[mask]
