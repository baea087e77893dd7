"""Hand-written test ODEs in the model-function form ``f(t, x, p, z) -> dx``, jitted once.

numba compiles them with ``cache=True`` (and the engine's kernels are cached), so only
the first test session on a machine pays the compilation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest
from numba import njit

JIT = {"cache": True, "error_model": "numpy"}


@njit(**JIT)
def oscillator(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """q' = v, v' = -w^2 q (p = [w])."""
    d = np.empty(2)
    d[0] = x[1]
    d[1] = -p[0] * p[0] * x[0]
    return d


@njit(**JIT)
def oscillator_energy(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Observed: the energy and the time (p = [w])."""
    out = np.empty(2)
    out[0] = 0.5 * x[1] * x[1] + 0.5 * p[0] * p[0] * x[0] * x[0]
    out[1] = t
    return out


@njit(**JIT)
def spring_pendulum(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The seed: a mass on a 2-D spring under gravity (p = [k, rest length, mass, g])."""
    r = math.sqrt(x[0] * x[0] + x[1] * x[1])
    pull = -p[0] * (r - p[1]) / r / p[2]
    d = np.empty(4)
    d[0] = x[2]
    d[1] = x[3]
    d[2] = pull * x[0]
    d[3] = pull * x[1] - p[3]
    return d


@njit(**JIT)
def damped_pendulum(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The spring pendulum plus a first-order state x[4]' = x[0] - x[4] (not a pair)."""
    d4 = spring_pendulum(t, x, p, z)
    d = np.empty(5)
    d[:4] = d4
    d[4] = x[0] - x[4]
    return d


@njit(**JIT)
def van_der_pol(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x'' = mu (1 - x^2) x' - x (p = [mu])."""
    d = np.empty(2)
    d[0] = x[1]
    d[1] = p[0] * (1 - x[0] * x[0]) * x[1] - x[0]
    return d


@dataclass(frozen=True)
class Problem:
    """An ODE with its parameters, start and interval."""

    name: str
    rhs: Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    p: np.ndarray
    x0: np.ndarray
    stop: float

    def scipy_rhs(self) -> Callable[[float, np.ndarray], np.ndarray]:
        """The right-hand side as scipy calls it."""
        z = np.zeros(0)
        return lambda t, x: self.rhs(t, x, self.p, z)


PROBLEMS = {
    "oscillator": Problem("oscillator", oscillator, np.array([2.0]), np.array([1.0, 0.0]),
                          5.0),
    "spring pendulum": Problem("spring pendulum", spring_pendulum,
                               np.array([100.0, 1.0, 1.0, 9.81]),
                               np.array([1.0, -1.0, 0.0, 0.0]), 3.0),
    "van der pol": Problem("van der pol", van_der_pol, np.array([1.0]),
                           np.array([2.0, 0.0]), 10.0),
}


@pytest.fixture(params=sorted(PROBLEMS))
def problem(request: pytest.FixtureRequest) -> Problem:
    """Each test ODE in turn."""
    return PROBLEMS[request.param]


@pytest.fixture(scope="session")
def odes() -> SimpleNamespace:
    """The jitted model functions above, by name."""
    return SimpleNamespace(oscillator=oscillator, oscillator_energy=oscillator_energy,
                           spring_pendulum=spring_pendulum, damped_pendulum=damped_pendulum,
                           van_der_pol=van_der_pol)


@njit(**JIT)
def sqrt_of_falling(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x0' = -1 (x0 = 1 - t), x1' = sqrt(x0): NaN once x0 < 0, i.e. past t = 1."""
    d = np.empty(2)
    d[0] = -1.0
    d[1] = math.sqrt(x[0])
    return d


@njit(**JIT)
def blow_up(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x' = x^2 from x(0) = 1: x = 1 / (1 - t), infinite at t = 1."""
    d = np.empty(1)
    d[0] = x[0] * x[0]
    return d


@njit(**JIT)
def flags_after_half(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """x' = 1, but the model reports failure (z[-1] = 7) when evaluated past t = 0.5."""
    if t > 0.5:
        z[z.size - 1] = 7.0
    d = np.empty(1)
    d[0] = 1.0
    return d


@njit(**JIT)
def wrong_length(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Three derivatives, whatever the number of states."""
    return np.zeros(3)


@pytest.fixture(scope="session")
def failing() -> SimpleNamespace:
    """The model functions above that make a run fail, by name."""
    return SimpleNamespace(sqrt_of_falling=sqrt_of_falling, blow_up=blow_up,
                           flags_after_half=flags_after_half, wrong_length=wrong_length)


# ------------------------------------------------------------------ stiff problems

@njit(**JIT)
def van_der_pol(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    d = np.empty(2)
    d[0] = x[1]
    d[1] = p[0] * (1 - x[0] * x[0]) * x[1] - x[0]
    return d


@njit(**JIT)
def van_der_pol_jacobian(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray
                         ) -> np.ndarray:
    """Non-zeros in CSC order: column 0 (row 1), column 1 (rows 0, 1)."""
    v = np.empty(3)
    v[0] = -2 * p[0] * x[0] * x[1] - 1
    v[1] = 1.0
    v[2] = p[0] * (1 - x[0] * x[0])
    return v


VDP_INDPTR, VDP_INDICES = np.array([0, 1, 3]), np.array([1, 0, 1])


@njit(**JIT)
def chain(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """N masses (x = s1, v1, s2, v2, ...), springs k between neighbours and to a wall at
    the left, dampers c: p = [k, c, m]."""
    n = x.size // 2
    d = np.empty(x.size)
    for i in range(n):
        s, v = x[2 * i], x[2 * i + 1]
        left = x[2 * i - 2] if i > 0 else 0.0
        force = -p[0] * (s - left) - p[1] * v
        if i + 1 < n:
            force += p[0] * (x[2 * i + 2] - s)
        d[2 * i] = v
        d[2 * i + 1] = force / p[2]
    return d


@njit(**JIT)
def chain_jacobian(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Non-zeros in the CSC order of :func:`chain_pattern`."""
    n = x.size // 2
    out = np.empty(5 * n - 2)
    k = 0
    for i in range(n):  # column s_i: rows v_{i-1}, v_i, v_{i+1}
        if i > 0:
            out[k] = p[0] / p[2]
            k += 1
        out[k] = -(2.0 if i + 1 < n else 1.0) * p[0] / p[2]
        k += 1
        if i + 1 < n:
            out[k] = p[0] / p[2]
            k += 1
        out[k] = 1.0  # column v_i: rows s_i, v_i
        out[k + 1] = -p[1] / p[2]
        k += 2
    return out


def chain_pattern(n: int) -> tuple[np.ndarray, np.ndarray]:
    indices: list[int] = []
    indptr = [0]
    for i in range(n):
        indices += ([2 * i - 1] if i > 0 else []) + [2 * i + 1] + \
            ([2 * i + 3] if i + 1 < n else [])
        indptr.append(len(indices))
        indices += [2 * i, 2 * i + 1]
        indptr.append(len(indices))
    return np.array(indptr), np.array(indices)


@njit(**JIT)
def falling(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    d = np.empty(2)
    d[0] = x[1]
    d[1] = -p[0]
    return d


@njit(**JIT)
def falling_jacobian(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """CSC: column 0 empty, column 1 row 0 (dh'/dv = 1)."""
    return np.ones(1)


@njit(**JIT)
def height(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The zero crossing h = 0 (x[0])."""
    return x[:1].copy()


@pytest.fixture(scope="session")
def stiff() -> SimpleNamespace:
    """Stiff test problems with their Jacobians' non-zeros in CSC order (test_radau/bdf)."""
    return SimpleNamespace(van_der_pol=van_der_pol, van_der_pol_jacobian=van_der_pol_jacobian,
                           VDP_INDPTR=VDP_INDPTR, VDP_INDICES=VDP_INDICES, chain=chain,
                           chain_jacobian=chain_jacobian, chain_pattern=chain_pattern,
                           falling=falling, falling_jacobian=falling_jacobian, height=height)
