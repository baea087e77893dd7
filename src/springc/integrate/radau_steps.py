"""Radau IIA (order 5), compiled: the method's hooks of the shared loop (:mod:`.loop`),
the Newton matrices, the simplified Newton iteration of the collocation system, the
step-size predictor and the dense output.

The implicit method for stiff scenes, as scipy's ``Radau`` runs it (Hairer and Wanner's
``radau5``: same controller, Newton iteration, Jacobian reuse and error estimate; the
tests compare steps and errors with scipy's on the same problems): the 3n x 3n Newton
system is transformed by ``T`` into one real and one complex n x n system (the complex
one solved as a real 2n x 2n system: :func:`factor_newton_matrices`), factorised by
:mod:`.banded_lu` in the ordering of :func:`.banded_lu.band_layout` (``order``:
position -> state), with the generated sparse Jacobian (``jacobian_values`` in CSC
order) assembled into the band.

numba keys its disk cache on this file's modification time only: touch it after editing
``radau_tableau``, ``banded_lu``, ``status``.
"""

import math

import numpy as np

from . import radau_tableau as tableau
from .arrays import copy, inlined, internal
from .banded_lu import band_factor, band_solve
from .dop853_steps import verdict
from .signatures import ModelFunction
from .status import JACOBIAN_CALLS, REJECTED, RHS_CALLS, Status

SUCCESS = int(Status.SUCCESS)
STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
MODEL_FAILED = int(Status.MODEL_FAILED)
MIN_FACTOR, MAX_FACTOR = 0.2, 10.0
EPS = float(np.finfo(float).eps)
ERROR_ORDER = 3  # of the error estimator: the initial step's exponent is 1 / 4
C, E, T, TI, P = tableau.C, tableau.E, tableau.T, tableau.TI, tableau.P
TI_REAL, TI_COMPLEX = tableau.TI_REAL, tableau.TI_COMPLEX
MU_REAL, MU_COMPLEX = tableau.MU_REAL, tableau.MU_COMPLEX
NEWTON_MAXITER = tableau.NEWTON_MAXITER


@inlined
def rms(x: np.ndarray) -> float:
    """Root mean square (scipy's ``norm(x) / sqrt(x.size)``) of a vector."""
    total = 0.0
    for j in range(x.size):
        total += x[j] * x[j]
    result: float = math.sqrt(total) / float(x.size) ** 0.5
    return result


@inlined
def pair_bands(kl: int, ku: int) -> tuple[int, int]:
    """The bandwidths of the complex system as a real one of twice the size (see
    :func:`factor_newton_matrices`)."""
    return 2 * kl if kl > 0 else 1, 2 * ku if ku > 0 else 1


@internal
def factor_newton_matrices(h: float, jacobian: np.ndarray, positions: np.ndarray,
                           diagonal: np.ndarray, kl: int, ku: int, real: np.ndarray,
                           pair: np.ndarray, pivots: np.ndarray) -> bool:
    """``MU_REAL / h I - J`` and ``MU_COMPLEX / h I - J`` assembled in their bands and
    factorised (pivots in ``pivots[0]``, ``pivots[1]``); False if either is singular.

    The complex matrix ``(a + i g) I - J`` is factorised as the real matrix of twice the
    size that acts on each state's real and imaginary parts side by side (rows and
    columns ``2i``, ``2i + 1``: the block ``[[a - J_ii, -g], [g, a - J_ii]]`` on the
    diagonal, ``-J_ij`` twice off it), so that one real band LU serves both systems:
    numba compiles no complex arithmetic (each complex specialisation of the band LU,
    its solve and the complex vectors cost seconds of compile time)."""
    width = real.shape[1]  # (positions: flat indices into the band)
    for i in range(real.shape[0]):
        for j in range(width):
            real[i, j] = 0.0
    for i in range(pair.shape[0]):
        for j in range(pair.shape[1]):
            pair[i, j] = 0.0
    kl2, ku2 = pair_bands(kl, ku)
    a, g = MU_COMPLEX.real / h, MU_COMPLEX.imag / h
    for k in range(diagonal.size):
        i = diagonal[k] // width
        real[i, diagonal[k] % width] = MU_REAL / h
        pair[2 * i, kl2], pair[2 * i, kl2 + 1] = a, -g
        pair[2 * i + 1, kl2 - 1], pair[2 * i + 1, kl2] = g, a
    for k in range(positions.size):
        i, column = positions[k] // width, positions[k] % width
        real[i, column] -= jacobian[k]
        column2 = 2 * (column - kl) + kl2
        pair[2 * i, column2] -= jacobian[k]
        pair[2 * i + 1, column2] -= jacobian[k]
    return (band_factor(real, kl, ku, pivots[0])
            and band_factor(pair, kl2, ku2, pivots[1]))


