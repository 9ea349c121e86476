"""The inputs of the closed forms, checked: poses T (a 4×4 homogeneous transform or a batch
(N, 4, 4), metres; a position (3,) or (N, 3) where only the position is compared), tolerances, and
the swivel angles / held-joint values (rad) with their batch rule (:func:`swivel_array`).

A rotation part R is accepted where max |RᵀR − I| ≤ ``tol_orthonormal`` and det R > 0, the last
row where it is [0, 0, 0, 1] to 1e-12; every error is a ValueError that names the pose and the
value (a compiled call that found a malformed pose reports only its index:
:func:`detail_bad_pose` says what is wrong with it).
"""

from __future__ import annotations

import math

import numpy as np

from ..vec3 import WRAP_MAX

#: default swivel grid of a redundant (srs_7r) arm (rad)
DEFAULT_SWIVEL = np.linspace(-np.pi, np.pi, 36, endpoint=False)


def check_poses(
    T, name="T", tol_orthonormal=1e-6, position_only=False, rigid=True
) -> tuple[np.ndarray, bool]:
    """Return (N, 4, 4) and whether the input was a single pose.  ValueError on bad input:
    the shape, a value that is not finite, and (``rigid``) the last row and the rotation part
    (``rigid=False``: the caller's compiled solver checks those, :class:`.geometric.BadPoseError`)."""
    arr = np.asarray(T, dtype=float)
    single = arr.ndim == 2
    if position_only and arr.ndim in (1, 2) and arr.shape[-1] == 3 and arr.shape != (3, 3):
        single = arr.ndim == 1
        P = arr.reshape(-1, 3)
        arr = np.tile(np.eye(4), (P.shape[0], 1, 1))
        arr[:, :3, 3] = P
    elif arr.ndim == 2 and arr.shape == (4, 4):
        arr = arr[None]
    elif not (arr.ndim == 3 and arr.shape[1:] == (4, 4)):
        raise ValueError(
            f"{name} must be a 4x4 homogeneous pose or a batch (N, 4, 4), got shape {arr.shape}"
        )
    if arr.shape[0] == 0:
        return arr, single  # an empty batch: an empty result
    if not np.isfinite(arr).all():
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(
            f"{name}{list(idx) if not single else list(idx[1:])} is {arr[idx]} (not finite)"
        )
    if not rigid:
        return arr, single
    if np.abs(arr[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max() > 1e-12:
        raise ValueError(f"{name}: the last row of a homogeneous pose must be [0, 0, 0, 1]")
    R = arr[:, :3, :3]
    err = np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    det = (
        np.linalg.det(R)
        if len(R) < 64
        else np.einsum("ni,ni->n", R[:, :, 0], np.cross(R[:, :, 1], R[:, :, 2]))
    )
    bad = (err > tol_orthonormal) | (det < 0)
    if not position_only and bad.any():
        i = int(np.argmax(bad))
        where = "" if single else f"[{i}]"
        raise ValueError(
            f"{name}{where}: the rotation part is not a rotation matrix (max |R^T R - I| = {err[i]:.3g}, "
            f"det = {det[i]:.6g}); orthonormalise it first (e.g. nearest rotation by SVD)"
        )
    return arr, single


def detail_bad_pose(Ts, i, single, tol_orthonormal):
    """Raise :func:`check_poses`'s detailed ValueError for pose ``i`` of ``Ts``, named as the
    caller indexed it — the pose a compiled call found malformed (its
    :class:`.geometric.BadPoseError` says only which)."""
    check_poses(Ts[i], name="T" if single else f"T[{i}]", tol_orthonormal=tol_orthonormal)


def c_order(T) -> np.ndarray:
    """``T`` as an array in C order (the compiled calls take C order): a list as floats, an
    array as it is (its dtype checked later), a strided view copied."""
    arr = T if isinstance(T, np.ndarray) else np.asarray(T, dtype=float)
    return arr if arr.flags.c_contiguous else np.ascontiguousarray(arr)


def check_tol(name, value):
    """``tol`` / ``tol_orthonormal``: a finite positive number, else ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name} must be a positive number, got {type(value).__name__} {value!r}")
    if not (math.isfinite(float(value)) and float(value) > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


def swivel_array(swivel, N, grid_1d=False):
    """(N, S) swivel angles.  Batch rule: scalar -> every pose; 1-D -> one angle per pose
    (length N), unless ``grid_1d`` (single-pose call: a 1-D array is a grid); 2-D (N, S) or
    (1, S) -> a grid per pose; None -> :data:`DEFAULT_SWIVEL` for every pose."""
    if swivel is None:
        return np.broadcast_to(DEFAULT_SWIVEL[None, :], (N, DEFAULT_SWIVEL.size)).copy()
    if type(swivel) is float and abs(swivel) < WRAP_MAX:  # the usual one angle: no numpy checks
        sw = np.empty((N, 1))
        sw.fill(swivel)
        return sw
    sw = np.asarray(swivel, dtype=float)
    if not (np.abs(sw) < WRAP_MAX).all():
        raise ValueError(
            f"swivel must be finite angles (rad) of magnitude below {WRAP_MAX:g}, got {swivel!r}"
        )
    if sw.ndim == 0:
        return np.full((N, 1), float(sw))
    if sw.ndim == 1 and grid_1d:
        sw = sw[None, :]
    elif sw.ndim == 1:
        if sw.shape[0] != N:
            raise ValueError(
                f"swivel: a 1-D array gives one angle per pose and must have length N = {N}, "
                f"got {sw.shape[0]} (pass shape (1, S) for a grid shared by all poses)"
            )
        return sw[:, None].copy()
    if sw.ndim == 2 and sw.shape[0] in (1, N) and sw.shape[1] >= 1:
        return np.broadcast_to(sw, (N, sw.shape[1])).copy()
    raise ValueError(
        f"swivel must be a scalar, shape (N,), (1, S) or (N, S) with N = {N}, got {sw.shape}"
    )


def held_angle(param) -> float | None:
    """A held joint's value ``param`` as a float angle, or None where it is not one (the batch
    path says what is wrong)."""
    try:
        prm = float(param)
    except (TypeError, ValueError):
        return None
    return prm if abs(prm) < WRAP_MAX else None
