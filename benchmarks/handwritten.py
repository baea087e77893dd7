"""Hand-written numba right-hand sides of the benchmark scenes (the baselines).

States are laid out as springc lays them out (``m[i].s, m[i].v`` for the chain;
``p[i,j].pos[1..2], p[i,j].v[1..2]`` row by row for the cloth), so results compare
element by element.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def chain_rhs(t: float, x: np.ndarray, k: float, rest: float, mass: float) -> np.ndarray:
    """Scenes.Chain: fixed -- s[1] -- m[1] -- s[2] -- ... -- m[N] (right end free)."""
    n = x.shape[0] // 2
    dx = np.empty(2 * n)
    previous = 0.0
    pull = k * (x[0] - rest)  # tension of spring 1
    for i in range(n):
        s = x[2 * i]
        nxt = k * (x[2 * i + 2] - s - rest) if i + 1 < n else 0.0
        dx[2 * i] = x[2 * i + 1]
        dx[2 * i + 1] = (nxt - pull) / mass
        pull = nxt
        previous = s
    return dx + 0.0 * previous


@njit(cache=True, inline="always")
def _spring(F: np.ndarray, ax: float, ay: float, bx: float, by: float, k: float,
            rest: float, ia: int, ib: int) -> None:
    """Add the forces of a spring from a to b (a < 0: an anchor) to F."""
    dxv, dyv = bx - ax, by - ay
    length = math.sqrt(dxv * dxv + dyv * dyv)
    f = k * (length - rest) / length
    if ib >= 0:
        F[ib, 0] -= f * dxv
        F[ib, 1] -= f * dyv
    if ia >= 0:
        F[ia, 0] += f * dxv
        F[ia, 1] += f * dyv


@njit(cache=True)
def cloth_rhs(t: float, x: np.ndarray, n: int, m: int, h: float, mass: float,
              k_struct: float, k_shear: float) -> np.ndarray:
    """Scenes.Cloth: n x m masses below m anchors, structural and shear springs."""
    F = np.zeros((n * m, 2))
    diag = math.sqrt(2.0) * h
    for i in range(n):
        for j in range(m):
            b = i * m + j
            F[b, 1] -= mass * 9.81
            # vertical spring from the node above (or the anchor)
            if i == 0:
                _spring(F, h * j, 0.0, x[4 * b], x[4 * b + 1], k_struct, h, -1, b)
            else:
                a = b - m
                _spring(F, x[4 * a], x[4 * a + 1], x[4 * b], x[4 * b + 1], k_struct, h, a, b)
            if j + 1 < m:
                c = b + 1
                _spring(F, x[4 * b], x[4 * b + 1], x[4 * c], x[4 * c + 1], k_struct, h, b, c)
                # shear springs from the row above: (i-1, j) -- (i, j+1), (i-1, j+1) -- (i, j)
                if i == 0:
                    _spring(F, h * j, 0.0, x[4 * c], x[4 * c + 1], k_shear, diag, -1, c)
                    _spring(F, h * (j + 1), 0.0, x[4 * b], x[4 * b + 1], k_shear, diag, -1, b)
                else:
                    a, d = b - m, b - m + 1
                    _spring(F, x[4 * a], x[4 * a + 1], x[4 * c], x[4 * c + 1], k_shear, diag,
                            a, c)
                    _spring(F, x[4 * d], x[4 * d + 1], x[4 * b], x[4 * b + 1], k_shear, diag,
                            d, b)
    dx = np.empty_like(x)
    for b in range(n * m):
        dx[4 * b] = x[4 * b + 2]
        dx[4 * b + 1] = x[4 * b + 3]
        dx[4 * b + 2] = F[b, 0] / mass
        dx[4 * b + 3] = F[b, 1] / mass
    return dx