@inlined
def solve_pair(pair: np.ndarray, kl: int, ku: int, pivots: np.ndarray, order: np.ndarray,
               re: np.ndarray, im: np.ndarray, work: np.ndarray) -> None:
    """Solve the complex system factorised by :func:`factor_newton_matrices` in place
    (its real and imaginary parts ``re``, ``im`` in state order)."""
    kl2, ku2 = pair_bands(kl, ku)
    for q in range(order.size):
        work[2 * q], work[2 * q + 1] = re[order[q]], im[order[q]]
    band_solve(pair, kl2, ku2, pivots, work)
    for q in range(order.size):
        re[order[q]], im[order[q]] = work[2 * q], work[2 * q + 1]


@internal
def solve_in_order(factors: np.ndarray, kl: int, ku: int, pivots: np.ndarray,
                   order: np.ndarray, b: np.ndarray, work: np.ndarray) -> None:
    """Solve with band factors of the reordered matrix, ``b`` in state order, in place."""
    for i in range(order.size):
        work[i] = b[order[i]]
    band_solve(factors, kl, ku, pivots, work)
    for i in range(order.size):
        b[order[i]] = work[i]


@inlined
def predict_factor(h_abs: float, h_abs_old: float, error_norm: float,
                   error_norm_old: float) -> float:
    """Gustafsson's predictive step-size factor (``h_abs_old < 0``: no history)."""
    if error_norm_old < 0 or h_abs_old < 0 or error_norm == 0:
        multiplier = 1.0
    else:
        multiplier = h_abs / h_abs_old * (error_norm_old / error_norm) ** 0.25
    if error_norm == 0:
        return math.inf
    factor: float = min(1.0, multiplier) * error_norm ** -0.25
    return factor


@internal
def newton(rhs: ModelFunction, t: float, y: np.ndarray, h: float, Z0: np.ndarray,
           scale: np.ndarray, tol: float, real: np.ndarray, pair: np.ndarray,
           pivots: np.ndarray, kl: int, ku: int, order: np.ndarray, p: np.ndarray,
           z: np.ndarray, Z: np.ndarray, rows: np.ndarray, work_pair: np.ndarray
           ) -> tuple[bool, int, float, int, int]:
    """The simplified Newton iteration of the collocation system from ``Z0``; the stage
    increments in ``Z``; ``rows``: the method's vectors (from :data:`W_ROWS` on: work
    space), ``work_pair``: the complex system's. Returns (converged, iterations, rate
    (-1: none), evaluations, status: MODEL_FAILED if the model flagged a failure)."""
    n = y.size
    m_real = MU_REAL / h
    m_re, m_im = MU_COMPLEX.real / h, MU_COMPLEX.imag / h
    W, F, dW = rows[W_ROWS:W_ROWS + 3], rows[F_ROWS:F_ROWS + 3], rows[DW_ROWS:DW_ROWS + 3]
    stage, f_real, work_real = rows[NEWTON_STAGE], rows[F_REAL], rows[WORK_REAL]
    f_re, f_im = rows[F_RE], rows[F_IM]
    for r in range(3):
        for j in range(n):
            W[r, j] = TI[r, 0] * Z0[0, j] + TI[r, 1] * Z0[1, j] + TI[r, 2] * Z0[2, j]
    for r in range(3):
        copy(Z[r], Z0[r])
    dW_norm_old, rate = -1.0, -1.0
    evaluations, iterations = 0, 0
    for k in range(NEWTON_MAXITER):
        iterations = k + 1
        finite = True
        for i in range(3):
            for j in range(n):
                stage[j] = y[j] + Z[i, j]
            d = rhs(t + h * C[i], stage, p, z)
            evaluations += 1
            if z.size > 0 and z[z.size - 1] != 0.0:
                return False, iterations, rate, evaluations, MODEL_FAILED
            for j in range(n):
                F[i, j] = d[j]
                if not math.isfinite(d[j]):
                    finite = False
        if not finite:
            break
        for j in range(n):
            f_real[j] = (F[0, j] * TI_REAL[0] + F[1, j] * TI_REAL[1] + F[2, j] * TI_REAL[2]
                         - m_real * W[0, j])
            f_re[j] = (F[0, j] * TI[1, 0] + F[1, j] * TI[1, 1] + F[2, j] * TI[1, 2]
                       - (m_re * W[1, j] - m_im * W[2, j]))
            f_im[j] = (F[0, j] * TI[2, 0] + F[1, j] * TI[2, 1] + F[2, j] * TI[2, 2]
                       - (m_re * W[2, j] + m_im * W[1, j]))
        solve_in_order(real, kl, ku, pivots[0], order, f_real, work_real)
        solve_pair(pair, kl, ku, pivots[1], order, f_re, f_im, work_pair)
        total = 0.0
        for j in range(n):
            dW[0, j] = f_real[j] / scale[j]
            dW[1, j] = f_re[j] / scale[j]
            dW[2, j] = f_im[j] / scale[j]
        for r in range(3):
            for j in range(n):
                total += dW[r, j] * dW[r, j]
        dW_norm = math.sqrt(total) / float(3 * n) ** 0.5
        if dW_norm_old >= 0:
            rate = dW_norm / dW_norm_old
        if rate >= 0 and (rate >= 1 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dW_norm
                          > tol):
            break
        for j in range(n):
            W[0, j] += f_real[j]
            W[1, j] += f_re[j]
            W[2, j] += f_im[j]
        for r in range(3):
            for j in range(n):
                Z[r, j] = T[r, 0] * W[0, j] + T[r, 1] * W[1, j] + T[r, 2] * W[2, j]
        if dW_norm == 0 or (rate >= 0 and rate / (1 - rate) * dW_norm < tol):
            return True, iterations, rate, evaluations, SUCCESS
        dW_norm_old = dW_norm
    return False, iterations, rate, evaluations, SUCCESS


