"""The spatial cell method (空间单元法), book §7-3, Eq. (7-32).

Off-line, the workspace is cut into cubic cells of edge ``D`` for one fixed hand orientation
and the exact IK (:func:`anthroarm.ik.analytic_batch`) is stored at every lattice point
``M = origin + D·(i, j, k)``.  On-line, a target ``P0`` is located in its cell and the joint
vector is interpolated from the 8 corners by repeated linear division (定比分割), Eq. (7-32):

    N1 = t1 M0 + m1 M1,  N2 = t1 M2 + m1 M4,  N3 = t1 M3 + m1 M6,  N4 = t1 M5 + m1 M7,
    N5 = t2 N1 + m2 N2,  N6 = t2 N3 + m2 N4,  P0 = t3 N5 + m3 N6,   t_i = 1 − m_i,

with corner labels M0 = (0,0,0), M1 = (1,0,0), M2 = (0,1,0), M3 = (0,0,1), M4 = (1,1,0),
M5 = (0,1,1), M6 = (1,0,1), M7 = (1,1,1) (the printed chain has sign/index misprints, see
docs/errata.md).  Only arithmetic is needed at run time.  :meth:`CellTable.refine` adds one
Newton step (Pinocchio Jacobian) after the lookup.

Motor pulses (§9-3, l. 7589): the care robot of Chapter 9 stores, for every lattice point, the
motor pulse counts from the origin (all joints at zero) instead of joint angles, and reaches a
commanded point by the *relative* pulses between two table entries (its position registers).
:meth:`CellTable.with_pulses` attaches the integer table ``pulses = round(q · pulses_per_rad)``;
:meth:`CellTable.lookup_pulses` interpolates it by Eq. (7-32) and rounds to whole pulses;
:meth:`CellTable.relative_pulses` is the register difference.  The lattice may be of any point
fixed in the tool frame (``point=``, e.g. the wrist centre of §9-3, "手腕的位置坐标").

Units: metres and radians (the book's D = 50 mm is ``D=0.05``); pulses are integers.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from tqdm.auto import tqdm

from ..errors import ParameterError
from .closed_form import analytic_batch, require_form

#: corner offsets (i, j, k) of M0 … M7 in the book's labelling
CORNERS = np.array(
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, 1, 1]]
)


def trilinear_weights(m) -> np.ndarray:
    """Weights of M0 … M7 in Eq. (7-32) for local cell coordinates ``m`` = (m1, m2, m3) ∈ [0, 1]³
    (shape (3,) or (N, 3)); returns (8,) or (N, 8).  They are ≥ 0 and sum to 1."""
    m = np.asarray(m, float)
    t = 1.0 - m
    m1, m2, m3 = m[..., 0], m[..., 1], m[..., 2]
    t1, t2, t3 = t[..., 0], t[..., 1], t[..., 2]
    return np.stack(
        [
            t1 * t2 * t3,
            m1 * t2 * t3,
            t1 * m2 * t3,
            t1 * t2 * m3,
            m1 * m2 * t3,
            t1 * m2 * m3,
            m1 * t2 * m3,
            m1 * m2 * m3,
        ],
        -1,
    )


def nested_division(M, m) -> np.ndarray:
    """Eq. (7-32) as the book computes it: the chain N1 … N6, P0 of linear divisions.
    ``M`` (8, k) corner values in the book's order, ``m`` (3,) local coordinates."""
    M = np.asarray(M, float)
    m1, m2, m3 = (float(x) for x in m)
    t1, t2, t3 = 1 - m1, 1 - m2, 1 - m3
    N1 = t1 * M[0] + m1 * M[1]
    N2 = t1 * M[2] + m1 * M[4]
    N3 = t1 * M[3] + m1 * M[6]
    N4 = t1 * M[5] + m1 * M[7]
    N5 = t2 * N1 + m2 * N2
    N6 = t2 * N3 + m2 * N4
    return t3 * N5 + m3 * N6


