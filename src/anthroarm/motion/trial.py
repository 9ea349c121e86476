"""Marker trajectories of a recorded trial (what a C3D file holds, in SI units).

:class:`MarkerTrajectories` keeps ``positions`` (N frames, M markers, 3) in metres in the
laboratory (world) frame, the marker ``names`` and the sampling ``rate`` (Hz).  A marker that
was not seen in a frame (occluded, a gap) is NaN in all three coordinates there: that is the
C3D convention (residual −1) and the only place anthroarm keeps NaN on purpose; ``visible``
is the mask, and marker IK gives such samples zero weight.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import MotionDataError

#: the largest marker coordinate accepted, m: beyond it a value is not a position in a lab (wrong
#: units, a corrupt sample) and its squares would overflow the marker-IK residuals to inf
MAX_COORDINATE = 1e6


def check_coordinates(P: np.ndarray, names, path=None) -> None:
    """Raise :class:`~anthroarm.errors.MotionDataError` naming the first marker and frame whose
    finite coordinate exceeds :data:`MAX_COORDINATE` in magnitude (``P`` is (N, M, 3), m)."""
    big = np.isfinite(P) & (np.abs(np.nan_to_num(P)) > MAX_COORDINATE)
    if big.any():
        n, k, _ = np.argwhere(big)[0]
        raise MotionDataError(
            f"marker {names[k]!r} in frame {n} is at {P[n, k].tolist()} m, beyond "
            f"{MAX_COORDINATE:g} m: not a position in a lab (wrong units?)",
            path,
        )


@dataclass
class MarkerTrajectories:
    """Marker positions of a trial.

    Attributes
    ----------
    names : tuple of str
        Marker labels, one per column (unique).
    positions : (N, M, 3) array
        World positions, m; NaN where a marker is missing.  A coordinate beyond
        :data:`MAX_COORDINATE` (1e6 m) is a :class:`~anthroarm.errors.MotionDataError`.
    rate : float
        Frame rate, Hz (> 0).
    source : str
        Where it came from (a file path), for messages.
    """

    names: tuple
    positions: np.ndarray
    rate: float = 100.0
    source: str = "<array>"
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        self.names = tuple(str(n) for n in self.names)
        try:
            P = np.array(self.positions, dtype=float)
        except (TypeError, ValueError):
            raise MotionDataError("marker positions must be numbers (m)", self._path()) from None
        if P.ndim != 3 or P.shape[2] != 3 or P.shape[1] != len(self.names):
            raise MotionDataError(
                f"marker positions must have shape (frames, {len(self.names)} markers, 3), "
                f"got {P.shape}",
                self._path(),
            )
        if len(set(self.names)) != len(self.names):
            dup = sorted({n for n in self.names if self.names.count(n) > 1})
            raise MotionDataError(f"duplicate marker labels {dup}", self._path())
        if not (
            isinstance(self.rate, (int, float, np.floating, np.integer))
            and np.isfinite(self.rate)
            and self.rate > 0
        ):
            raise MotionDataError(
                f"frame rate must be a positive number (Hz), got {self.rate!r}", self._path()
            )
        self.rate = float(self.rate)
        check_coordinates(P, self.names, self._path())
        bad = ~np.isfinite(P).all(axis=2)
        P[bad] = np.nan  # a marker is seen in all three coordinates or missing
        self.positions = P

    def _path(self):
        return None if self.source == "<array>" else self.source

    def __len__(self) -> int:
        return self.positions.shape[0]

    def __repr__(self) -> str:
        return (
            f"MarkerTrajectories({len(self)} frames at {self.rate:g} Hz, {len(self.names)} "
            f"markers, {self.visible.mean() * 100:.1f} % visible, source={self.source!r})"
        )

    @property
    def n_frames(self) -> int:
        return self.positions.shape[0]

    @property
    def visible(self) -> np.ndarray:
        """(N, M) bool: the marker was seen in that frame."""
        return np.isfinite(self.positions).all(axis=2)

    @property
    def time(self) -> np.ndarray:
        """(N,) s from the first frame."""
        return np.arange(self.n_frames) / self.rate

    def marker(self, name: str) -> np.ndarray:
        """(N, 3) trajectory of one marker (m, NaN where missing)."""
        if name not in self.names:
            raise MotionDataError(
                f"no marker {name!r}; markers: {', '.join(self.names)}", self._path()
            )
        return self.positions[:, self.names.index(name)]
