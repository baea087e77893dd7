"""Compiled BDF against scipy's BDF: same steps and evaluations on stiff van der Pol,
the same error on a sparse chain at equal tolerance, events on its interpolant."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.integrate
import scipy.sparse as sp

from springc.integrate import Crossings, Status, bdf, dop853
from springc.integrate.bdf_steps import change_differences

NO_Z = np.zeros(0)


def test_difference_rescaling_is_scipys() -> None:
    from scipy.integrate._ivp.bdf import change_D

    rng = np.random.default_rng(0)
    for order in range(1, 6):
        ours = rng.normal(size=(8, 3))
        theirs = ours.copy()
        change_differences(ours, order, 0.37)
        change_D(theirs, order, 0.37)
        np.testing.assert_allclose(ours, theirs, rtol=1e-13, atol=1e-13)


def scipy_bdf(ode: SimpleNamespace, rtol: float, p: np.ndarray, stop: float) -> object:
    return scipy.integrate.solve_ivp(
        lambda t, x: ode.van_der_pol(t, x, p, NO_Z), (0.0, stop), [2.0, 0.0], method="BDF",
        rtol=rtol, atol=rtol * 1e-3, dense_output=True,
        jac=lambda t, x: sp.csc_matrix((ode.van_der_pol_jacobian(t, x, p, NO_Z),
                                        ode.VDP_INDICES, ode.VDP_INDPTR), shape=(2, 2)).toarray())


@pytest.mark.parametrize("rtol", [1e-4, 1e-6])
def test_same_steps_and_evaluations_as_scipy_on_stiff_van_der_pol(stiff: SimpleNamespace,
                                                                 rtol: float) -> None:
    ode, p, stop = stiff, np.array([1000.0]), 3000.0
    ref = scipy_bdf(ode, rtol, p, stop)
    grid = np.linspace(0.0, stop, 301)
    run = bdf(ode.van_der_pol, ode.van_der_pol_jacobian, ode.VDP_INDPTR, ode.VDP_INDICES, grid,
              [2.0, 0.0], p, NO_Z, rtol=rtol, atol=rtol * 1e-3)
    assert run.ok and run.accepted_steps == len(ref.t) - 1
    assert run.rhs_evaluations == ref.nfev and run.jacobian_evaluations == ref.njev
    # the same steps; rounding (loops vs BLAS sums) grows through the sharp transitions
    scale = np.abs(ref.y).max(axis=1)
    assert (np.abs(run.states - ref.sol(grid).T) <= 0.1 * rtol * scale).all()


def test_sparse_chain_same_error_as_scipy_bdf(stiff: SimpleNamespace) -> None:
    ode, masses, rtol = stiff, 100, 1e-6
    p = np.array([1e4, 1.0, 1.0])
    x0 = np.zeros(2 * masses)
    x0[1::2] = np.linspace(1.0, 0.0, masses)
    indptr, indices = ode.chain_pattern(masses)
    grid = np.linspace(0.0, 2.0, 41)
    run = bdf(ode.chain, ode.chain_jacobian, indptr, indices, grid, x0, p, NO_Z, rtol=rtol,
              atol=rtol * 1e-3)
    ref = scipy.integrate.solve_ivp(
        lambda t, x: ode.chain(t, x, p, NO_Z), (0.0, 2.0), x0, method="BDF", rtol=rtol,
        atol=rtol * 1e-3, t_eval=grid,
        jac=lambda t, x: sp.csc_matrix((ode.chain_jacobian(t, x, p, NO_Z), indices, indptr),
                                       shape=(2 * masses, 2 * masses)))
    tight = dop853(ode.chain, grid, x0, p, NO_Z, rtol=1e-12, atol=1e-15)
    assert run.ok and tight.ok
    error = np.abs(run.states - tight.states).max()
    scipy_error = np.abs(ref.y.T - tight.states).max()
    assert 0.5 <= error / scipy_error <= 2


def test_bouncing_ball_impact_on_the_interpolant(stiff: SimpleNamespace) -> None:
    run = bdf(stiff.falling, stiff.falling_jacobian, np.array([0, 0, 1]), np.array([0]),
              [0.0, 1.0], [1.0, 0.0], [9.81], NO_Z, rtol=1e-10, atol=1e-12,
              crossings=Crossings(stiff.height, [1.0]))
    assert run.status == Status.STATE_EVENT and list(run.fired) == [-1]
    assert run.event_time == pytest.approx(math.sqrt(2 / 9.81), abs=1e-8)
