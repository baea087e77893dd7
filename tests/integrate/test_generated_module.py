"""The engine on a springc-generated numba module: the same trajectory as ``simulate``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import springc
from springc.integrate import Status, dop853, fixed_step
from springc.simulation import initial_state

SEED = Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl"


def test_generated_module_runs_as_simulate_does() -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="numba", cache=False)
    mod, p = model.module, model.parameters()
    grid = np.linspace(0.0, 10.0, 501)
    reference = springc.simulate(model, solver="dop853", stop=10.0, rtol=1e-6)
    run = dop853(mod.rhs, grid, initial_state(model, p), p, mod.guesses(p), rtol=1e-6,
                 atol=1e-9, observed=mod.observed)
    assert run.status == Status.SUCCESS and run.accepted_steps == reference.stats.steps
    np.testing.assert_array_equal(reference.time, grid)
    for i, name in enumerate(model.states):
        np.testing.assert_array_equal(run.states[:, i], reference[name])  # bit for bit
    for i, name in enumerate(model.observed):
        np.testing.assert_array_equal(run.observed[:, i], reference[name])

    verlet = springc.simulate(model, solver="verlet", stop=10.0, step=1e-3)
    run = fixed_step("verlet", mod.rhs, grid, initial_state(model, p), p, mod.guesses(p),
                     step=1e-3, pairs=[(0, 2), (1, 3)])
    for i, name in enumerate(model.states):
        np.testing.assert_allclose(run.states[:, i], verlet[name], rtol=1e-13, atol=1e-13)
