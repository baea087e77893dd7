"""Piecewise polynomials of the table blocks, as expressions.

Input: a table's abscissae and one column of ordinates, its smoothness and
extrapolation (numbers as in ``Modelica.Blocks.Types``). Output: an expression of the
input ``u`` that a binary search of nested ``if noEvent(u < b)`` selects the segment
of (``log2(n)`` deep), each segment a cubic in ``u - x_i`` (Horner form). The
formulas are those the Modelica Standard Library documents for CombiTable1D and
CombiTimeTable: linear and constant segments, cubic Hermite splines whose slopes are
Akima's (1970), modified Akima's, Fritsch-Butland's (1984) or Steffen's (1990), and
extrapolation that holds the last point, continues the end slope, or repeats the table.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ...ir import expr as x

LINEAR, AKIMA, CONSTANT, FRITSCH_BUTLAND, STEFFEN, MODIFIED_AKIMA = 1, 2, 3, 4, 5, 6
"""``Modelica.Blocks.Types.Smoothness``, by ordinal."""
HOLD, LAST_TWO, PERIODIC, NO_EXTRAPOLATION = 1, 2, 3, 4
"""``Modelica.Blocks.Types.Extrapolation``, by ordinal."""
SPLINES = (AKIMA, FRITSCH_BUTLAND, STEFFEN, MODIFIED_AKIMA)


@dataclass(frozen=True)
class Piece:
    """``c[0] + c[1] d + c[2] d^2 + c[3] d^3`` with ``d = u - at``, valid from ``start``."""

    start: float
    at: float
    c: tuple[float, ...]


def pieces(xs: np.ndarray, ys: np.ndarray, smoothness: int, extrapolation: int
           ) -> list[Piece]:
    """The segments of the interpolant, left to right; the first holds for every u
    below the second's start, the last for every u from its start on."""
    if len(xs) == 1:
        return [Piece(-math.inf, 0.0, (float(ys[0]),))]
    inner: list[Piece] = []
    slopes = _slopes(xs, ys, smoothness) if smoothness in SPLINES else None
    for i in range(len(xs) - 1):
        h = float(xs[i + 1] - xs[i])
        if h == 0.0:
            continue  # a duplicated abscissa: a jump, the right value from there on
        y0, y1 = float(ys[i]), float(ys[i + 1])
        if smoothness == CONSTANT:
            c: tuple[float, ...] = (y0,)
        elif slopes is None:
            c = (y0, (y1 - y0) / h)
        else:
            m, t0, t1 = (y1 - y0) / h, float(slopes[i]), float(slopes[i + 1])
            c = (y0, t0, (3 * m - 2 * t0 - t1) / h, (t0 + t1 - 2 * m) / (h * h))
        inner.append(Piece(float(xs[i]), float(xs[i]), c))
    inner[0] = Piece(-math.inf, inner[0].at, inner[0].c)
    if extrapolation not in (HOLD, LAST_TWO):
        return inner  # u is inside the table (periodic), else it is an error
    first, last = float(xs[0]), float(xs[-1])
    left, right = _ends(xs, ys, extrapolation, slopes)
    return [Piece(-math.inf, first, left), replace(inner[0], start=first), *inner[1:],
            Piece(last, last, right)]


