"""Stiffness k from 1 to 1e12 (unit masses): auto against the closed form, and the
solver it picks; other solvers where they are still affordable.

Two pairs: with even walls the stiff mode x2 - x1 stays exactly at rest, so the
explicit method is never held to the stability limit and finishes in a few steps; with uneven
walls the stiff mode is excited at ~1/k, and auto's race decides (:mod:`springc.simulation.race`).
"""

from __future__ import annotations

import numpy as np
import pytest

import springc
from springc.pipeline.compiler import CompiledModel

from .cases import STIFFNESSES, stiff_pair, stiff_pair_expm, uneven_pair, uneven_pair_expm

BOUND = 2e-5  # max |x1 - cos(t)| over 10 s (x1 and x2 of the uneven pair)


def test_closed_forms_match_the_matrix_exponential() -> None:
    t = np.linspace(0.0, 10.0, 11)
    assert np.max(np.abs(stiff_pair(t, 1e4) - stiff_pair_expm(t, 1e4))) < 1e-10
    assert np.max(np.abs(uneven_pair(t, 1e4) - uneven_pair_expm(t, 1e4))) < 1e-9


@pytest.mark.parametrize("k", STIFFNESSES)
def test_auto_within_bound(compiled: dict[str, CompiledModel], k: float) -> None:
    result = springc.simulate(compiled["StiffPair"], parameters={"k": k})
    assert np.max(np.abs(result["x1"] - stiff_pair(result.time, k))) < BOUND
    # rho*T up to 1.4e7, but dop853 is never held to 1/rho: no estimate is needed (its
    # 10 compiled probe steps leave under 4 to go).
    assert result.stats.solver == "dop853"
    assert result.stats.reason == "non-stiff: dop853 needs ~3.9 more steps"


@pytest.mark.parametrize(("k", "solver", "steps", "reason"), [
    (1e4, "dop853", 799, "non-stiff: spectral radius 141 1/s over 10 s (rho*T = 1.41e+03 <= "
                         "2000)"),
    (1e8, "radau", 4729, "stiff: fastest time scale 1/1.41e+04 s is 1.41e+05x shorter than "
                         "the 10 s span; counted: radau finished the run in its trial steps, "
                         "~8.1e+04 RHS evaluations, dop853 ~7.3e+04 steps x 18.8 = ~1.4e+06 "
                         "to go"),
    (1e12, "radau", 129, "stiff: fastest time scale 1/1.41e+06 s is 1.41e+07x shorter than "
                         "the 10 s span; counted: radau ~1.4e+02 steps x 16.5 = ~2.3e+03 RHS "
                         "evaluations to go, dop853 ~5.8e+06 steps x 26.4 = ~1.5e+08")])
def test_auto_on_the_excited_stiff_mode(compiled: dict[str, CompiledModel], k: float,
                                        solver: str, steps: int, reason: str) -> None:
    # k = 1e4: rho*T = 1.4e3, no race. k = 1e8: the vibration's velocity (~5e-5) is
    # above the tolerance, radau must resolve its first periods, but its steps grow
    # as it damps them, and it finishes the run within its trial stretches (a fifth of
    # dop853's projected work); k = 1e12: below the tolerance (~5e-7), radau steps over
    # it from the start. Decided by counts (race.py), the same on every run. The race's
    # own run (error control off: tightening would rerun it at a tighter rtol).
    result = springc.simulate(compiled["StiffPair"], parameters={"k": k, "k2": 2.0},
                              error_control="off")
    assert (result.stats.solver, result.stats.steps, result.stats.reason) == (
        solver, steps, reason)
    positions = np.column_stack([result["x1"], result["x2"]])
    assert np.max(np.abs(positions - uneven_pair(result.time, k)[:, :2])) < BOUND


@pytest.mark.parametrize(("k", "solver"), [(1e4, "dop853"), (1e4, "bdf"), (1e12, "bdf")])
def test_other_solvers_within_bound(compiled: dict[str, CompiledModel], k: float,
                                    solver: str) -> None:
    result = springc.simulate(compiled["StiffPair"], parameters={"k": k}, solver=solver)
    assert np.max(np.abs(result["x1"] - stiff_pair(result.time, k))) < 20 * BOUND
