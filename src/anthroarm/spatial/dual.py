"""Dual numbers, Plücker lines, dual angles and dual orthogonal (screw) matrices (book §5-6).

* :class:`Dual` â = a + ε a*, ε² = 0 (Clifford), Eq. (5-131).  The parts may be numpy
  arrays: + − × ÷ act element-wise, ``@`` is the dual matrix product
  (A + εA*)(B + εB*) = AB + ε(AB* + A*B), ``.T`` transposes.  Functions extend by
  f(â) = f(a) + ε a* f′(a) (rule 5): :func:`sin`, :func:`cos`, :func:`tan`, :func:`sqrt`,
  :func:`atan2`, :func:`acos`, :func:`asin`, Eq. (5-134).
* A dual angle θ̂ = θ + ε θ* (5-133): θ the projected angle between two directed lines, θ* the
  distance along their common perpendicular.
* A line (unit screw, 单位旋量) û_O = u + ε u_O (5-135) with u_O = r × u (Plücker moment about
  the reference point O); :class:`Line`.
* Dual orthogonal matrices (5-145): **passive, old → new** (x̂₂ = Â x̂₁).  If frame II has
  rotation R (columns = II axes in I) and origin p in frame I, Â = Rᵀ(I + εP), P = −[p]×.
  The basic screw matrices (5-146)–(5-149) are :func:`screw_x`, :func:`screw_y`,
  :func:`screw_z`; the pure translation is (5-150).

Convention warning: §5-4/§5-5 matrices are active (new → old); §5-6 matrices are passive
(old → new).  :func:`dual_matrix_from_se3` / :func:`se3_from_dual_matrix` convert between a
Pinocchio ``SE3(R, p)`` (active pose of frame II in frame I) and Â.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import DualDivisionError
from .rotations import (
    as_scalar,
    as_vector3,
    check_rotation,
    check_unit_axis,
    skew,
    unit_axis,
    unskew,
)


class Dual:
    """Dual number (or array / matrix of dual numbers) â = a + ε a*, Eq. (5-131)."""

    __slots__ = ("real", "dual")
    __array_priority__ = 100  # so that ndarray * Dual defers to Dual.__rmul__

    def __init__(self, real, dual=0.0):
        if isinstance(real, (float, int, np.floating, np.integer)) and isinstance(
            dual, (float, int, np.floating, np.integer)
        ):
            self.real, self.dual = float(real), float(dual)  # scalar fast path
            ok = math.isfinite(self.real) and math.isfinite(self.dual)
        else:
            self.real = np.asarray(real, dtype=float)
            self.dual = np.asarray(dual, dtype=float)
            ok = bool(np.isfinite(self.real).all() and np.isfinite(self.dual).all())
        if not ok:
            raise ValueError(
                f"dual number with a NaN or infinite part: {np.asarray(real).tolist()} + "
                f"ε{np.asarray(dual).tolist()}"
            )

    # -- helpers
    @staticmethod
    def lift(x) -> "Dual":
        """x as a dual number (a real x gets dual part 0)."""
        return x if isinstance(x, Dual) else Dual(x, np.zeros_like(np.asarray(x, float)))

    @property
    def pitch(self):
        """P_a = a*/a, Eq. (5-132) (inf for a pure dual number)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(
                np.asarray(self.real) != 0,
                np.asarray(self.dual) / np.where(np.asarray(self.real) != 0, self.real, 1.0),
                np.inf,
            )

    @property
    def shape(self):
        return np.broadcast(np.asarray(self.real), np.asarray(self.dual)).shape

    @property
    def T(self) -> "Dual":
        return Dual(
            np.swapaxes(np.asarray(self.real), -1, -2), np.swapaxes(np.asarray(self.dual), -1, -2)
        )

    def __getitem__(self, idx) -> "Dual":
        r, d = np.broadcast_arrays(np.asarray(self.real), np.asarray(self.dual))
        return Dual(r[idx], d[idx])

    def __repr__(self) -> str:
        return f"Dual({np.asarray(self.real).tolist()!r}, {np.asarray(self.dual).tolist()!r})"

    def __iter__(self):
        for i in range(self.shape[0]):
            yield self[i]

    def __len__(self):
        return self.shape[0]

    # -- arithmetic (rules 2–4 of §5-6)
    def __add__(self, o):
        o = Dual.lift(o)
        return Dual(self.real + o.real, self.dual + o.dual)

    __radd__ = __add__

    def __sub__(self, o):
        o = Dual.lift(o)
        return Dual(self.real - o.real, self.dual - o.dual)

    def __rsub__(self, o):
        return Dual.lift(o) - self

    def __neg__(self):
        return Dual(-self.real, -self.dual)

    def __mul__(self, o):
        o = Dual.lift(o)
        return Dual(self.real * o.real, self.real * o.dual + self.dual * o.real)

    __rmul__ = __mul__

    def __truediv__(self, o):
        o = Dual.lift(o)
        if np.any(np.asarray(o.real) == 0):
            raise DualDivisionError(
                f"division by a dual number with zero real part: {o!r} (a pure dual "
                "number a = 0 + eps b has no inverse)"
            )
        return Dual(self.real / o.real, self.dual / o.real - self.real * o.dual / o.real**2)

    def __rtruediv__(self, o):
        return Dual.lift(o) / self

    def __pow__(self, n):
        if not isinstance(n, (int, np.integer)):
            return exp(log(self) * n)
        return (
            Dual(self.real**n, n * self.real ** (n - 1) * self.dual)
            if n != 0
            else Dual(np.ones_like(np.asarray(self.real)), np.zeros_like(np.asarray(self.dual)))
        )

    def __matmul__(self, o):
        o = Dual.lift(o)
        return Dual(self.real @ o.real, self.real @ o.dual + self.dual @ o.real)

    def __rmatmul__(self, o):
        return Dual.lift(o) @ self

    def __eq__(self, o):  # exact equality of both parts (rule 1)
        o = Dual.lift(o)
        return bool(np.array_equal(self.real, o.real) and np.array_equal(self.dual, o.dual))

    __hash__ = None

    def isclose(self, o, atol: float = 1e-12) -> bool:
        o = Dual.lift(o)
        return bool(
            np.allclose(self.real, o.real, atol=atol, rtol=0)
            and np.allclose(self.dual, o.dual, atol=atol, rtol=0)
        )

    def conj(self) -> "Dual":
        """a − ε a*."""
        return Dual(self.real, -self.dual)