@inlined
def dense_coefficients(Z: np.ndarray, Q: np.ndarray) -> None:
    """The collocation polynomial of the step: ``Q = Z^T P`` (n x 3)."""
    for j in range(Z.shape[1]):
        for c in range(3):
            Q[j, c] = Z[0, j] * P[0, c] + Z[1, j] * P[1, c] + Z[2, j] * P[2, c]


@inlined
def dense_state(Q: np.ndarray, y_old: np.ndarray, x: float, out: np.ndarray) -> None:
    """The dense output at the step fraction ``x`` (from ``y_old``)."""
    x2 = x * x
    x3 = x2 * x
    for j in range(y_old.size):
        out[j] = y_old[j] + Q[j, 0] * x + Q[j, 1] * x2 + Q[j, 2] * x3


# The hooks of the shared loop (see :mod:`.loop` for their contract).

Layout = tuple[np.ndarray, int, int, np.ndarray, np.ndarray]
Work = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
             np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: the rows of the vectors ``work[3]`` (few arrays in the tuple: each one a hook takes
#: costs compile time): the state at the last step's start, the error weights, the error
#: estimate, its collocation part, a work vector, the derivative at the step's start
Y_OLD, SCALE, ERROR, ERROR_Z, STAGE, F = 0, 1, 2, 3, 4, 5
#: and the Newton iteration's work space (allocated once, not at every iteration): the
#: transformed increments ``W``, the stage derivatives, the corrections (3 rows each),
#: a stage, the real system's right-hand side and its solve's work vector
W_ROWS, F_ROWS, DW_ROWS, NEWTON_STAGE, F_REAL, WORK_REAL, F_RE, F_IM, VECTOR_ROWS = \
    6, 9, 12, 15, 16, 17, 18, 19, 20
#: the method's scalars between steps (``work[8]``): the Newton tolerance, the last
#: step size and error norm (-1: none), the start and length of the last step
NEWTON_TOL, H_ABS_OLD, ERROR_NORM_OLD, T_OLD, H_DENSE = 0, 1, 2, 3, 4
#: its flags (``work[9]``): the Jacobian is current, the matrices are factorised, the
#: last step's collocation polynomial is there
CURRENT_JAC, FACTORED, HAVE_DENSE = 0, 1, 2


@internal
def setup(n: int, layout: Layout) -> Work:
    """The stage arrays, the band matrices of the Newton systems and their pivots, the
    Jacobian's non-zeros, the derivative at the step's start and the scalars."""
    _, kl, ku, positions, _ = layout
    kl2, ku2 = pair_bands(kl, ku)
    return (np.zeros((3, n)), np.zeros((3, n)), np.zeros((n, 3)), np.empty((VECTOR_ROWS, n)),
            np.empty(positions.size), np.zeros((n, 2 * kl + ku + 1)),
            np.zeros((2 * n, 2 * kl2 + ku2 + 1)), np.empty((2, 2 * n), dtype=np.int64),
            np.zeros(5), np.zeros(3, dtype=np.int64), np.empty(2 * n))


@internal
def begin(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, f: np.ndarray,
          h_abs: float, p: np.ndarray, z: np.ndarray, rtol: float, work: Work,
          counts: np.ndarray, end: np.ndarray) -> tuple[int, float]:
    """The Newton tolerance, the Jacobian at the start, no step history."""
    reals, flags = work[8], work[9]
    reals[NEWTON_TOL] = max(10 * EPS / rtol, min(0.03, rtol ** 0.5))
    J = jac(t, y, p, z)
    counts[JACOBIAN_CALLS] += 1
    status = verdict(J, z)
    if status != SUCCESS:
        copy(end, y)
        return status, t
    copy(work[4], J)
    copy(work[3][F], f)
    flags[CURRENT_JAC], flags[FACTORED], flags[HAVE_DENSE] = 1, 0, 0
    reals[H_ABS_OLD], reals[ERROR_NORM_OLD], reals[T_OLD], reals[H_DENSE] = -1.0, -1.0, t, 0.0
    return SUCCESS, t


@internal
def converge(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, h: float,
             p: np.ndarray, z: np.ndarray, layout: Layout, work: Work, counts: np.ndarray
             ) -> tuple[bool, int, float, int]:
    """The collocation system of the step ``h`` solved by Newton's method, the matrices
    factorised again (and the Jacobian evaluated again once) where needed: (converged,
    iterations, rate, status)."""
    order, kl, ku, positions, diagonal = layout
    Z0, Z, scale, J = work[0], work[1], work[3][SCALE], work[4]
    real, pair, pivots, reals, flags = work[5], work[6], work[7], work[8], work[9]
    converged, n_iter, rate = False, 0, -1.0
    while not converged:
        if not flags[FACTORED]:
            flags[FACTORED] = factor_newton_matrices(h, J, positions, diagonal, kl, ku, real,
                                                     pair, pivots)
        if flags[FACTORED]:
            converged, n_iter, rate, used, status = newton(
                rhs, t, y, h, Z0, scale, reals[NEWTON_TOL], real, pair, pivots, kl, ku, order,
                p, z, Z, work[3], work[10])
            counts[RHS_CALLS] += used
            if status != SUCCESS:
                return False, n_iter, rate, status
        if converged or flags[CURRENT_JAC]:
            break
        values = jac(t, y, p, z)
        counts[JACOBIAN_CALLS] += 1
        status = verdict(values, z)
        if status != SUCCESS:
            return False, n_iter, rate, status
        copy(J, values)
        flags[CURRENT_JAC], flags[FACTORED] = 1, 0
    return converged, n_iter, rate, SUCCESS


@internal
def step(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray, h_proposed: float,
         h_abs: float, min_step: float, limit: float, p: np.ndarray, z: np.ndarray,
         rtol: float, atol: np.ndarray, layout: Layout, work: Work, counts: np.ndarray,
         y_new: np.ndarray, end: np.ndarray, blas: bool | None
         ) -> tuple[int, float, float, float, float]:
    """One accepted step of Radau IIA from ``(t, y)`` (rejected ones before it), then
    the next step size, the derivative there and, if Newton converged slowly, the
    Jacobian."""
    order, kl, ku = layout[0], layout[1], layout[2]
    Z0, Z, Q, vectors = work[0], work[1], work[2], work[3]
    y_old, scale, error, ZE = vectors[Y_OLD], vectors[SCALE], vectors[ERROR], vectors[ERROR_Z]
    stage, f = vectors[STAGE], vectors[F]
    real, pivots_real, reals, flags = work[5], work[7][0], work[8], work[9]
    n = y.size
    step_h_old, step_error_old = reals[H_ABS_OLD], reals[ERROR_NORM_OLD]
    if h_abs != h_proposed:  # clamped: no step-size history
        step_h_old, step_error_old = -1.0, -1.0
    step_rejected = False
    n_iter, rate, error_norm, safety = 0, -1.0, 0.0, 0.9
    while True:
        if h_abs < min_step:
            copy(end, y)
            return STEP_TOO_SMALL, t, 0.0, h_abs, t
        t_new = t + h_abs
        if t_new - limit > 0:
            t_new = limit
        h = t_new - t
        h_abs = abs(h)
        for i in range(3):  # the last step's collocation polynomial, extrapolated
            if flags[HAVE_DENSE]:
                dense_state(Q, y_old, (t + h * C[i] - reals[T_OLD]) / reals[H_DENSE], stage)
                for j in range(n):
                    Z0[i, j] = stage[j] - y[j]
            else:
                for j in range(n):
                    Z0[i, j] = 0.0
        for j in range(n):
            scale[j] = atol[j] + abs(y[j]) * rtol
        converged, n_iter, rate, status = converge(rhs, jac, t, y, h, p, z, layout, work,
                                                   counts)
        if status != SUCCESS:
            copy(end, y)
            return status, t, h, h_abs, t
        if not converged:  # (scipy's Radau: not a rejection of the error test)
            h_abs *= 0.5
            flags[FACTORED] = 0
            counts[REJECTED] += 1
            continue
        for j in range(n):
            y_new[j] = y[j] + Z[2, j]
            ZE[j] = (Z[0, j] * E[0] + Z[1, j] * E[1] + Z[2, j] * E[2]) / h
            error[j] = f[j] + ZE[j]
        solve_in_order(real, kl, ku, pivots_real, order, error, stage)
        for j in range(n):
            scale[j] = atol[j] + max(abs(y[j]), abs(y_new[j])) * rtol
            stage[j] = error[j] / scale[j]
        error_norm = rms(stage)
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
        if step_rejected and error_norm > 1:
            for j in range(n):
                stage[j] = y[j] + error[j]
            d = rhs(t, stage, p, z)
            counts[RHS_CALLS] += 1
            if z.size > 0 and z[z.size - 1] != 0.0:
                copy(end, stage)
                return MODEL_FAILED, t, h, h_abs, t
            for j in range(n):
                error[j] = d[j] + ZE[j]
            solve_in_order(real, kl, ku, pivots_real, order, error, stage)
            for j in range(n):
                stage[j] = error[j] / scale[j]
            error_norm = rms(stage)
        if error_norm > 1:
            factor = predict_factor(h_abs, step_h_old, error_norm, step_error_old)
            h_abs *= max(MIN_FACTOR, safety * factor)
            flags[FACTORED] = 0
            step_rejected = True
            counts[REJECTED] += 1
            continue
        break
    return after_step(rhs, jac, t, y, t_new, h, h_abs, h_proposed, step_h_old,
                      step_error_old, n_iter, rate, error_norm, safety, p, z, work, counts,
                      y_new, end)


@internal
def after_step(rhs: ModelFunction, jac: ModelFunction, t: float, y: np.ndarray,
               t_new: float, h: float, h_abs: float, h_proposed: float, step_h_old: float,
               step_error_old: float, n_iter: int, rate: float, error_norm: float,
               safety: float, p: np.ndarray, z: np.ndarray, work: Work, counts: np.ndarray,
               y_new: np.ndarray, end: np.ndarray) -> tuple[int, float, float, float, float]:
    """After an accepted step: the next step size, the derivative at the new state, the
    Jacobian there if Newton converged slowly, and the step's collocation polynomial."""
    Z, Q, y_old, J, f = work[1], work[2], work[3][Y_OLD], work[4], work[3][F]
    reals, flags = work[8], work[9]
    recompute_jac = n_iter > 2 and rate > 1e-3
    factor = min(MAX_FACTOR, safety * predict_factor(h_abs, step_h_old, error_norm,
                                                       step_error_old))
    if not recompute_jac and factor < 1.2:
        factor = 1.0
    else:
        flags[FACTORED] = 0
    d = rhs(t_new, y_new, p, z)
    counts[RHS_CALLS] += 1
    status = verdict(d, z)
    if status != SUCCESS:
        copy(end, y_new)
        return status, t_new, h, h_abs, t_new
    copy(f, d)
    if recompute_jac:
        values = jac(t_new, y_new, p, z)
        counts[JACOBIAN_CALLS] += 1
        status = verdict(values, z)
        if status != SUCCESS:
            copy(end, y_new)
            return status, t_new, h, h_abs, t_new
        copy(J, values)
        flags[CURRENT_JAC] = 1
    else:
        flags[CURRENT_JAC] = 0
    reals[H_ABS_OLD], reals[ERROR_NORM_OLD] = h_proposed, error_norm
    copy(y_old, y)
    reals[T_OLD], reals[H_DENSE] = t, h
    dense_coefficients(Z, Q)
    flags[HAVE_DENSE] = 1
    return SUCCESS, t_new, h, h_abs * factor, t


@internal
def prepare_dense(rhs: ModelFunction, t: float, h: float, y: np.ndarray, y_new: np.ndarray,
                  p: np.ndarray, z: np.ndarray, work: Work, counts: np.ndarray,
                  end: np.ndarray, blas: bool | None) -> tuple[int, float]:
    """Nothing: the step's collocation polynomial is its dense output."""
    return SUCCESS, t


@internal
def dense(work: Work, t: float, h: float, y: np.ndarray, at: float, out: np.ndarray,
          blas: bool | None) -> None:
    """The collocation polynomial of the step at time ``at``."""
    dense_state(work[2], y, (at - t) / h, out)
