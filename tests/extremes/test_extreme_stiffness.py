"""Stiffness k from 1 to 1e12 (unit masses): auto against the closed form, and the
solver it picks; an explicit solver where it is still affordable."""

from __future__ import annotations

import numpy as np
import pytest

import springc
from springc.build import CompiledModel

from .cases import STIFFNESSES, stiff_pair, stiff_pair_expm

BOUND = 2e-5  # max |x1 - cos(t)| over 10 s


def test_closed_form_matches_the_matrix_exponential() -> None:
    t = np.linspace(0.0, 10.0, 11)
    assert np.max(np.abs(stiff_pair(t, 1e4) - stiff_pair_expm(t, 1e4))) < 1e-10


@pytest.mark.parametrize("k", STIFFNESSES)
def test_auto_within_bound(compiled: dict[str, CompiledModel], k: float) -> None:
    result = springc.simulate(compiled["StiffPair"], parameters={"k": k})
    assert np.max(np.abs(result["x1"] - stiff_pair(result.time, k))) < BOUND
    rho_t = np.sqrt(1 + 2 * k) * 10
    assert result.stats.solver == ("radau" if rho_t > 2000 else "dop853")
    assert result.stats.reason.startswith("stiff: " if rho_t > 2000 else "non-stiff: ")


@pytest.mark.parametrize(("k", "solver"), [(1e4, "dop853"), (1e4, "bdf"), (1e12, "bdf")])
def test_other_solvers_within_bound(compiled: dict[str, CompiledModel], k: float,
                                    solver: str) -> None:
    result = springc.simulate(compiled["StiffPair"], parameters={"k": k}, solver=solver)
    assert np.max(np.abs(result["x1"] - stiff_pair(result.time, k))) < 20 * BOUND
