"""Private helpers of :mod:`anthroarm.mechanisms`: input validation and 3x3 rotation algebra.

The rotation helpers are the 002 text's matrices (book notation in brackets); ``rot`` is
:func:`anthroarm.spatial.screw.rotation_matrix`, the others are batched local versions of
``spatial.screw`` (checked equal in ``tests/mechanisms/test_mech_util.py``):

* ``skew(u)`` = [P_u], the cross-product matrix, 002 line 185 and Eq. (6-89) with the
  *standard* sign pattern (the print swaps u_x and u_z, see docs/errata.md); it is
  :func:`anthroarm.spatial.rotations.skew`, as are the scalar and unit-axis checks;
* ``rot(theta, u)`` = [R_{theta,u}] = -[P_u]^2 cos(theta) + [P_u] sin(theta) + [Q_u], Eq. (6-89),
  equal to Rodrigues' form (6-88) and to ``pin.exp3(theta * u)``;
* ``W(thetadot, u)`` = [W_{thetadot,u}] = thetadot [P_u], Eq. (6-91);
* ``Wdot(thetadot, thetaddot, u)`` = [E] = thetaddot [P_u] + thetadot^2 [P_u]^2, Eq. (6-92)
  for a fixed axis (002 (4-28)).

All frames are world frames, right-handed, SI units.
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from ..errors import ParameterError
from ..spatial.rotations import UNIT_TOL, as_scalar, check_unit_axis, skew  # noqa: F401  (re-exported)
from ..spatial.screw import rotation_matrix


def _short(x, n: int = 80) -> str:
    """``repr(x)`` cut to ``n`` characters, for error messages."""
    r = repr(x)
    return r if len(r) <= n else r[: n - 3] + "..."


def _not_a_number(x) -> bool:
    """None, a str/bytes or a bool: values numpy would turn into a number (NaN, a parsed float,
    0/1) that are never a length, angle or coordinate the caller meant."""
    return x is None or isinstance(x, (str, bytes, bool, np.bool_))


def finite_scalar(name: str, x) -> float:
    """``float(x)`` or :class:`~anthroarm.errors.ParameterError` (a ``ValueError``) naming
    ``name`` when x is not a finite real scalar (:func:`anthroarm.spatial.rotations.as_scalar`
    with the name first)."""
    if _not_a_number(x):
        raise ParameterError(
            f"{name} must be a finite real number, got {type(x).__name__} {_short(x)}"
        )
    try:
        return as_scalar(x, name)
    except (TypeError, ValueError) as exc:
        raise ParameterError(str(exc)) from None


def positive_length(name: str, x) -> float:
    """``float(x)``; :class:`~anthroarm.errors.ParameterError` naming ``name`` unless x is a
    finite length > 0."""
    v = finite_scalar(name, x)
    if v <= 0.0:
        raise ParameterError(f"{name} must be a positive length (> 0, finite), got {_short(x)}")
    return v


def finite_array(name: str, x, shape=None) -> np.ndarray:
    """Float array (copy) of ``x``; :class:`~anthroarm.errors.ParameterError` (a ``ValueError``
    and a ``TypeError``) naming ``name`` for a value that is not an array of real numbers, a
    wrong shape or NaN/inf.

    ``shape`` may contain ``None`` for "any size" in that position (checked from the end)."""
    want = "" if shape is None else f" of shape {tuple('N' if s is None else s for s in shape)}"
    if _not_a_number(x):
        raise ParameterError(
            f"{name} must be a real array{want}, got {type(x).__name__} {_short(x)}"
        )
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{name} must be a real array{want}, got {_short(x)}") from None
    if (isinstance(x, np.ndarray) and x.dtype.kind in "USb") or (
        isinstance(x, (list, tuple)) and _has_strings(x)
    ):
        raise ParameterError(f"{name} must be a real array{want}, got {_short(x)}")
    if shape is not None:
        tail = a.shape[len(a.shape) - len(shape) :] if len(a.shape) >= len(shape) else None
        if (
            tail is None
            or len(a.shape) != len(shape)
            or any(s is not None and s != t for s, t in zip(shape, tail))
        ):
            raise ParameterError(
                f"{name} must have shape {tuple('N' if s is None else s for s in shape)}, got "
                f"{a.shape}"
            )
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"{name} must be finite, got {_short(x)}")
    return a


def _has_strings(x) -> bool:
    """True when the nested list/tuple ``x`` holds a str/bytes/None (numpy parses "1.5" and
    turns None into NaN)."""
    for v in x:
        if isinstance(v, (list, tuple)):
            if _has_strings(v):
                return True
        elif v is None or isinstance(v, (str, bytes)):
            return True
    return False


def point3(name: str, x) -> np.ndarray:
    return finite_array(name, x, (3,))


def unit_axis(name: str, u) -> np.ndarray:
    """A 3-vector that must already be a unit vector (|u| = 1 within 1e-9);
    :class:`~anthroarm.errors.ParameterError` (a ``ValueError``) otherwise.

    :func:`anthroarm.spatial.rotations.check_unit_axis` restricted to one axis of shape (3,),
    then divided by its norm (so that |u| = 1 to rounding)."""
    p = point3(name, u)
    try:
        a = check_unit_axis(p, name)
    except ValueError as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(
            f"{exc} ({name} must be a unit 3-vector, |{name}| = 1 within {UNIT_TOL:g})"
        ) from None
    return a / float(np.linalg.norm(a))


def rot(theta, u) -> np.ndarray:
    """[R_{theta,u}] = -[P_u]^2 cos + [P_u] sin + [Q_u], Eq. (6-89) (corrected skew); batched in
    theta.

    Delegates to :func:`anthroarm.spatial.screw.rotation_matrix` (002 line 185)."""
    return rotation_matrix(theta, u)


def W(thetadot, u) -> np.ndarray:
    """[W_{thetadot,u}] = thetadot [P_u], Eq. (6-91): W @ r == (thetadot u) x r."""
    return np.asarray(thetadot, dtype=float)[..., None, None] * skew(u)


def Wdot(thetadot, thetaddot, u) -> np.ndarray:
    """Angular-acceleration matrix for a fixed axis, Eq. (6-92) / 002 (4-28):
    thetaddot [P_u] + thetadot^2 [P_u]^2, so that r_ddot = Wdot @ r for r fixed in the body."""
    P = skew(u)
    return np.asarray(thetaddot, dtype=float)[..., None, None] * P + np.asarray(
        thetadot, dtype=float
    )[..., None, None] ** 2 * (P @ P)


def wrap(a):
    """Angle(s) wrapped to (-pi, pi]."""
    a = np.asarray(a, dtype=float)
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi
    w = np.where(w == -np.pi, np.pi, w)
    return float(w) if w.ndim == 0 else w


def out(x):
    """Scalars as Python floats/bools/str, arrays unchanged."""
    a = np.asarray(x)
    if a.ndim == 0:
        return a.item()
    return a


# 8th-order central finite-difference stencils (offsets 1..4)
_D1 = np.array([4 / 5, -1 / 5, 4 / 105, -1 / 280])
_D2 = np.array([8 / 5, -1 / 5, 8 / 315, -1 / 560])
_D2_0 = -205 / 72


def assembly_status(assembled, dead, x, disc, x_name: str, dead_reason: str, eq: str = ""):
    """Status array ("ok", "dead_point", "cannot_assemble") of a closure with discriminant
    E² + F² − G² (``disc``) at input ``x``, and one reason string: for a scalar input the
    reason of its state (``dead_reason`` at a branch point), for a batch the counts.  ``eq``
    names the book's equation of the assembly condition, e.g. " (4-31)"."""
    st = np.where(~assembled, "cannot_assemble", np.where(dead, "dead_point", "ok"))
    if np.ndim(x) == 0:
        reason = {
            "ok": "ok",
            "dead_point": dead_reason,
            "cannot_assemble": f"cannot assemble at {x_name} = {float(x):.6g}: "
            f"E^2 + F^2 - G^2 = {float(disc):.6g} < 0{eq}",
        }[str(st)]
    else:
        na, nd = int(np.sum(~assembled)), int(np.sum(dead))
        reason = (
            "ok"
            if na == nd == 0
            else f"{na} of {np.size(x)} cannot assemble{eq}, {nd} at a branch point"
        )
    return st, reason