def _ends(xs: np.ndarray, ys: np.ndarray, extrapolation: int,
          slopes: np.ndarray | None) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The extrapolating segments below the first and from the last abscissa on."""
    y0, yn = float(ys[0]), float(ys[-1])
    if extrapolation != LAST_TWO:
        return (y0,), (yn,)
    if slopes is not None:
        return (y0, float(slopes[0])), (yn, float(slopes[-1]))
    # linear and constant segments: the line through the first (last) two points,
    # the two of a duplicated end abscissa being the last two distinct ones
    lo = next(i for i in range(1, len(xs)) if xs[i] != xs[0])
    hi = next(i for i in range(len(xs) - 2, -1, -1) if xs[i] != xs[-1])
    d0 = (float(ys[lo]) - float(ys[lo - 1])) / float(xs[lo] - xs[lo - 1])
    dn = (yn - float(ys[hi])) / float(xs[-1] - xs[hi])
    return (y0, d0), (yn, dn)


def _slopes(xs: np.ndarray, ys: np.ndarray, smoothness: int) -> np.ndarray:
    """The derivative of the cubic Hermite spline at every abscissa."""
    h = np.diff(xs).astype(float)
    m = np.diff(ys).astype(float) / h
    n = len(xs)
    if n == 2:
        return np.array([m[0], m[0]])
    if smoothness in (AKIMA, MODIFIED_AKIMA):
        return _akima(m, smoothness == MODIFIED_AKIMA)
    t = np.zeros(n)
    for i in range(1, n - 1):
        a, b = m[i - 1], m[i]
        if smoothness == FRITSCH_BUTLAND:
            if a * b > 0:
                w1, w2 = 2 * h[i] + h[i - 1], h[i] + 2 * h[i - 1]
                t[i] = (w1 + w2) / (w1 / a + w2 / b)
        else:  # Steffen
            p = (a * h[i] + b * h[i - 1]) / (h[i - 1] + h[i])
            t[i] = (np.sign(a) + np.sign(b)) * min(abs(a), abs(b), 0.5 * abs(p))
    t[0] = _end_slope(h[0], h[1], m[0], m[1], smoothness)
    t[-1] = _end_slope(h[-1], h[-2], m[-1], m[-2], smoothness)
    return t


def _end_slope(h0: float, h1: float, m0: float, m1: float, smoothness: int) -> float:
    """A monotone spline's slope at an end: the three-point estimate, limited so as
    not to reverse the end segment's direction (Steffen's also to twice its slope)."""
    p = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1) if smoothness == FRITSCH_BUTLAND \
        else m0 * (1 + h0 / (h0 + h1)) - m1 * h0 / (h0 + h1)
    if p * m0 <= 0:
        return 0.0
    if smoothness == FRITSCH_BUTLAND:
        return 3 * m0 if m0 * m1 <= 0 and abs(p) > 3 * abs(m0) else p
    return 2 * m0 if abs(p) > 2 * abs(m0) else p


def _akima(m: np.ndarray, modified: bool) -> np.ndarray:
    """Akima's slopes, the secants extended by two on each side (``2 m0 - m1``)."""
    ext = np.empty(len(m) + 4)
    ext[2:-2] = m
    ext[1] = 2 * ext[2] - ext[3]
    ext[0] = 2 * ext[1] - ext[2]
    ext[-2] = 2 * ext[-3] - ext[-4]
    ext[-1] = 2 * ext[-2] - ext[-3]
    t = np.empty(len(m) + 1)
    for i in range(len(t)):
        m2, m1, m0, mp = ext[i], ext[i + 1], ext[i + 2], ext[i + 3]
        w1, w2 = abs(mp - m0), abs(m1 - m2)
        if modified:
            w1, w2 = w1 + abs(mp + m0) / 2, w2 + abs(m1 + m2) / 2
        t[i] = (m1 + m0) / 2 if w1 + w2 == 0 else (w1 * m1 + w2 * m0) / (w1 + w2)
    return t


def piecewise(u: x.Expr, segments: Sequence[Piece]) -> x.Expr:
    """The expression of ``segments`` at ``u``: a balanced search over their starts."""
    if len(segments) == 1:
        return _poly(u, segments[0])
    mid = len(segments) // 2
    cond = x.Call("noEvent", (x.BinOp("<", u, x.Const(segments[mid].start)),))
    return x.If(cond, piecewise(u, segments[:mid]), piecewise(u, segments[mid:]))


def _poly(u: x.Expr, piece: Piece) -> x.Expr:
    coefficients = list(piece.c)
    while len(coefficients) > 1 and coefficients[-1] == 0.0:
        coefficients.pop()
    if len(coefficients) == 1:
        return x.Const(coefficients[0])
    d = x.sub(u, x.Const(piece.at)) if piece.at != 0.0 else u
    result: x.Expr = x.Const(coefficients[-1])
    for c in reversed(coefficients[:-1]):
        result = x.add(x.Const(c), x.mul(d, result)) if c != 0.0 else x.mul(d, result)
    return result


def periodic(u: x.Expr, first: float, last: float) -> x.Expr:
    """``u`` moved into ``[first, last)`` by whole periods."""
    period = last - first
    shifted = x.sub(u, x.Const(first)) if first != 0.0 else u
    wraps = x.Call("floor", (x.div(shifted, x.Const(period)),))
    return x.sub(u, x.mul(x.Const(period), wraps))