# ----------------------------------------------------------------------------- functions f(â) =
# f(a) + ε a* f′(a)
def _f(x, f, df, name: str = "f"):
    """f(â) = f(a) + ε a* f'(a); ``ValueError`` naming ``name`` when a part of the result cannot
    be represented (e.g. exp of a real part above ~709.78 overflows)."""
    x = Dual.lift(x)
    with np.errstate(over="ignore", invalid="ignore"):
        re, du = f(x.real), x.dual * df(x.real)
    for part, v in (("real", re), ("dual", du)):
        if not np.all(np.isfinite(v)):
            raise ValueError(
                f"{name}({x!r}): the {part} part is beyond the float range "
                f"(largest float {np.finfo(float).max:.6g})"
            )
    return Dual(re, du)


def sin(x) -> Dual:
    """sin θ̂ = sin θ + ε θ* cos θ, Eq. (5-134)."""
    return _f(x, np.sin, np.cos)


def cos(x) -> Dual:
    """cos θ̂ = cos θ − ε θ* sin θ, Eq. (5-134)."""
    return _f(x, np.cos, lambda a: -np.sin(a))


def tan(x) -> Dual:
    return _f(x, np.tan, lambda a: 1.0 / np.cos(a) ** 2)


def exp(x) -> Dual:
    return _f(x, np.exp, np.exp, "exp")


def log(x) -> Dual:
    x = Dual.lift(x)
    if np.any(np.asarray(x.real) <= 0):
        raise ValueError(f"log of a dual number needs a positive real part, got {x!r}")
    return _f(x, np.log, lambda a: 1.0 / a)