def _stencil_sums(f, h: float, angular: bool):
    """Σ_k D1_k (f(kh) − f(−kh)) and Σ_k D2_k (f(kh) + f(−kh) − 2 f(0)) over k = 1..4, the
    numerators of the first and second derivative (values taken relative to f(0), so the centre
    weight of the second-derivative stencil drops out; wrapped to (-pi, pi] when ``angular``)."""
    f0 = np.asarray(f(0.0), dtype=float)
    d1 = np.zeros_like(f0)
    d2 = _D2_0 * np.zeros_like(f0)
    for k in range(1, 5):
        fp = np.asarray(f(k * h), dtype=float) - f0
        fm = np.asarray(f(-k * h), dtype=float) - f0
        if angular:
            fp, fm = np.asarray(wrap(fp)), np.asarray(wrap(fm))
        d1 = d1 + _D1[k - 1] * (fp - fm)
        d2 = d2 + _D2[k - 1] * (fp + fm)
    return d1, d2


def fd_rates(f, h: float = 1e-2, angular: bool = False):
    """First and second derivative at t = 0 of ``f(t)`` (array-valued) by 8th-order central
    differences.  ``angular=True`` wraps differences to (-pi, pi] (for angle outputs).

    Used as the *mathematical* oracle of the mechanism rates: for smooth outputs with
    derivatives of order one, h = 1e-2 gives errors ~1e-12 (truncation h^8, round-off eps/h^2)."""
    d1, d2 = _stencil_sums(f, h, angular)
    return d1 / h, d2 / (h * h)


