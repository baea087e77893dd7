"""DOP853, compiled, in the argument order of a run without a Jacobian: the shared loop
of :mod:`.loop` specialised on :mod:`.dop853_steps` (with scipy's sums, or plain loops).

:func:`dop853_run` is the entry point other compiled code calls (the ensemble of
:mod:`.ensemble_kernel` runs it once per row); Python calls go through
:func:`springc.integrate.dop853`, which compiles only the arithmetic it asks for. A
stage whose derivative is not finite rejects its attempt where a shorter step is allowed
(:func:`.dop853_steps.shrinks`; numba's cache of this file does not see a change of
that one: edit this docstring with it).
"""

import numpy as np
from numba import njit

from .dop853_steps import Work  # noqa: F401  (the hooks module is the method)
from .kernels import dispatcher
from .signatures import ImplicitTuple, ModelFunction

PLAIN = dispatcher("dop853")
SCIPY_SUMS = dispatcher("dop853", blas=True)


@njit(cache=True, error_model="numpy", nogil=True)
def dop853_run(rhs: ModelFunction, observed: ModelFunction, n_observed: int,
               crossing: ModelFunction, signs: np.ndarray, directions: np.ndarray,
               grid: np.ndarray, x0: np.ndarray, p: np.ndarray, z: np.ndarray, rtol: float,
               atol: np.ndarray, max_step: float, first_step: float, max_steps: int,
               blas: bool, t_stop: float) -> ImplicitTuple:
    """Integrate ``x' = rhs(t, x, p, z)`` over ``grid`` with DOP853 (arguments as
    :func:`.loop.adaptive_loop`, ``blas``: scipy's sums). Returns ``IMPLICIT_RESULT``
    (no Jacobian evaluations)."""
    none = np.empty(0, dtype=np.int64)
    layout = (none, 0, 0, none, none)
    if blas:
        result: ImplicitTuple = SCIPY_SUMS(rhs, observed, observed, n_observed, crossing,
                                           signs, directions, grid, x0, p, z, rtol, atol,
                                           max_step, first_step, max_steps, t_stop, layout)
        return result
    plain: ImplicitTuple = PLAIN(rhs, observed, observed, n_observed, crossing, signs,
                                 directions, grid, x0, p, z, rtol, atol, max_step,
                                 first_step, max_steps, t_stop, layout)
    return plain