def sqrt(x) -> Dual:
    """√â = √a + ε a*/(2√a); ``ValueError`` for a < 0 or for a = 0 with a* ≠ 0 (not defined)."""
    x = Dual.lift(x)
    a = np.asarray(x.real)
    if np.any(a < 0):
        raise ValueError(f"sqrt of a dual number with negative real part: {x!r}")
    if np.any((a == 0) & (np.asarray(x.dual) != 0)):
        raise ValueError(f"sqrt(0 + ε a*) with a* ≠ 0 is not a dual number: {x!r}")
    r = np.sqrt(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(r > 0, np.asarray(x.dual) / (2 * np.where(r > 0, r, 1.0)), 0.0)
    return Dual(r, d)


def atan2(y, x) -> Dual:
    """Dual atan2: atan2(y, x) + ε (x y* − y x*)/(x² + y²).  ``ValueError`` when x = y = 0."""
    y, x = Dual.lift(y), Dual.lift(x)
    r2 = np.asarray(x.real) ** 2 + np.asarray(y.real) ** 2
    if np.any(r2 == 0):
        raise ValueError(f"atan2 of (0, 0) is undefined: y={y!r}, x={x!r}")
    return Dual(np.arctan2(y.real, x.real), (x.real * y.dual - y.real * x.dual) / r2)


def acos(x) -> Dual:
    """acos â = acos a − ε a*/√(1 − a²); ``ValueError`` for |a| > 1 or |a| = 1 (derivative
    infinite)."""
    x = Dual.lift(x)
    a = np.asarray(x.real)
    if np.any(np.abs(a) >= 1):
        raise ValueError(f"acos of a dual number needs |real part| < 1, got {x!r}")
    return _f(x, np.arccos, lambda t: -1.0 / np.sqrt(1 - t**2))


def asin(x) -> Dual:
    x = Dual.lift(x)
    if np.any(np.abs(np.asarray(x.real)) >= 1):
        raise ValueError(f"asin of a dual number needs |real part| < 1, got {x!r}")
    return _f(x, np.arcsin, lambda t: 1.0 / np.sqrt(1 - t**2))


def dual_angle(theta, distance=0.0) -> Dual:
    """θ̂ = θ + ε θ*, Eq. (5-133) (also the link angle α̂ᵢⱼ = αᵢⱼ + ε aᵢⱼ and joint angle
    θ̂ⱼ = θⱼ + ε sⱼ of Eq. (5-151))."""
    return Dual(float(theta), float(distance))


# ----------------------------------------------------------------------------- dual vectors
def dot(a: Dual, b: Dual) -> Dual:
    """Dual dot product â·b̂ = a·b + ε(a·b* + a*·b) (= cos θ̂ for unit lines, Eq. (5-141))."""
    a, b = Dual.lift(a), Dual.lift(b)
    return Dual(np.sum(a.real * b.real, -1), np.sum(a.real * b.dual + a.dual * b.real, -1))


def cross(a: Dual, b: Dual) -> Dual:
    """Dual cross product â×b̂ = a×b + ε(a×b* + a*×b) (= ŝ sin θ̂ for unit lines, Eq. (5-141))."""
    a, b = Dual.lift(a), Dual.lift(b)
    return Dual(np.cross(a.real, b.real), np.cross(a.real, b.dual) + np.cross(a.dual, b.real))


def norm(a: Dual) -> Dual:
    """Dual length √(â·â) (= 1 for a line, Eq. (5-143))."""
    return sqrt(dot(a, a))


# ----------------------------------------------------------------------------- lines
@dataclass(frozen=True)
class Line:
    """A directed line (unit line vector / unit screw) û_O = u + ε u_O, Eq. (5-135).

    ``u`` is the unit direction, ``moment`` = u_O = r × u about the reference point O for any
    point r on the line (5-136)/(5-137).  Plücker coordinates (u, u_O): u·u = 1, u·u_O = 0
    (5-144).  Lengths in m."""

    u: np.ndarray
    moment: np.ndarray

    def __post_init__(self):
        u = check_unit_axis(self.u, "line direction u")
        m = as_vector3(self.moment, "line moment")
        if abs(float(u @ m)) > 1e-9 * max(1.0, float(np.linalg.norm(m))):
            raise ValueError(
                f"not a line: direction {u.tolist()} and moment {m.tolist()} are not perpendicular "
                f"(u·m = {float(u @ m):.3e})"
            )
        object.__setattr__(self, "u", u)
        object.__setattr__(self, "moment", m)

    @classmethod
    def from_point_direction(cls, point, direction) -> "Line":
        """The line through ``point`` along ``direction`` (normalised; zero → ValueError)."""
        u = unit_axis(direction, "line direction")
        r = as_vector3(point, "point")
        return cls(u, np.cross(r, u))

    @classmethod
    def from_dual(cls, d: Dual) -> "Line":
        return cls(np.asarray(d.real, float), np.asarray(d.dual, float))

    def as_dual(self) -> Dual:
        return Dual(self.u, self.moment)

    def foot(self) -> np.ndarray:
        """d = u × u_O, Eq. (5-138): the foot of the perpendicular from O to the line."""
        return np.cross(self.u, self.moment)

    def moved(self, A) -> "Line":
        """The same line referred to the point A (coordinates of A relative to O), Eq.
        (5-139)/(5-140): u_A = AO × u + u_O with AO = O − A."""
        A = as_vector3(A, "reference point A")
        return Line(self.u, np.cross(-A, self.u) + self.moment)

    def transformed(self, R, p) -> "Line":
        """The line after the active rigid motion x ↦ R x + p (Plücker: u′ = R u,
        m′ = R m + p × R u; ``pin.SE3(R, p).act(Motion(m, u))``)."""
        R = check_rotation(R, "R")
        p = as_vector3(p, "p")
        u = R @ self.u
        return Line(u, R @ self.moment + np.cross(p, u))

    def distance_to_point(self, x) -> float:
        x = as_vector3(x, "point")
        return float(np.linalg.norm(np.cross(x, self.u) - self.moment))

    def as_motion(self):
        """The zero-pitch unit twist ``pin.Motion(linear=u_O, angular=u)`` of this line."""
        return pin.Motion(self.moment, self.u)


def line_dual_angle(a: Line, b: Line, tol: float = 1e-12) -> tuple[Dual, np.ndarray | None]:
    """Dual angle θ̂ = θ + ε θ* from line a to line b, Eq. (5-133), and the direction n of the
    common perpendicular (θ measured about n, θ* = signed distance along n from a to b).

    Skew lines: proper dual angle; intersecting: θ* = 0; parallel: θ = 0 or π and n is the
    direction from a to b (None for coincident lines).  Satisfies â·b̂ = cos θ̂ and
    â×b̂ = n̂ sin θ̂ (5-141)."""
    c = np.cross(a.u, b.u)
    sn = float(np.linalg.norm(c))
    pa, pb = a.foot(), b.foot()
    if sn > tol:
        n = c / sn
        theta = float(np.arctan2(sn, float(a.u @ b.u)))
        # signed distance: project (any b point − any a point) on n
        dist = float(n @ (pb - pa))
        return Dual(theta, dist), n
    theta = 0.0 if a.u @ b.u > 0 else float(np.pi)
    d = pb - pa
    d = d - (d @ a.u) * a.u
    dist = float(np.linalg.norm(d))
    return Dual(theta, dist), (d / dist if dist > tol else None)


# ----------------------------------------------------------------------------- dual orthogonal
# matrices
_PX = -skew([1.0, 0, 0])
_PY = -skew([0, 1.0, 0])
_PZ = -skew([0, 0, 1.0])


def _passive(axis: int, angle: Dual) -> Dual:
    """Passive (old → new) basic dual rotation matrix about coordinate axis ``axis``:
    real part R_kᵀ(θ), dual part θ* · d/dθ R_kᵀ(θ) (rule 5 element-wise)."""
    a = Dual.lift(angle)
    t, ts = float(a.real), float(a.dual)
    c, s = math.cos(t), math.sin(t)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]  # the rotated plane (i, j), cyclic
    R = np.eye(3)
    Dm = np.zeros((3, 3))
    R[i, i] = R[j, j] = c
    R[i, j], R[j, i] = s, -s
    Dm[i, i] = Dm[j, j] = -s * ts
    Dm[i, j], Dm[j, i] = c * ts, -c * ts
    return Dual(R, Dm)


