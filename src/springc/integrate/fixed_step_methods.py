"""One step of each fixed-step scene integrator, compiled (the kernel's arithmetic).

The same formulas, in the same order, as ``springc.simulation.integrators``:
``symplectic-euler`` (kick then drift) and ``verlet`` (velocity Verlet) treat the
(position, velocity) index pairs, other states advance with explicit Euler; ``rk4`` is
the classical fourth-order method. A step of any length ``h`` can be taken from the same
start, which is how the kernel locates a crossing inside a step (bisection on split
steps).

numba keys its disk cache on this file's modification time only: touch it after
editing ``status``.
"""

import math

import numpy as np
from numba import njit

from .signatures import ModelFunction
from .status import Status

SUCCESS = int(Status.SUCCESS)
NON_FINITE_DERIVATIVE = int(Status.NON_FINITE_DERIVATIVE)
MODEL_FAILED = int(Status.MODEL_FAILED)

#: method codes of :func:`advance`
EULER, SYMPLECTIC_EULER, VERLET, RK4 = 0, 1, 2, 3
METHOD_CODES = {"euler": EULER, "symplectic-euler": SYMPLECTIC_EULER, "verlet": VERLET,
                "rk4": RK4}


@njit(cache=True, error_model="numpy", nogil=True)
def verdict(d: np.ndarray, z: np.ndarray) -> int:
    """SUCCESS, or why the evaluation that returned ``d`` (and set ``z``) is unusable."""
    if z.size > 0 and z[z.size - 1] != 0.0:
        return MODEL_FAILED
    for value in d:
        if not math.isfinite(value):
            return NON_FINITE_DERIVATIVE
    return SUCCESS


@njit(cache=True, error_model="numpy", nogil=True)
def advance(method: int, rhs: ModelFunction, t: float, x: np.ndarray, d: np.ndarray,
            h: float, p: np.ndarray, z: np.ndarray, positions: np.ndarray,
            velocities: np.ndarray, out: np.ndarray) -> tuple[int, int, np.ndarray, float]:
    """One step of ``method`` from ``(t, x)`` with ``d = rhs(t, x)``: the new state in
    ``out``. Returns the status, the evaluations made, the derivative at the new state
    (verlet; ``d`` for the others) and the time of a failed evaluation (its state is in
    ``out``)."""
    n = x.size
    if method == EULER:
        for i in range(n):
            out[i] = x[i] + h * d[i]
        return SUCCESS, 0, d, t
    if method == SYMPLECTIC_EULER:
        moved = np.empty(positions.size)
        for i in range(n):
            out[i] = x[i] + h * d[i]
        for i in range(positions.size):
            moved[i] = x[positions[i]] + h * out[velocities[i]]
        for i in range(positions.size):
            out[positions[i]] = moved[i]
        return SUCCESS, 0, d, t
    if method == VERLET:
        half = np.empty(velocities.size)
        for i in range(n):
            out[i] = x[i] + h * d[i]
        for i in range(velocities.size):
            half[i] = x[velocities[i]] + 0.5 * h * d[velocities[i]]
        for i in range(positions.size):
            out[positions[i]] = x[positions[i]] + h * half[i]
        for i in range(velocities.size):
            out[velocities[i]] = half[i]
        d_end = rhs(t + h, out, p, z)
        status = verdict(d_end, z)
        if status != SUCCESS:
            return status, 1, d_end, t + h
        for i in range(velocities.size):
            out[velocities[i]] = half[i] + 0.5 * h * d_end[velocities[i]]
        return SUCCESS, 1, d_end, t
    k1 = d
    for i in range(n):
        out[i] = x[i] + h / 2 * k1[i]
    k2 = rhs(t + h / 2, out, p, z)
    status = verdict(k2, z)
    if status != SUCCESS:
        return status, 1, k2, t + h / 2
    for i in range(n):
        out[i] = x[i] + h / 2 * k2[i]
    k3 = rhs(t + h / 2, out, p, z)
    status = verdict(k3, z)
    if status != SUCCESS:
        return status, 2, k3, t + h / 2
    for i in range(n):
        out[i] = x[i] + h * k3[i]
    k4 = rhs(t + h, out, p, z)
    status = verdict(k4, z)
    if status != SUCCESS:
        return status, 3, k4, t + h
    for i in range(n):
        out[i] = x[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
    return SUCCESS, 3, d, t
