"""OpenSim's one-argument functions, evaluated exactly as OpenSim does, with their first and
second derivatives, on arrays.

A ``TransformAxis`` of a ``CustomJoint`` and a ``CoordinateCouplerConstraint`` hold one of these
functions of a coordinate.  Each class here reproduces the OpenSim 4.x source it names
(opensim-core, ``OpenSim/Common``), so that a pose computed here equals OpenSim's to rounding:

* ``Constant`` — ``Constant.cpp``: ``SimTK::Function::Constant``.
* ``LinearFunction`` — ``LinearFunction.cpp``: ``SimTK::Function::Linear`` with the
  coefficients (slope, intercept): f(x) = slope·x + intercept.
* ``SimmSpline`` (and ``NaturalCubicSpline``, which ``RegisterTypes_osimCommon.cpp`` renames to
  ``SimmSpline``) — ``SimmSpline.cpp``: Peter Loan's cubic spline (Forsythe, Malcolm & Moler's
  ``spline``): end conditions from third divided differences, linear extrapolation with the
  end slopes outside the knots, the end values returned exactly within 2e-13 of an end knot
  (``SimmMacros.h``: ``ROUNDOFF_ERROR``), knot spacing floored at 1e-7 (``TINY_NUMBER``).
* ``PolynomialFunction`` — ``PolynomialFunction.h``: ``SimTK::Function::Polynomial``,
  coefficients from the highest power down.
* ``MultiplierFunction`` — ``MultiplierFunction.cpp``: scale · f(x).
* ``PiecewiseLinearFunction`` — ``PiecewiseLinearFunction.cpp``: linear between knots, the
  end segments' slopes outside.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: SimmMacros.h
TINY_NUMBER = 1e-7
ROUNDOFF_ERROR = 2e-13


class Function:
    """A function of one coordinate: :meth:`eval` returns (f, f', f'') at ``x`` (an array)."""

    #: the OpenSim class name
    kind = ""
    #: a constant (no coordinate)
    constant = False

    def eval(self, x):  # pragma: no cover - every subclass overrides
        raise NotImplementedError

    def value(self, x):
        return self.eval(np.asarray(x, dtype=float))[0]

    @property
    def identity(self) -> bool:
        """f(x) = x exactly (a LinearFunction with slope 1 and intercept 0)."""
        return False


@dataclass(frozen=True, eq=False)
class Constant(Function):
    c: float
    kind = "Constant"
    constant = True

    def eval(self, x):
        x = np.asarray(x, dtype=float)
        z = np.zeros_like(x)
        return z + self.c, z, z


@dataclass(frozen=True, eq=False)
class Linear(Function):
    slope: float
    intercept: float
    kind = "LinearFunction"

    def eval(self, x):
        x = np.asarray(x, dtype=float)
        z = np.zeros_like(x)
        return self.slope * x + self.intercept, z + self.slope, z

    @property
    def identity(self) -> bool:
        return self.slope == 1.0 and self.intercept == 0.0


@dataclass(frozen=True, eq=False)
class Polynomial(Function):
    coefficients: tuple  # highest power first
    kind = "PolynomialFunction"

    def eval(self, x):
        x = np.asarray(x, dtype=float)
        c = np.asarray(self.coefficients, dtype=float)
        d1 = np.polyder(c) if c.size > 1 else np.zeros(1)
        d2 = np.polyder(d1) if d1.size > 1 else np.zeros(1)
        return _horner(c, x), _horner(d1, x), _horner(d2, x)


def _horner(c, x):
    out = np.zeros_like(x) + c[0]
    for a in c[1:]:
        out = out * x + a
    return out


@dataclass(frozen=True, eq=False)
class Multiplier(Function):
    scale: float
    inner: Function
    kind = "MultiplierFunction"

    @property
    def constant(self) -> bool:  # type: ignore[override]
        return self.inner.constant

    def eval(self, x):
        f, f1, f2 = self.inner.eval(x)
        return f * self.scale, f1 * self.scale, f2 * self.scale


class PiecewiseLinear(Function):
    kind = "PiecewiseLinearFunction"

    def __init__(self, x, y):
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.slope = np.diff(self.y) / np.maximum(np.diff(self.x), TINY_NUMBER)

    def eval(self, x):
        x = np.asarray(x, dtype=float)
        k = np.clip(np.searchsorted(self.x, x, side="right") - 1, 0, self.x.size - 2)
        s = self.slope[k]
        return self.y[k] + (x - self.x[k]) * s, s, np.zeros_like(x)


class SimmSpline(Function):
    """OpenSim's ``SimmSpline`` (``SimmSpline.cpp``, ``calcCoefficients`` / ``calcValue`` /
    ``calcDerivative``): cubic pieces y_k + b_k dx + c_k dx² + d_k dx³ with dx = x − x_k."""

    kind = "SimmSpline"

    def __init__(self, x, y):
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.b, self.c, self.d = _simm_coefficients(self.x, self.y)

    def eval(self, x):
        x = np.asarray(x, dtype=float)
        xs, ys, b, c, d = self.x, self.y, self.b, self.c, self.d
        n = xs.size
        # the interval k with x_k <= x <= x_{k+1} (the binary search of calcValue)
        k = np.clip(np.searchsorted(xs, x, side="left") - 1, 0, n - 2)
        dx = x - xs[k]
        f = ys[k] + dx * (b[k] + dx * (c[k] + dx * d[k]))
        f1 = b[k] + dx * (2.0 * c[k] + 3.0 * dx * d[k])
        f2 = 2.0 * c[k] + 6.0 * dx * d[k]
        lo, hi = x < xs[0], x > xs[-1]
        at_lo = ~lo & (np.abs(x - xs[0]) <= ROUNDOFF_ERROR)
        at_hi = ~hi & ~at_lo & (np.abs(x - xs[-1]) <= ROUNDOFF_ERROR)
        f = np.where(lo, ys[0] + (x - xs[0]) * b[0], f)
        f = np.where(hi, ys[-1] + (x - xs[-1]) * b[-1], f)
        f = np.where(at_lo, ys[0], f)
        f = np.where(at_hi, ys[-1], f)
        f1 = np.where(lo | at_lo, b[0], f1)
        f1 = np.where(hi | at_hi, b[-1], f1)
        f2 = np.where(lo | hi, 0.0, f2)
        f2 = np.where(at_lo, 2.0 * c[0], f2)
        f2 = np.where(at_hi, 2.0 * c[-1], f2)
        return f, f1, f2


def _simm_coefficients(x, y):
    """``SimmSpline::calcCoefficients`` line by line (n >= 2 knots)."""
    n = x.size
    b, c, d = np.zeros(n), np.zeros(n), np.zeros(n)
    if n == 2:
        t = max(TINY_NUMBER, x[1] - x[0])
        b[0] = b[1] = (y[1] - y[0]) / t
        return b, c, d
    nm1, nm2 = n - 1, n - 2
    d[0] = max(TINY_NUMBER, x[1] - x[0])
    c[1] = (y[1] - y[0]) / d[0]
    for i in range(1, nm1):
        d[i] = max(TINY_NUMBER, x[i + 1] - x[i])
        b[i] = 2.0 * (d[i - 1] + d[i])
        c[i + 1] = (y[i + 1] - y[i]) / d[i]
        c[i] = c[i + 1] - c[i]
    b[0] = -d[0]
    b[nm1] = -d[nm2]
    c[0] = 0.0
    c[nm1] = 0.0
    if n > 3:
        d31 = max(TINY_NUMBER, x[3] - x[1])
        d20 = max(TINY_NUMBER, x[2] - x[0])
        d1 = max(TINY_NUMBER, x[nm1] - x[n - 3])
        d2 = max(TINY_NUMBER, x[nm2] - x[n - 4])
        d30 = max(TINY_NUMBER, x[3] - x[0])
        d3 = max(TINY_NUMBER, x[nm1] - x[n - 4])
        c[0] = c[2] / d31 - c[1] / d20
        c[nm1] = c[nm2] / d1 - c[n - 3] / d2
        c[0] = c[0] * d[0] * d[0] / d30
        c[nm1] = -c[nm1] * d[nm2] * d[nm2] / d3
    for i in range(1, n):  # forward elimination
        t = d[i - 1] / b[i - 1]
        b[i] -= t * d[i - 1]
        c[i] -= t * c[i - 1]
    c[nm1] /= b[nm1]  # back substitution
    for j in range(nm1):
        i = nm2 - j
        c[i] = (c[i] - d[i] * c[i + 1]) / b[i]
    b[nm1] = (y[nm1] - y[nm2]) / d[nm2] + d[nm2] * (c[nm2] + 2.0 * c[nm1])
    for i in range(nm1):
        b[i] = (y[i + 1] - y[i]) / d[i] - d[i] * (c[i + 1] + 2.0 * c[i])
        d[i] = (c[i + 1] - c[i]) / d[i]
        c[i] *= 3.0
    c[nm1] *= 3.0
    d[nm1] = d[nm2]
    return b, c, d