def _finite_vector(v, name: str, n: int) -> np.ndarray:
    """``v`` as a finite float vector of length ``n``; :class:`~anthroarm.errors.ParameterError`
    (a ValueError) naming ``name`` otherwise."""
    try:
        a = np.array(v, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be {n} finite numbers, got {v!r}") from None
    if a.shape != (n,) or not np.isfinite(a).all():
        raise ParameterError(f"{name} must be {n} finite numbers, got {v!r}")
    return a


class OutsideCellTableError(ValueError):
    """A query point whose cell is not covered by the table (outside the lattice, or a corner
    outside the workspace / joint limits)."""


@dataclass
class CellLookup:
    """Batch lookup result: ``q`` (N, nq), NaN where ``ok`` is False (cell not covered)."""

    q: np.ndarray
    ok: np.ndarray


#: the most lattice points a cell table may have
MAX_LATTICE = 5_000_000


def lattice(lo, hi, D: float) -> tuple[np.ndarray, tuple[int, int, int]]:
    """The §7-3 lattice covering the box [lo, hi] (m, base frame): points at integer multiples
    of the cell size ``D`` (m) from the base origin.  Returns (i0, shape): the integer index of
    the first point per axis (its position is i0·D) and the number of points per axis."""
    i0 = np.floor(np.asarray(lo, float) / D + 1e-9).astype(int)
    i1 = np.ceil(np.asarray(hi, float) / D - 1e-9).astype(int)
    return i0, tuple(int(x) for x in (i1 - i0 + 1))


class CellTable:
    """Joint-angle lattice of one robot for one fixed hand orientation (book §7-3).

    Build with :meth:`build`, query with :meth:`lookup` / :meth:`lookup_batch`, persist with
    :meth:`save` / :meth:`load`.  Attributes: ``origin`` (3,) m, ``D`` m, ``shape`` (nx, ny, nz),
    ``Q`` (nx, ny, nz, nq) rad (NaN where the lattice point has no IK solution on the branch),
    ``valid`` (nx, ny, nz), ``rotation`` (3, 3), ``model`` and ``params``."""

    def __init__(
        self,
        model: str,
        params: dict,
        rotation,
        origin,
        D: float,
        Q,
        valid,
        *,
        point=None,
        pulses_per_rad=None,
    ):
        self.model = model
        #: the point (m, tool frame) whose position the lattice holds; zero = the tool origin
        self.point = np.zeros(3) if point is None else _finite_vector(point, "point", 3)
        #: motor pulses per joint radian (nq,), or None for a table of joint angles only
        self.pulses_per_rad = None
        self.pulses = None
        self.params = dict(params)
        self.rotation = np.asarray(rotation, float)
        self.origin = np.asarray(origin, float)
        self.D = float(D)
        self.Q = np.asarray(Q, float)
        self.valid = np.asarray(valid, bool)
        self.shape = self.valid.shape
        self.nq = self.Q.shape[-1]
        self._origin_f = tuple(float(v) for v in self.origin)
        self._hi = tuple(int(v) - 2 for v in self.shape)
        # per-cell usability: all 8 corners valid
        v = self.valid
        self.cell_ok = (
            v[:-1, :-1, :-1]
            & v[1:, :-1, :-1]
            & v[:-1, 1:, :-1]
            & v[:-1, :-1, 1:]
            & v[1:, 1:, :-1]
            & v[:-1, 1:, 1:]
            & v[1:, :-1, 1:]
            & v[1:, 1:, 1:]
        )
        if pulses_per_rad is not None:
            self._set_pulses(pulses_per_rad)

    # ------------------------------------------------------------------ build
    # long: the public docstring, the checks of every argument in turn, then one loop over
    # the lattice
    @classmethod
    def build(
        cls,
        robot,
        rotation,
        D: float,
        bounds,
        *,
        q_ref=None,
        branch: str | None = None,
        progress: bool = True,
        swivel: float = 0.0,
        point=None,
    ) -> "CellTable":
        """Exact IK at every lattice point of the box ``bounds = (lo(3), hi(3))`` (m); the
        lattice is anchored at the base origin (points are integer multiples of ``D``).

        Branch choice: the solution with label ``branch`` if given, else the valid solution
        nearest to ``q_ref`` (default: the joint-range middle), so that the 8 corners of a cell
        come from one consistent branch.  ``progress`` shows a tqdm bar (one step per z slice).
        ``point`` (3,) m in the tool frame: the lattice holds the positions of this point (the
        tool pose at lattice point M is the table's rotation R at ``M − R·point``); default the
        tool origin."""
        form = require_form(robot)
        name, params = robot.spec.name, dict(robot.spec.params)
        try:
            R = np.asarray(rotation, float)
            D = float(D)
            lo, hi = (np.asarray(b, float) for b in bounds)
        except (TypeError, ValueError):
            raise ParameterError(
                f"rotation (3x3), D (m) and bounds (lo(3), hi(3)) must be numbers, got "
                f"{rotation!r}, {D!r}, {bounds!r}"
            ) from None
        if (
            R.shape != (3, 3)
            or not np.isfinite(R).all()
            or np.abs(R.T @ R - np.eye(3)).max() > 1e-9
        ):
            raise ParameterError(f"rotation must be a 3x3 rotation matrix, got {R!r}")
        if not (np.isfinite(D) and D > 0):
            raise ParameterError(f"cell size D must be > 0 (m), got {D}")
        if (
            lo.shape != (3,)
            or hi.shape != (3,)
            or not (np.isfinite(lo).all() and np.isfinite(hi).all())
            or (hi <= lo).any()
        ):
            raise ParameterError(f"bounds must be (lo(3), hi(3)) with lo < hi, got {bounds!r}")
        point = np.zeros(3) if point is None else _finite_vector(point, "point", 3)
        i0, shape = lattice(lo, hi, D)
        if np.prod(shape) > MAX_LATTICE:
            raise ParameterError(f"lattice of {shape} points is too large; increase D")
        origin = i0 * D
        if q_ref is None:
            lo_q = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
            hi_q = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
            q_ref = 0.5 * (lo_q + hi_q)
        q_ref = robot.check_q(q_ref, "q_ref")
        Q = np.full(shape + (robot.nq,), np.nan)
        valid = np.zeros(shape, bool)
        gx, gy = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
        it = range(shape[2])
        if progress:
            it = tqdm(it, desc=f"cell table {name} D={D * 1000:g} mm", unit="slice")
        kw = {"swivel": swivel} if form.swivel else {}
        for k in it:
            P = origin + D * np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, k)], -1)
            T = np.tile(np.eye(4), (P.shape[0], 1, 1))
            T[:, :3, :3] = R
            T[:, :3, 3] = P - R @ point
            res = analytic_batch(robot, T, **kw)
            if branch is not None:
                if branch not in res.branches:
                    raise ParameterError(f"branch {branch!r} is not one of {res.branches}")
                b = res.branches.index(branch)
                sel = res.solutions[:, b]
                ok = res.valid[:, b]
            else:
                d = np.abs(np.where(res.valid[..., None], res.solutions, np.inf) - q_ref).max(-1)
                b = np.argmin(d, axis=1)
                sel = res.solutions[np.arange(len(b)), b]
                ok = res.valid[np.arange(len(b)), b]
            Q[:, :, k] = np.where(ok[:, None], sel, np.nan).reshape(shape[0], shape[1], robot.nq)
            valid[:, :, k] = ok.reshape(shape[0], shape[1])
        return cls(name, params, R, origin, D, Q, valid, point=point)

    # ------------------------------------------------------------------ lookup
    def _locate(self, P):
        rel = (P - self.origin) / self.D
        idx = np.floor(rel).astype(np.int64)
        # points exactly on the upper lattice face belong to the last cell
        hi = np.array(self.shape) - 2
        idx = np.where((idx == hi + 1) & (rel <= hi + 1 + 1e-12), hi, idx)
        m = rel - idx
        inside = ((idx >= 0) & (idx <= hi)).all(-1)
        return idx, m, inside

    def lookup(self, p) -> np.ndarray:
        """Joint vector (nq,) at position ``p`` (3,) m by Eq. (7-32).  Raises
        :class:`OutsideCellTableError` if the cell is not covered."""
        (i, j, k), w = self._cell(p)
        return np.dot(w, self.Q[i : i + 2, j : j + 2, k : k + 2].reshape(8, self.nq))

    def _cell(self, p):
        """The covered cell (i, j, k) of position ``p`` and the 8 weights of Eq. (7-32) in the
        corner order of ``Q[i:i+2, j:j+2, k:k+2]`` (i slowest)."""
        try:
            x, y, z = (float(v) for v in p)
        except (TypeError, ValueError):
            raise ParameterError(f"p must be a finite position (3,) in metres, got {p!r}") from None
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            raise ParameterError(f"p must be a finite position (3,) in metres, got {p!r}")
        D, o, hi = self.D, self._origin_f, self._hi
        r = ((x - o[0]) / D, (y - o[1]) / D, (z - o[2]) / D)
        idx = [math.floor(v) for v in r]
        for a in range(3):  # points exactly on the upper lattice face belong to the last cell
            if idx[a] == hi[a] + 1 and r[a] <= hi[a] + 1 + 1e-12:
                idx[a] = hi[a]
            if not 0 <= idx[a] <= hi[a]:
                raise OutsideCellTableError(
                    f"position {tuple(p)} m is outside the lattice {self.bounds}"
                )
        i, j, k = idx
        if not self.cell_ok[i, j, k]:
            raise OutsideCellTableError(
                f"position {tuple(p)} m lies in a cell with a corner outside the workspace or the "
                "joint limits"
            )
        m1, m2, m3 = r[0] - i, r[1] - j, r[2] - k
        t1, t2, t3 = 1.0 - m1, 1.0 - m2, 1.0 - m3
        # the 8 weights of (7-32) in the corner order of Q[i:i+2, j:j+2, k:k+2] (i slowest)
        w = (
            t1 * t2 * t3,
            t1 * t2 * m3,
            t1 * m2 * t3,
            t1 * m2 * m3,
            m1 * t2 * t3,
            m1 * t2 * m3,
            m1 * m2 * t3,
            m1 * m2 * m3,
        )
        return (i, j, k), w

    def lookup_batch(self, P) -> CellLookup:
        """Vectorised Eq. (7-32) for positions ``P`` (N, 3) m."""
        P = np.asarray(P, float)
        if P.ndim != 2 or P.shape[1] != 3 or not np.isfinite(P).all():
            raise ParameterError(
                f"P must be finite positions (N, 3) in metres, got shape {P.shape}"
            )
        idx, m, inside = self._locate(P)
        idc = np.clip(idx, 0, np.array(self.shape) - 2)
        ok = inside & self.cell_ok[idc[:, 0], idc[:, 1], idc[:, 2]]
        w = trilinear_weights(m)  # (N, 8)
        q = np.zeros((P.shape[0], self.nq))
        for c, (a, b, e) in enumerate(CORNERS):
            q += w[:, c : c + 1] * self.Q[idc[:, 0] + a, idc[:, 1] + b, idc[:, 2] + e]
        q[~ok] = np.nan
        return CellLookup(q, ok)

    def refine(self, robot, p, q, steps: int = 1) -> np.ndarray:
        """``steps`` Newton steps on the full pose error (position ``p``, the table's rotation)
        from ``q``: Δq = J⁺ (p − p(q); log3(R* R(q)ᵀ)), J = Pinocchio LOCAL_WORLD_ALIGNED."""
        q = robot.check_q(q).copy()
        Rt = self.rotation
        target = np.asarray(p, float) - Rt @ self.point  # the tool origin's position
        for _ in range(steps):
            T = robot.fk(q)
            e = np.concatenate([target - T[:3, 3], pin.log3(Rt @ T[:3, :3].T)])
            J = robot.jacobian(q)
            q = q + np.linalg.lstsq(J, e, rcond=None)[0]
        return q

    # ------------------------------------------------------------------ motor pulses (§9-3)
    def _set_pulses(self, pulses_per_rad) -> None:
        k = _finite_vector(
            [pulses_per_rad] * self.nq if np.ndim(pulses_per_rad) == 0 else pulses_per_rad,
            "pulses_per_rad",
            self.nq,
        )
        if (k <= 0).any():
            raise ParameterError(f"pulses_per_rad must be > 0 (pulses per joint radian), got {k}")
        Q = np.where(self.valid[..., None], self.Q, 0.0) * k
        if np.abs(Q).max(initial=0.0) >= 2.0**62:
            raise ParameterError("pulses_per_rad too large: the pulse counts overflow int64")
        self.pulses_per_rad = k
        #: integer motor pulses from the origin (q = 0) to every lattice point, (nx, ny, nz, nq);
        #: 0 where ``valid`` is False
        self.pulses = np.rint(Q).astype(np.int64)

    def with_pulses(self, pulses_per_rad) -> "CellTable":
        """A copy of the table that also stores motor pulses (§9-3, l. 7589): the integer
        ``round(q · pulses_per_rad)`` at every lattice point.  ``pulses_per_rad``: a scalar or
        (nq,) motor pulses per joint radian (encoder counts per motor turn × gear ratio / 2π),
        finite and > 0; ValueError otherwise."""
        return type(self)(
            self.model,
            self.params,
            self.rotation,
            self.origin,
            self.D,
            self.Q,
            self.valid,
            point=self.point,
            pulses_per_rad=pulses_per_rad,
        )

    def _require_pulses(self):
        if self.pulses is None:
            raise ParameterError(
                "this cell table stores no motor pulses: use table.with_pulses(pulses_per_rad)"
            )

    def lookup_pulses(self, p) -> np.ndarray:
        """Motor pulses (nq,) int64 from the origin to position ``p`` (3,) m: Eq. (7-32) on the
        stored integer pulses of the 8 corners, rounded to whole pulses.  Raises
        :class:`OutsideCellTableError` if the cell is not covered, ValueError without pulses."""
        self._require_pulses()
        (i, j, k), w = self._cell(p)
        corners = self.pulses[i : i + 2, j : j + 2, k : k + 2].reshape(8, self.nq).astype(float)
        return np.rint(np.dot(w, corners)).astype(np.int64)

    def relative_pulses(self, p_from, p_to) -> np.ndarray:
        """Pulses (nq,) int64 each motor turns to move from ``p_from`` to ``p_to`` (m): the
        difference of the two table lookups, as the position registers of §9-3 compute it."""
        return self.lookup_pulses(p_to) - self.lookup_pulses(p_from)

    def pulses_to_q(self, pulses) -> np.ndarray:
        """Joint values (rad) of motor pulses (nq,) or (N, nq) counted from the origin."""
        self._require_pulses()
        try:
            p = np.asarray(pulses, float)
        except (TypeError, ValueError):
            p = np.zeros(0)
        if p.ndim not in (1, 2) or p.shape[-1] != self.nq or not np.isfinite(p).all():
            raise ParameterError(
                f"pulses must be finite counts of shape ({self.nq},) or (N, {self.nq}), got "
                f"{pulses!r}"
            )
        return p / self.pulses_per_rad

    @property
    def bounds(self):
        return self.origin, self.origin + self.D * (np.array(self.shape) - 1)

    # ------------------------------------------------------------------ persistence
    def save(self, path) -> Path:
        """Write the table to ``path`` (.npz) atomically (temporary file + os.replace)."""
        path = Path(path)
        if path.suffix != ".npz":
            path = path.with_suffix(".npz")
        tmp = path.with_name(path.name + ".tmp.npz")
        extra = {"point": [float(v) for v in self.point]}
        if self.pulses_per_rad is not None:
            extra["pulses_per_rad"] = [float(v) for v in self.pulses_per_rad]
        meta = json.dumps(
            {"model": self.model, "params": self.params, "D": self.D, "format": 1, **extra}
        )
        with open(tmp, "wb") as fh:
            np.savez(
                fh,
                Q=self.Q,
                valid=self.valid,
                origin=self.origin,
                rotation=self.rotation,
                meta=np.array(meta),
            )
        os.replace(tmp, path)
        return path

    @classmethod
    def load(cls, path) -> "CellTable":
        """Read a table written by :meth:`save`.  ValueError if the file is not one."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                meta = json.loads(str(z["meta"]))
                return cls(
                    meta["model"],
                    meta["params"],
                    z["rotation"],
                    z["origin"],
                    meta["D"],
                    z["Q"],
                    z["valid"],
                    point=meta.get("point"),
                    pulses_per_rad=meta.get("pulses_per_rad"),
                )
        except (KeyError, json.JSONDecodeError, OSError, ValueError) as exc:
            if isinstance(exc, FileNotFoundError):
                raise
            raise ValueError(
                f"{path}: not a cell table written by CellTable.save ({exc})"
            ) from None

    def matches(self, robot) -> bool:
        """True if ``robot`` is the model and parameters this table was built for."""
        return (
            robot.spec is not None
            and robot.spec.name == self.model
            and dict(robot.spec.params) == self.params
        )


def cell_table(
    robot,
    *,
    rotation=None,
    bounds=None,
    D: float | None = None,
    branch: str | None = None,
    encoder_counts: float | None = None,
    gear_ratio: float | None = None,
) -> CellTable:
    """The spatial cell table a catalog arm's parameter table declares (``robot.spec.cells``, a
    :class:`~anthroarm.models.spec.CellRecipe`), with the motor pulses stored: the §9-3 care
    robot's table of wrist-centre positions every 10 cm (l. 7589) is one.

    Every lattice point holds the exact IK (:meth:`CellTable.build`, the closed form of the
    arm, branch ``branch``) for the hand orientation ``rotation`` at the positions of the
    recipe's ``point`` of the tool frame, and the motor pulses from the origin (q = 0),
    ``round(q · pulses_per_rad)`` (:meth:`CellTable.with_pulses`).  Every keyword left None
    takes the recipe's value.

    Parameters
    ----------
    robot : Robot
        A catalog arm loaded with its parameter table (``anthroarm.load(NAME, ...)``) whose
        spec declares a cell table.
    rotation : array_like, optional
        Hand orientation of the table, a 3×3 rotation matrix (base frame).
    bounds : tuple, optional
        Box of lattice positions ``(lo, hi)``, two corners of 3 coordinates each, m.
    D : float, optional
        Cell size, m.
    branch : str, optional
        IK branch label stored at every lattice point.
    encoder_counts, gear_ratio : float, optional
        The pulse scale: encoder counts per motor turn and motor turns per joint turn
        (:func:`~anthroarm.models.spec.encoder_pulses_per_rad`).

    Returns
    -------
    CellTable
        With ``point`` and ``pulses`` set: :meth:`CellTable.lookup_pulses` and
        :meth:`CellTable.relative_pulses` answer queries, a point outside the lattice raises
        :class:`OutsideCellTableError`.

    Raises
    ------
    ParameterError
        For a robot without a declared cell table (another arm, or one loaded from a URDF
        without its parameter table) and for bad table parameters.
    """
    spec = getattr(robot, "spec", None)
    recipe = getattr(spec, "cells", None)
    if recipe is None:
        raise ParameterError(
            "cell_table needs a catalog arm whose parameter table declares a cell table "
            "(ChainSpec.cells, e.g. the care robot of §9-3): its point and IK branch are the "
            f"arm's own; got {robot.name!r}"
            + (" without its parameter table (loaded from a URDF?)" if spec is None else "")
        )
    table = CellTable.build(
        robot,
        recipe.rotation if rotation is None else rotation,
        recipe.D if D is None else D,
        recipe.bounds if bounds is None else bounds,
        branch=recipe.branch if branch is None else branch,
        progress=False,
        point=recipe.point,
    )
    return table.with_pulses(recipe.pulses_per_rad(encoder_counts, gear_ratio))
