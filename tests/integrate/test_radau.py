"""Compiled Radau IIA against scipy's Radau (same steps, evaluations and solution), its
banded LU against dense solves, events on its dense output, and a sparse chain."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.integrate
import scipy.integrate._ivp.radau as scipy_radau
import scipy.sparse as sp

from springc.integrate import Crossings, Status, radau
from springc.integrate import radau_tableau as tableau
from springc.integrate.banded_lu import band_factor, band_layout, band_solve

JIT = {"cache": True, "error_model": "numpy"}
NO_Z = np.zeros(0)


def scipy_jacobian(values: object, indptr: np.ndarray, indices: np.ndarray, n: int) -> object:
    return sp.csc_matrix((values, indices, indptr), shape=(n, n))


def test_tableau_is_scipys() -> None:
    for name in ("C", "E", "T", "TI", "P"):
        np.testing.assert_array_equal(getattr(tableau, name), getattr(scipy_radau, name))
    assert tableau.MU_REAL == scipy_radau.MU_REAL
    assert tableau.MU_COMPLEX == scipy_radau.MU_COMPLEX


@pytest.mark.parametrize("n, dense_limit", [(7, 64), (300, 64)])
def test_banded_lu_solves_like_a_dense_solve(n: int, dense_limit: int) -> None:
    rng = np.random.default_rng(n)
    A = (sp.random(n, n, density=3.0 / n, random_state=n, format="csc")
         + sp.diags(rng.normal(size=n))).tocsc()
    A.sort_indices()
    order, kl, ku, positions, diagonal = band_layout(n, A.indptr, A.indices, dense_limit)
    for c in (0.5, 2.0 - 1.5j):
        B = np.zeros((n, 2 * kl + ku + 1), dtype=complex if isinstance(c, complex) else float)
        B.reshape(-1)[diagonal] = c
        np.subtract.at(B.reshape(-1), positions, A.data)
        pivots = np.empty(n, dtype=np.int64)
        assert band_factor(B, kl, ku, pivots)
        b = rng.normal(size=n).astype(B.dtype)
        x = b[order].copy()
        band_solve(B, kl, ku, pivots, x)
        solution = np.empty_like(x)
        solution[order] = x
        expected = np.linalg.solve(c * np.eye(n) - A.toarray(), b)
        np.testing.assert_allclose(solution, expected, rtol=1e-9, atol=1e-12)


def test_chain_band_after_reverse_cuthill_mckee_is_narrow(stiff: SimpleNamespace) -> None:
    indptr, indices = stiff.chain_pattern(1000)
    order, kl, ku, _, _ = band_layout(2000, indptr, indices)
    assert sorted(order) == list(range(2000)) and max(kl, ku) <= 3


def scipy_van_der_pol(stiff: SimpleNamespace, rtol: float, atol: float, p: np.ndarray,
                      stop: float) -> object:
    return scipy.integrate.solve_ivp(
        lambda t, x: stiff.van_der_pol(t, x, p, NO_Z), (0.0, stop), [2.0, 0.0], method="Radau",
        rtol=rtol, atol=atol, dense_output=True,
        jac=lambda t, x: scipy_jacobian(stiff.van_der_pol_jacobian(t, x, p, NO_Z), stiff.VDP_INDPTR,
                                        stiff.VDP_INDICES, 2).toarray())


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-7])
def test_same_steps_and_evaluations_as_scipy_on_stiff_van_der_pol(stiff: SimpleNamespace,
                                                                 rtol: float) -> None:
    mu, stop, atol = 1000.0, 3000.0, rtol * 1e-3
    p = np.array([mu])
    ref = scipy_van_der_pol(stiff, rtol, atol, p, stop)
    grid = np.linspace(0.0, stop, 301)
    run = radau(stiff.van_der_pol, stiff.van_der_pol_jacobian, stiff.VDP_INDPTR,
                stiff.VDP_INDICES, grid,
                [2.0, 0.0], p, NO_Z, rtol=rtol, atol=atol)
    assert run.ok
    assert run.accepted_steps == len(ref.t) - 1
    assert run.rhs_evaluations == ref.nfev and run.jacobian_evaluations == ref.njev
    # the same steps: the solutions differ by rounding only (BLAS vs loop sums)
    scale = np.abs(ref.y).max(axis=1)
    assert (np.abs(run.states - ref.sol(grid).T) <= 1e-8 * scale).all()


def test_tight_tolerance_van_der_pol_within_rounding_of_scipy(stiff: SimpleNamespace) -> None:
    # at rtol 1e-9 rounding differences grow over 7,000 steps into other step choices:
    # the step count and the solution agree to the tolerance
    mu, stop, rtol = 1000.0, 3000.0, 1e-9
    p = np.array([mu])
    ref = scipy_van_der_pol(stiff, rtol, rtol * 1e-3, p, stop)
    grid = np.linspace(0.0, stop, 301)
    run = radau(stiff.van_der_pol, stiff.van_der_pol_jacobian, stiff.VDP_INDPTR,
                stiff.VDP_INDICES, grid,
                [2.0, 0.0], p, NO_Z, rtol=rtol, atol=rtol * 1e-3)
    assert abs(run.accepted_steps / (len(ref.t) - 1) - 1) < 0.01
    scale = np.abs(ref.y).max(axis=1)
    assert (np.abs(run.states - ref.sol(grid).T) <= 1e3 * rtol * scale).all()


def test_sparse_chain_agrees_with_scipy_radau_at_equal_tolerance(stiff: SimpleNamespace) -> None:
    masses = 100  # 200 states: above the dense limit, banded after the ordering
    p, rtol = np.array([1e4, 1.0, 1.0]), 1e-6
    x0 = np.zeros(2 * masses)
    x0[1::2] = np.linspace(1.0, 0.0, masses)  # a velocity profile
    indptr, indices = stiff.chain_pattern(masses)
    grid = np.linspace(0.0, 2.0, 41)
    run = radau(stiff.chain, stiff.chain_jacobian, indptr, indices, grid, x0, p, NO_Z, rtol=rtol,
                atol=rtol * 1e-3)
    ref = scipy.integrate.solve_ivp(
        lambda t, x: stiff.chain(t, x, p, NO_Z), (0.0, 2.0), x0, method="Radau", rtol=rtol,
        atol=rtol * 1e-3, t_eval=grid,
        jac=lambda t, x: scipy_jacobian(stiff.chain_jacobian(t, x, p, NO_Z), indptr, indices,
                                        2 * masses))
    tight = radau(stiff.chain, stiff.chain_jacobian, indptr, indices, grid, x0, p, NO_Z, rtol=1e-11,
                  atol=1e-14)
    assert run.ok and tight.ok
    error = np.abs(run.states - tight.states).max()
    scipy_error = np.abs(ref.y.T - tight.states).max()
    assert 0.5 <= error / scipy_error <= 2  # same error at equal tolerance
    assert error < 1e-3 * np.abs(tight.states).max()


def test_bouncing_ball_impact_on_the_collocation_polynomial(stiff: SimpleNamespace) -> None:
    # constant acceleration: the cubic collocation polynomial is exact
    run = radau(stiff.falling, stiff.falling_jacobian, np.array([0, 0, 1]), np.array([0]),
                [0.0, 1.0], [1.0, 0.0], [9.81], NO_Z, rtol=1e-10, atol=1e-12,
                crossings=Crossings(stiff.height, [1.0]))
    assert run.status == Status.STATE_EVENT and list(run.fired) == [-1]
    assert run.event_time == pytest.approx(math.sqrt(2 / 9.81), abs=1e-9)


