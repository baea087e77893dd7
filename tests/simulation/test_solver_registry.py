"""The solver registry (simulation/solver_names.py): every fact about a solver in one
row, a row missing a fact its kind needs refused, the tables derived from the rows."""

from __future__ import annotations

import pytest

from springc.simulation import solver_names as names
from springc.simulation.integrators import STEPPERS


def test_fixed_step_rows_state_their_order_and_have_a_step() -> None:
    assert names.ORDERS == {"verlet": 2, "symplectic-euler": 1, "rk4": 4}
    assert set(names.FIXED_STEP) <= set(STEPPERS)
    assert [s for s in names.FIXED_STEP if names.registered(s).pairs] == \
        ["verlet", "symplectic-euler"]


def test_a_fixed_step_row_without_an_order_is_refused() -> None:
    with pytest.raises(ValueError) as info:
        names.Solver("leapfrog", names.FIXED)
    assert str(info.value) == "solver leapfrog: a fixed-step solver states its order"
    with pytest.raises(ValueError) as info:
        names.Solver("ode23", names.ADAPTIVE)
    assert str(info.value) == "solver ode23: an adaptive solver names its scipy class"


def test_derived_tables() -> None:
    assert names.SOLVERS == {"rk45": "RK45", "dop853": "DOP853", "radau": "Radau",
                             "bdf": "BDF", "lsoda": "LSODA"}
    assert sorted(names.IMPLICIT_SOLVERS) == ["bdf", "lsoda", "radau"]
    assert names.ALL_SOLVERS == ("auto", "rk45", "dop853", "radau", "bdf", "lsoda",
                                 "verlet", "symplectic-euler", "rk4")
    assert names.COMPILED_SOLVERS == ("rk45", "dop853", "radau", "bdf", "verlet",
                                      "symplectic-euler", "rk4")
    assert [names.registered(s).setting for s in ("rk4", "lsoda")] == ["step", "rtol"]
