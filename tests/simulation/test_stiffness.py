"""The stiffness estimate behind ``--solver auto``, on matrices with known spectra."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from springc.simulation.stiffness import STIFF_THRESHOLD, choose_solver, spectral_radius


def oscillator_jacobian(k: float, m: float = 1.0) -> np.ndarray:
    """q' = v, v' = -(k/m) q: eigenvalues +-i sqrt(k/m)."""
    return np.array([[0.0, 1.0], [-k / m, 0.0]])


def test_small_dense_is_exact() -> None:
    assert abs(spectral_radius(oscillator_jacobian(1e4)) - 100.0) < 1e-9


def test_large_sparse_chain_bound_is_tight() -> None:
    # Fixed-free spring chain, k = 1, m = 1: the eigenvalues of K are
    # 4 sin^2((2j - 1) pi / (4n + 2)), so rho = 2 sin((2n - 1) pi / (4n + 2)).
    n = 1000
    k = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    k[n - 1, n - 1] = 1.0
    jac = sp.bmat([[None, sp.identity(n)], [-k.tocsr(), None]]).tocsr()
    exact = 2 * np.sin((2 * n - 1) * np.pi / (4 * n + 2))
    assert abs(spectral_radius(jac) - exact) < 1e-2 * exact


def test_choice_and_reason() -> None:
    soft = choose_solver(oscillator_jacobian(1.0), span=10.0)
    assert soft.solver == "dop853"
    assert soft.reason == "non-stiff: spectral radius 1 1/s over 10 s (rho*T = 10 <= 2000)"
    stiff = choose_solver(oscillator_jacobian(1e12), span=10.0)
    assert stiff.solver == "radau"
    assert stiff.stiffness > STIFF_THRESHOLD
    assert stiff.reason.startswith("stiff: fastest time scale 1/1e+06 s is 1e+07x shorter")


def test_non_finite_jacobian_goes_implicit() -> None:
    choice = choose_solver(np.array([[np.inf]]), span=1.0)
    assert choice.solver == "radau"


def test_large_non_stiff_jacobian_is_decided_by_the_row_sum_bound() -> None:
    n = 1000  # the chain above: row sums <= 4, so rho * T <= 40 without eigenvalues
    k = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    jac = sp.bmat([[None, sp.identity(n)], [-k.tocsr(), None]]).tocsr()
    choice = choose_solver(jac, span=10.0)
    assert choice.solver == "dop853"
    assert choice.reason == ("non-stiff: spectral radius <= 4 1/s (row-sum bound) over "
                             "10 s (rho*T <= 40 <= 2000)")