def fd_derivative(f, h: float = 1e-3, angular: bool = False):
    """First derivative at t = 0 of ``f(t)`` by the 8th-order central stencil (round-off ~eps/h).

    The accelerations of the mechanisms are checked as the derivative of their (closed-form,
    itself finite-difference-checked) velocity along the trajectory: this keeps the oracle at
    ~1e-12 where a second difference of positions is limited to ~eps/h^2."""
    return _stencil_sums(f, h, angular)[0] / h


def pow2_scale(*xs) -> float:
    """The largest power of two not above max |x| over ``xs`` (1.0 when all are 0).

    Dividing by a power of two is exact (for normal numbers), so formulas evaluated on
    ``x / pow2_scale(...)`` and scaled back give the same bits as the unscaled ones wherever those
    do not overflow, and finite answers where the squares of the raw lengths would overflow."""
    m = max(
        (float(np.max(np.abs(np.asarray(x, dtype=float)), initial=0.0)) for x in xs), default=0.0
    )
    if not np.isfinite(m):
        raise ParameterError(
            f"a length or coordinate is beyond the float range ({m}); inputs must be finite"
        )
    if m == 0.0:
        return 1.0
    return float(np.ldexp(1.0, np.frexp(m)[1] - 1))


def norm(name: str, v, axis=-1):
    """|v| along ``axis`` without overflow or underflow of the squares (v / 2^k first);
    :class:`~anthroarm.errors.ParameterError` naming ``name`` when a difference of coordinates
    already overflowed."""
    v = np.asarray(v, dtype=float)
    if not np.all(np.isfinite(v)):
        raise ParameterError(f"{name} is beyond the float range: the coordinates are too far apart")
    s = pow2_scale(v)
    return s * np.linalg.norm(v / s, axis=axis)


def representable(name: str, x, why: str):
    """``x`` (computed under ``np.errstate(over='ignore', invalid='ignore')``) as a float array,
    or :class:`~anthroarm.errors.ParameterError` naming ``name`` when it holds inf/NaN: the true
    value exists but is beyond the float range (``why`` says which inputs make it so)."""
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ParameterError(
            f"{name} cannot be represented in floating point ({why}); use other units or smaller "
            "rates"
        )
    return x


def difference(name: str, a, b):
    """``a - b`` or :class:`~anthroarm.errors.ParameterError` naming ``name`` when the difference
    overflows."""
    with np.errstate(over="ignore", invalid="ignore"):
        d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return representable(name, d, "the points are too far apart")


def representable_fields(state, why: str):
    """``state`` (a dataclass computed under ``np.errstate(over='ignore', invalid='ignore')``)
    unchanged, or :class:`~anthroarm.errors.ParameterError` naming the first numeric field that
    holds inf/NaN (its true value is beyond the float range; ``why`` names the inputs that make it
    so)."""
    for f in fields(state):
        v = getattr(state, f.name)
        if isinstance(v, (str, bool, np.bool_)) or v is None:
            continue
        a = np.asarray(v)
        if a.dtype.kind in "fc":
            representable(f.name, a, why)
    return state
