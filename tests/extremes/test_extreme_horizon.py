"""Long horizons: 10^4 periods of a unit-period oscillator; the symplectic
integrators keep the energy bounded (no drift), RK4 loses it at the same step."""

from __future__ import annotations

import numpy as np
import pytest

import springc
from springc.pipeline.compiler import CompiledModel

K = (2 * np.pi) ** 2  # period 1 s
PERIODS = 10_000
H = 1 / 25


def energy(result: springc.SimulationResult) -> np.ndarray:
    return 0.5 * result["v"] ** 2 + 0.5 * K * result["x"] ** 2


@pytest.mark.parametrize(("solver", "bound"), [("verlet", 0.02), ("symplectic-euler", 0.3)])
def test_symplectic_energy_bounded(compiled: dict[str, CompiledModel], solver: str,
                                   bound: float) -> None:
    result = springc.simulate(compiled["Harmonic"], parameters={"k": K}, stop=PERIODS,
                              interval=0.37 * 50, solver=solver, step=H)
    e = energy(result)
    e0 = e[0]
    # An error of order omega*h (verlet: (omega*h)^2/4 = 0.016) at every output time...
    assert np.max(np.abs(e - e0)) / e0 < bound
    # ... that does not grow: the envelope of the last tenth is that of the first.
    tenth = len(e) // 10
    first, last = np.max(np.abs(e[:tenth] - e0)), np.max(np.abs(e[-tenth:] - e0))
    assert last < 1.05 * first


def test_rk4_energy_drifts(compiled: dict[str, CompiledModel]) -> None:
    result = springc.simulate(compiled["Harmonic"], parameters={"k": K}, stop=PERIODS / 10,
                              interval=10.0, solver="rk4", step=H)
    e = energy(result)
    # RK4 damps by (omega*h)^6/72 per step: 8.3 % lost over 1,000 periods.
    loss = 1 - (1 - (2 * np.pi * H) ** 6 / 72) ** (PERIODS / 10 / H)
    assert abs((1 - e[-1] / e[0]) - loss) < 0.1 * loss