def screw_x(phi, phi_star=None) -> Dual:
    """φ̂_x, Eq. (5-146)/(5-147): rotation φ about and translation φ* along x, passive;
    = φ_x (I + ε φ* P_x).  ``phi`` may be a :class:`Dual` (then ``phi_star`` is omitted)."""
    return _passive(0, phi if phi_star is None else Dual(float(phi), float(phi_star)))


def screw_y(theta, theta_star=None) -> Dual:
    """θ̂_y, Eq. (5-148) = θ_y (I + ε θ* P_y), passive."""
    return _passive(1, theta if theta_star is None else Dual(float(theta), float(theta_star)))


def screw_z(psi, psi_star=None) -> Dual:
    """ψ̂_z, Eq. (5-149) = ψ_z (I + ε ψ* P_z), passive."""
    return _passive(2, psi if psi_star is None else Dual(float(psi), float(psi_star)))


def P_matrix(axis: str) -> np.ndarray:
    """P_x, P_y, P_z of Eq. (5-147)–(5-149): P_k = −[e_k]×."""
    return {"x": _PX, "y": _PY, "z": _PZ}[axis].copy()


def translation_dual(px: float, py: float, pz: float) -> Dual:
    """Pure translation (φ*, θ*, ψ*) as a dual matrix, Eq. (5-150): I + ε(φ*P_x + θ*P_y + ψ*P_z)."""
    px, py, pz = as_scalar(px, "px"), as_scalar(py, "py"), as_scalar(pz, "pz")
    return Dual(np.eye(3), px * _PX + py * _PY + pz * _PZ)


