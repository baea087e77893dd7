"""Near-singular geometry: a 2D spring whose length passes through 0 (the direction
divides by the length), and a start exactly on the singularity."""

from __future__ import annotations

import numpy as np
import pytest

import springc
from springc.errors import SimulationError
from springc.pipeline.compiler import CompiledModel

from .cases import harmonic


@pytest.mark.parametrize("solver", ["auto", "radau"])
def test_passes_through_zero_length(compiled: dict[str, CompiledModel], solver: str) -> None:
    result = springc.simulate(compiled["Through"], solver=solver)
    x = result["pos[1]"]
    assert np.sum(np.diff(np.sign(x)) != 0) >= 30  # it did cross the anchor, 31 times
    assert np.max(np.abs(x - harmonic(result.time, k=100))) < 1e-4
    assert np.max(np.abs(result["pos[2]"])) == 0.0


def test_verlet_passes_through_zero_length(compiled: dict[str, CompiledModel]) -> None:
    result = springc.simulate(compiled["Through"], solver="verlet", step=1e-3)
    assert np.max(np.abs(result["pos[1]"] - harmonic(result.time, k=100))) < 1e-3


@pytest.mark.parametrize("solver", ["auto", "dop853", "radau", "verlet"])
def test_start_at_zero_length_is_a_clear_error(compiled: dict[str, CompiledModel],
                                               solver: str) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(compiled["Through"], parameters={"r": 0.0}, solver=solver,
                         step=1e-3)
    error = info.value
    assert error.message.startswith("division by zero while computing dir[1] (")
    assert error.message.endswith(" at time 0")
    assert [n.message for n in error.notes][:2] == ["pos[1] = 0", "pos[2] = 0"]
