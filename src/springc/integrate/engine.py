"""The Python side of the compiled loops: checked arguments in, a :class:`Run` out.

numba is an optional dependency of springc, so the kernels (which compile, or load from
numba's on-disk cache, when their module is imported) are imported on first use only.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .kernels import FIXED_STEP_METHODS, kernel
from .status import Status

ModelFunction = Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Run:
    """The outcome of a compiled run on an output grid.

    ``states[k]`` (and ``observed[k]``) hold the solution at ``t[k]`` for ``k < filled``;
    later rows are NaN. Unless ``status`` is SUCCESS, ``failure_time`` and
    ``failure_state`` say where the run stopped (see :class:`Status`): for STATE_EVENT
    and TIME_EVENT (also named ``event_time`` and ``event_state``) the event time and
    the left-limit state there, with the grid filled up to (not including) that time.
    ``fired[i]`` is +1 (rising), -1 (falling) or 0 for each zero-crossing indicator;
    ``next_step`` is the step size the method would take next.
    """

    status: Status
    t: np.ndarray
    states: np.ndarray  # (len(t), n_states)
    observed: np.ndarray  # (len(t), n_observed)
    filled: int
    accepted_steps: int
    rejected_steps: int
    rhs_evaluations: int
    failure_time: float
    failure_state: np.ndarray
    fired: np.ndarray
    next_step: float
    jacobian_evaluations: int = 0

    @property
    def ok(self) -> bool:
        """Whether the run reached the end of the grid."""
        return self.status == Status.SUCCESS

    @property
    def event(self) -> bool:
        """Whether the run stopped at a state or time event (not at a failure)."""
        return self.status in (Status.STATE_EVENT, Status.TIME_EVENT)

    @property
    def event_time(self) -> float:
        return self.failure_time

    @property
    def event_state(self) -> np.ndarray:
        return self.failure_state


@dataclass(frozen=True)
class Crossings:
    """A model's zero crossings for a run: ``g(t, x, p, z) -> float64[::1]`` (a numba
    function, one indicator per relation), the held sign of each indicator (+1/-1: the
    side the model assumes now) and optional direction filters (+1 rising only, -1
    falling only, 0 both; default both). See :mod:`springc.integrate.crossings`."""

    function: ModelFunction
    signs: Sequence[float] | np.ndarray
    directions: Sequence[float] | np.ndarray | None = None


def dop853(rhs: ModelFunction, grid: Any, x0: Any, p: Any, z: Any, *, rtol: float,
           atol: float | Sequence[float] | np.ndarray, observed: ModelFunction | None = None,
           max_step: float = np.inf, first_step: float | None = None,
           max_steps: int = 0, scipy_arithmetic: bool = True,
           crossings: Crossings | None = None, t_stop: float = np.inf) -> Run:
    """Integrate ``x' = rhs(t, x, p, z)`` with compiled DOP853 on the output ``grid``.

    ``rhs`` and ``observed`` are numba-jitted functions ``f(t, x, p, z) -> array`` (the
    generated module's ``rhs`` and ``observed``); ``z`` is the model's work array and is
    updated in place. ``first_step`` None selects the initial step as scipy does;
    ``max_steps`` (accepted and rejected steps) 0 is no limit.

    With ``scipy_arithmetic`` the weighted sums go through the BLAS calls numpy makes, so
    the run equals ``solve_ivp(method="DOP853")`` on the same tolerances bit for bit
    (same steps, same states; the error estimate of tiny steps is rounding noise, so any
    other summation order picks other early steps); without it, plain loops, about 1.5x
    faster on small systems, the same method within rounding.

    ``crossings`` stops the run at the earliest zero crossing (status STATE_EVENT, located
    on the dense output); a ``t_stop`` inside the grid stops it exactly there (TIME_EVENT).
    """
    return _explicit("dop853", rhs, grid, x0, p, z, rtol, atol, observed, max_step,
                     first_step, max_steps, scipy_arithmetic, crossings, t_stop)


def rk45(rhs: ModelFunction, grid: Any, x0: Any, p: Any, z: Any, *, rtol: float,
         atol: float | Sequence[float] | np.ndarray, observed: ModelFunction | None = None,
         max_step: float = np.inf, first_step: float | None = None, max_steps: int = 0,
         scipy_arithmetic: bool = True, crossings: Crossings | None = None,
         t_stop: float = np.inf) -> Run:
    """Integrate with compiled RK45 (Dormand-Prince 5(4)), scipy's ``RK45`` method;
    arguments as :func:`dop853`."""
    return _explicit("rk45", rhs, grid, x0, p, z, rtol, atol, observed, max_step,
                     first_step, max_steps, scipy_arithmetic, crossings, t_stop)


def _explicit(method: str, rhs: ModelFunction, grid: Any, x0: Any, p: Any, z: Any,
              rtol: float, atol: Any, observed: ModelFunction | None, max_step: float,
              first_step: float | None, max_steps: int, scipy_arithmetic: bool,
              crossings: Crossings | None, t_stop: float) -> Run:
    from .models import no_observed

    grid_, x0_, p_, z_ = _vectors(grid, x0, p, z)
    atol_ = _tolerances(rtol, atol, x0_, grid_, first_step, max_step)
    rhs_, observed_, n_observed = _functions(rhs, observed, grid_, x0_, p_, z_)
    g, signs, directions = _crossings(crossings, grid_, x0_, p_, z_)
    none = np.empty(0, dtype=np.int64)
    loop = kernel(method, bool(scipy_arithmetic))
    result = loop(rhs_, no_observed, observed_, n_observed, g, signs, directions, grid_, x0_,
                  p_, z_, float(rtol), atol_, float(max_step), float(first_step or 0.0),
                  int(max_steps), _stop(t_stop, grid_), (none, 0, 0, none, none))
    return _run(grid_, result)


def radau(rhs: ModelFunction, jacobian: ModelFunction, indptr: Any, indices: Any, grid: Any,
          x0: Any, p: Any, z: Any, *, rtol: float, atol: float | Sequence[float] | np.ndarray,
          **options: Any) -> Run:
    """Integrate with compiled Radau IIA (order 5), scipy's ``Radau`` method.

    ``jacobian(t, x, p, z)`` returns the non-zeros of the Jacobian in the CSC order of
    ``(indptr, indices)`` (a generated module's ``jacobian_values``, ``JAC_INDPTR``,
    ``JAC_INDICES``). The Newton matrices are factorised dense up to ``dense_limit``
    (default 64) states, banded after a reverse Cuthill-McKee ordering above. Other
    options (``observed``, ``max_step``, ``first_step``, ``max_steps``, ``crossings``,
    ``t_stop``) as for :func:`dop853`.
    """
    return _implicit("radau", rhs, jacobian, indptr, indices, grid, x0, p, z, rtol, atol,
                     **options)


def bdf(rhs: ModelFunction, jacobian: ModelFunction, indptr: Any, indices: Any, grid: Any,
        x0: Any, p: Any, z: Any, *, rtol: float, atol: float | Sequence[float] | np.ndarray,
        **options: Any) -> Run:
    """Integrate with compiled BDF (orders 1-5), scipy's ``BDF`` method; arguments as
    :func:`radau`."""
    return _implicit("bdf", rhs, jacobian, indptr, indices, grid, x0, p, z, rtol, atol,
                     **options)


def _implicit(method: str, rhs: ModelFunction, jacobian: ModelFunction, indptr: Any,
              indices: Any, grid: Any, x0: Any, p: Any, z: Any, rtol: float, atol: Any, *,
              observed: ModelFunction | None = None, max_step: float = np.inf,
              first_step: float | None = None, max_steps: int = 0,
              crossings: Crossings | None = None, t_stop: float = np.inf,
              dense_limit: int = 64) -> Run:
    grid_, x0_, p_, z_ = _vectors(grid, x0, p, z)
    atol_ = _tolerances(rtol, atol, x0_, grid_, first_step, max_step)
    rhs_, observed_, n_observed = _functions(rhs, observed, grid_, x0_, p_, z_)
    indptr_ = np.asarray(indptr, dtype=np.int64)
    indices_ = np.asarray(indices, dtype=np.int64)
    if indptr_.shape != (x0_.size + 1,) or indptr_[-1] != indices_.size \
            or (indices_.size and not 0 <= indices_.min() <= indices_.max() < x0_.size):
        raise ValueError("indptr/indices are not a CSC sparsity of the state vector")
    values = np.asarray(jacobian(grid_[0], x0_, p_, z_.copy()))
    if values.shape != indices_.shape:
        raise ValueError(f"the Jacobian returns shape {values.shape} for {indices_.size} "
                         "non-zeros")
    order, kl, ku, positions, diagonal = _band_layout(x0_.size, indptr_.tobytes(),
                                                      indices_.tobytes(), dense_limit)
    g, signs, directions = _crossings(crossings, grid_, x0_, p_, z_)
    loop = kernel(method)
    result = loop(rhs_, jacobian, observed_, n_observed, g, signs, directions, grid_, x0_,
                  p_, z_, float(rtol), atol_, float(max_step), float(first_step or 0.0),
                  int(max_steps), _stop(t_stop, grid_), (order, kl, ku, positions, diagonal))
    return _run(grid_, result)


def newton_flops(indptr: Any, indices: Any, dense_limit: int = 64) -> float:
    """Floating-point operations of one factorization of :func:`radau`'s two Newton
    matrices (the real one and the complex one, 4 real operations per complex one) for
    a Jacobian of CSC sparsity ``(indptr, indices)``: about ``10 n kl (kl + ku)`` in the
    band the kernel uses."""
    indptr_ = np.ascontiguousarray(indptr, dtype=np.int64)
    indices_ = np.ascontiguousarray(indices, dtype=np.int64)
    n = indptr_.size - 1
    _, kl, ku, _, _ = _band_layout(n, indptr_.tobytes(), indices_.tobytes(), dense_limit)
    return 10.0 * n * max(kl, 1) * (kl + ku + 1)


def newton_solve_flops(indptr: Any, indices: Any, dense_limit: int = 64) -> float:
    """Floating-point operations of the solves of one Newton iteration of :func:`radau`
    (a real and a complex solve with the factors of :func:`newton_flops`, forward and
    back through the band: about ``2 n (2 kl + ku + 1)`` real operations, four times
    that for the complex one)."""
    indptr_ = np.ascontiguousarray(indptr, dtype=np.int64)
    indices_ = np.ascontiguousarray(indices, dtype=np.int64)
    n = indptr_.size - 1
    _, kl, ku, _, _ = _band_layout(n, indptr_.tobytes(), indices_.tobytes(), dense_limit)
    return 10.0 * n * (2 * kl + ku + 1)


def band_order(indptr: Any, indices: Any, dense_limit: int = 64) -> list[int] | None:
    """The ordering of the states (position -> state) in :func:`radau`'s and
    :func:`bdf`'s banded LU for a Jacobian of CSC sparsity ``(indptr, indices)``: None
    up to ``dense_limit`` states (a dense LU in state order), else the reverse
    Cuthill-McKee order of :func:`.ordering.band_layout`. The C loop takes it
    (``springc.native.LoopLibrary.run``'s ``order``) to factorise as these loops do."""
    indptr_ = np.ascontiguousarray(indptr, dtype=np.int64)
    indices_ = np.ascontiguousarray(indices, dtype=np.int64)
    n = indptr_.size - 1
    if n <= dense_limit:
        return None
    order = _band_layout(n, indptr_.tobytes(), indices_.tobytes(), dense_limit)[0]
    return [int(i) for i in order]


@functools.lru_cache(maxsize=16)
def _band_layout(n: int, indptr: bytes, indices: bytes, dense_limit: int
                 ) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray]:
    """:func:`.ordering.band_layout` of a sparsity, once per process (a model's runs,
    and ``auto``'s race, call the implicit kernels again and again on one sparsity;
    the reordering of a large scene takes milliseconds). The kernels only read it."""
    from .ordering import band_layout

    return band_layout(n, np.frombuffer(indptr, dtype=np.int64),
                       np.frombuffer(indices, dtype=np.int64), dense_limit)


def fixed_step(method: str, rhs: ModelFunction, grid: Any, x0: Any, p: Any, z: Any, *,
               step: float, pairs: Sequence[tuple[int, int]] = (),
               observed: ModelFunction | None = None, crossings: Crossings | None = None,
               t_stop: float = np.inf) -> Run:
    """Integrate with a fixed-step method of :data:`FIXED_STEP_METHODS`, compiled.

    Same methods and results as ``springc.simulation``'s fixed-step integrators:
    ``pairs`` lists (position index, velocity index) with ``der(x[q]) = x[v]``.
    ``crossings`` and ``t_stop`` as for :func:`dop853` (a crossing is located on split
    steps of the method; the steps after an event restart on the output interval).
    """
    from .fixed_step_methods import METHOD_CODES

    if method not in METHOD_CODES:
        raise ValueError(f"unknown fixed-step method {method!r}; use one of "
                         f"{FIXED_STEP_METHODS}")
    if not (step > 0 and np.isfinite(step)):
        raise ValueError(f"the step must be positive, got {step!r}")
    grid_, x0_, p_, z_ = _vectors(grid, x0, p, z)
    positions = np.array([q for q, _ in pairs], dtype=np.int64)
    velocities = np.array([v for _, v in pairs], dtype=np.int64)
    if pairs and not (min(positions.min(), velocities.min()) >= 0
                      and max(positions.max(), velocities.max()) < x0_.size):
        raise ValueError("a pair index is outside the state vector")
    rhs_, observed_, n_observed = _functions(rhs, observed, grid_, x0_, p_, z_)
    g, signs, directions = _crossings(crossings, grid_, x0_, p_, z_)
    result = kernel(method)(METHOD_CODES[method], rhs_, observed_, n_observed, g, signs,
                            directions, grid_, x0_, p_, z_, float(step), positions,
                            velocities, _stop(t_stop, grid_))
    return _run(grid_, result)


def observed_grid(observed: ModelFunction, ts: Any, states: Any, p: Any, z: Any
                  ) -> np.ndarray:
    """``observed(ts[i], states[i], p, z)`` as row ``i`` of a (len(ts), n_observed)
    array, compiled: a generated numba module's ``observed_grid`` without its Python
    loop. ``z`` is updated in place; from the first row whose call sets the failure flag
    ``z[-1]`` on, the rows are NaN (as the module's own ``observed_grid`` does)."""
    from numba.core.dispatcher import Dispatcher

    from .addresses import install
    from .grid_kernel import observed_grid_run

    install()
    if not isinstance(observed, Dispatcher):
        raise TypeError(f"observed must be a numba-jitted function, got "
                        f"{type(observed).__name__}")
    ts_ = np.ascontiguousarray(ts, dtype=float)
    states_ = np.ascontiguousarray(states, dtype=float)
    if ts_.ndim != 1 or states_.ndim != 2 or states_.shape[0] != ts_.shape[0]:
        raise ValueError(f"states must hold a row per time: shapes {ts_.shape} and "
                         f"{states_.shape}")
    _, _, p_, z_ = _vectors(np.zeros(1), states_[:1], p, z)
    if ts_.size == 0:
        return np.empty((0, np.asarray(observed(0.0, np.zeros(states_.shape[1]), p_,
                                                z_.copy())).size))
    n_observed = np.asarray(observed(ts_[0], states_[0], p_, z_.copy())).size
    return observed_grid_run(observed, n_observed, ts_, states_, p_, z_)


def _tolerances(rtol: float, atol: Any, x0: np.ndarray, grid: np.ndarray,
                first_step: float | None, max_step: float) -> np.ndarray:
    """atol per state, after the checks of the adaptive methods' arguments."""
    if not rtol > 0:
        raise ValueError(f"rtol must be positive, got {rtol!r}")
    atol_ = np.array(np.broadcast_to(np.asarray(atol, dtype=float), x0.shape))
    if not (atol_ >= 0).all():
        raise ValueError("atol must not be negative")
    if first_step is not None and not 0 < first_step <= grid[-1] - grid[0]:
        raise ValueError(f"first_step must be positive and within the interval, "
                         f"got {first_step!r}")
    if not max_step > 0:
        raise ValueError(f"max_step must be positive, got {max_step!r}")
    return atol_


def _vectors(grid: Any, x0: Any, p: Any, z: Any
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    # copies: the kernels take writable contiguous arrays (and never see the caller's)
    grid_ = np.array(grid, dtype=float)
    if grid_.ndim != 1 or grid_.size == 0 or not np.isfinite(grid_).all() \
            or (np.diff(grid_) <= 0).any():
        raise ValueError("the output grid must be a non-empty, finite, strictly "
                         "increasing 1-D array")
    x0_ = np.array(x0, dtype=float).ravel()
    if not isinstance(z, np.ndarray) or z.dtype != np.float64 or z.ndim != 1 \
            or not z.flags.c_contiguous or not z.flags.writeable:
        raise ValueError("z must be a writable contiguous 1-D float64 array (it is updated "
                         "in place)")
    return grid_, x0_, np.array(p, dtype=float).ravel(), z


def _functions(rhs: ModelFunction, observed: ModelFunction | None, grid: np.ndarray,
               x0: np.ndarray, p: np.ndarray, z: np.ndarray
               ) -> tuple[ModelFunction, ModelFunction, int]:
    """The model functions checked once from Python (on a copy of z), and the observed count.

    The kernels do no bounds checks, so a function whose result has the wrong length
    is refused here rather than read past its end.
    """
    from numba.core.dispatcher import Dispatcher

    from .addresses import install
    from .models import no_observed

    install()
    for name, f in (("rhs", rhs), ("observed", observed)):
        if f is not None and not isinstance(f, Dispatcher):
            raise TypeError(f"{name} must be a numba-jitted function, got {type(f).__name__}")
    size = np.asarray(rhs(grid[0], x0, p, z.copy())).shape
    if size != x0.shape:
        raise ValueError(f"rhs returns shape {size} for {x0.size} states")
    if observed is None:
        return rhs, no_observed, 0
    n_observed = np.asarray(observed(grid[0], x0, p, z.copy())).size
    return rhs, observed, n_observed


def _crossings(crossings: Crossings | None, grid: np.ndarray, x0: np.ndarray, p: np.ndarray,
               z: np.ndarray) -> tuple[ModelFunction, np.ndarray, np.ndarray]:
    """The zero-crossing function, held signs and directions as the kernels take them."""
    from numba.core.dispatcher import Dispatcher

    from .models import no_observed

    if crossings is None:
        return no_observed, np.empty(0), np.empty(0)
    if not isinstance(crossings.function, Dispatcher):
        raise TypeError(f"the zero-crossing function must be a numba-jitted function, got "
                        f"{type(crossings.function).__name__}")
    signs = np.array(crossings.signs, dtype=float).ravel()
    if not np.isin(signs, (-1.0, 1.0)).all():
        raise ValueError("the held signs must be +1 or -1")
    directions = np.zeros(signs.size) if crossings.directions is None \
        else np.array(crossings.directions, dtype=float).ravel()
    if directions.shape != signs.shape or not np.isin(directions, (-1.0, 0.0, 1.0)).all():
        raise ValueError("the directions must be -1, 0 or +1, one per held sign")
    size = np.asarray(crossings.function(grid[0], x0, p, z.copy())).shape
    if size != signs.shape:
        raise ValueError(f"the zero-crossing function returns shape {size} for "
                         f"{signs.size} held signs")
    return crossings.function, signs, directions


def _stop(t_stop: float, grid: np.ndarray) -> float:
    if not t_stop > grid[0]:
        raise ValueError(f"t_stop must be after the start, got {t_stop!r}")
    return float(t_stop)


def _run(grid: np.ndarray, result: tuple[Any, ...]) -> Run:
    (status, states, observed, filled, accepted, rejected, nfev, t_end, x_end, fired,
     next_step) = result[:11]
    states[filled:] = np.nan
    observed[filled:] = np.nan
    return Run(Status(status), grid, states, observed, int(filled), int(accepted),
               int(rejected), int(nfev), float(t_end), x_end, fired, float(next_step),
               int(result[11]) if len(result) > 11 else 0)