def dual_matrix_from_se3(R, p) -> Dual:
    """Â = Rᵀ(I + εP), P = −[p]×, for frame II at rotation R and origin p in frame I
    (``pin.SE3(R, p)``).  Â maps a line's dual coordinates in I to those in II (5-145)."""
    R = check_rotation(R, "R")
    p = as_vector3(p, "p")
    return Dual(R.T, -R.T @ skew(p))


def se3_from_dual_matrix(A: Dual, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """(R, p) of a dual orthogonal matrix (inverse of :func:`dual_matrix_from_se3`).
    ``ValueError`` if Â Âᵀ ≠ I (real part not orthogonal, or dual part not R-skew)."""
    check_dual_orthogonal(A, tol)
    R = np.asarray(A.real, float).T
    Pm = R @ np.asarray(A.dual, float)
    return R, -unskew(Pm)


def check_dual_orthogonal(A: Dual, tol: float = 1e-9) -> Dual:
    """Â Âᵀ = I (six dual row relations, §5-6 三); ``ValueError`` with the residual otherwise."""
    if not isinstance(A, Dual) or np.shape(A.real) != (3, 3) or np.shape(A.dual) != (3, 3):
        raise ValueError(f"expected a 3x3 dual matrix, got {A!r}")
    check_rotation(A.real, "real part of the dual matrix")
    M = A @ A.T
    err = max(float(np.abs(M.real - np.eye(3)).max()), float(np.abs(M.dual).max()))
    if err > tol:
        raise ValueError(
            f"dual matrix is not dual-orthogonal: max |Â Âᵀ − I| = {err:.3e} (dual part "
            f"{np.asarray(A.dual).tolist()})"
        )
    return A


def transform_line(A: Dual, line: Line) -> Line:
    """x̂₂ = Â x̂₁, Eq. (5-145): the dual coordinates of a line in the new frame."""
    return Line.from_dual(A @ line.as_dual())
