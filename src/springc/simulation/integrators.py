"""Fixed-step integrators for mechanical scenes: rhs + start -> trajectory on a grid.

``symplectic_euler`` (semi-implicit Euler) and ``verlet`` (velocity Verlet) treat the
states as position/velocity pairs (``der(q) = v``) and keep the energy of conservative
systems bounded over long runs, where adaptive explicit methods drift; states outside
the pairs (e.g. a damper's internal state) are advanced with explicit Euler in the
same step. ``rk4`` is the classical fourth-order method for any ODE.

All three take a step ``h`` that divides the output interval into whole steps (it is
shortened slightly if needed) and return the states exactly at the output times.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .solver_names import FIXED_STEP, REGISTRY, registered

Rhs = Callable[[float, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class FixedStepResult:
    t: np.ndarray
    x: np.ndarray  # shape (len(t), n_states)
    steps: int
    rhs_evaluations: int
    step: float


@dataclass(frozen=True)
class Pairs:
    """Indices of position states and of their velocities (``der(q[i]) = v[i]``)."""

    positions: np.ndarray
    velocities: np.ndarray

    @staticmethod
    def of(pairs: Sequence[tuple[int, int]]) -> Pairs:
        q = np.array([p for p, _ in pairs], dtype=int)
        v = np.array([v for _, v in pairs], dtype=int)
        return Pairs(q, v)


class NonFiniteState(ArithmeticError):
    """A state became NaN or infinite; carries the time and the state indices."""

    def __init__(self, time: float, indices: np.ndarray) -> None:
        self.time = time
        self.indices = indices
        super().__init__(f"non-finite state at t = {time:g}")


def _counted(rhs: Rhs) -> tuple[Rhs, list[int]]:
    count = [0]

    def wrapped(t: float, x: np.ndarray) -> np.ndarray:
        count[0] += 1
        return rhs(t, x)

    return wrapped, count


def integrate(method: str, rhs: Rhs, times: np.ndarray, x0: np.ndarray, step: float,
              pairs: Pairs | None = None,
              after_step: Callable[[float, np.ndarray], None] | None = None
              ) -> FixedStepResult:
    """Integrate from ``times[0]`` and record the state at every output time;
    ``after_step(t, x)`` is called after every step (the model's assertions)."""
    if method not in STEPPERS:
        raise ValueError(f"unknown fixed-step method {method!r}; use one of "
                         f"{tuple(STEPPERS)}")
    if step <= 0 or not np.isfinite(step):
        raise ValueError(f"the step must be positive, got {step!r}")
    advance = STEPPERS[method]
    if method in REGISTRY and registered(method).pairs and pairs is None:
        pairs = Pairs(np.array([], dtype=int), np.array([], dtype=int))
    f, count = _counted(rhs)
    out = np.empty((len(times), len(x0)))
    x = np.array(x0, dtype=float)
    out[0] = x
    total_steps = 0
    cache: dict[str, np.ndarray] = {}
    for k in range(1, len(times)):
        span = times[k] - times[k - 1]
        n = max(1, int(np.ceil(span / step - 1e-9)))
        h = span / n
        t = times[k - 1]
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            for _ in range(n):
                x = advance(f, t, x, h, pairs, cache)
                t += h
                if after_step is not None:
                    after_step(t, x)
        total_steps += n
        bad = ~np.isfinite(x)
        if bad.any():
            raise NonFiniteState(times[k], np.flatnonzero(bad))
        out[k] = x
    return FixedStepResult(np.asarray(times), out, total_steps, count[0], step)


def _euler(f: Rhs, t: float, x: np.ndarray, h: float, pairs: Pairs | None,
           cache: dict[str, np.ndarray]) -> np.ndarray:
    """Explicit Euler: a method of this module, not a solver of the registry."""
    return x + h * f(t, x)


def _symplectic_euler(f: Rhs, t: float, x: np.ndarray, h: float, pairs: Pairs | None,
                      cache: dict[str, np.ndarray]) -> np.ndarray:
    """Kick then drift: ``v += h*a(q, v)``, ``q += h*v_new``; others explicit Euler."""
    assert pairs is not None
    d = f(t, x)
    new = x + h * d
    new[pairs.velocities] = x[pairs.velocities] + h * d[pairs.velocities]
    new[pairs.positions] = x[pairs.positions] + h * new[pairs.velocities]
    return new


def _verlet(f: Rhs, t: float, x: np.ndarray, h: float, pairs: Pairs | None,
            cache: dict[str, np.ndarray]) -> np.ndarray:
    """Velocity Verlet; the acceleration at the end of the step reuses the next start.

    Velocity-dependent forces use the half-step velocity in the second evaluation.
    """
    assert pairs is not None
    q, v = pairs.positions, pairs.velocities
    d = cache.get("d")
    if d is None or not np.array_equal(cache["x"], x):
        d = f(t, x)
    new = x + h * d  # non-mechanical states: explicit Euler
    half = x[v] + 0.5 * h * d[v]
    new[q] = x[q] + h * half
    new[v] = half
    d_new = f(t + h, new)
    new[v] = half + 0.5 * h * d_new[v]
    cache["x"], cache["d"] = new.copy(), d_new
    return new


def _rk4_step(f: Rhs, t: float, x: np.ndarray, h: float, pairs: Pairs | None,
         cache: dict[str, np.ndarray]) -> np.ndarray:
    k1 = f(t, x)
    k2 = f(t + h / 2, x + h / 2 * k1)
    k3 = f(t + h / 2, x + h / 2 * k2)
    k4 = f(t + h, x + h * k3)
    new: np.ndarray = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return new


STEPPERS = {"euler": _euler, "symplectic-euler": _symplectic_euler, "verlet": _verlet,
            "rk4": _rk4_step}
"""One step of each fixed-step solver of the registry (its facts: order, pairs, in
:mod:`.solver_names`), and of explicit Euler: ``(rhs, t, x, h, pairs, cache) ->
x(t + h)`` (``cache`` carries verlet's last derivative; clear it when the states jump)."""
if set(FIXED_STEP) - set(STEPPERS):  # a registered fixed-step solver without arithmetic
    raise ImportError(f"fixed-step solvers without a step here: "
                      f"{sorted(set(FIXED_STEP) - set(STEPPERS))}")
