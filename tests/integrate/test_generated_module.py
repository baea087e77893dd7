"""The engine on a springc-generated numba module: the same trajectory as ``simulate``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.integrate

import springc
from same_method import assert_same_method
from springc.integrate import Status, dop853, fixed_step
from springc.simulation import initial_state

SEED = Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl"
CHAIN = Path(__file__).resolve().parents[2] / "models" / "Scenes.mdl"


def test_generated_module_runs_as_simulate_does() -> None:
    model = springc.compile_model([SEED], "SpringMass", backend="numba", cache=False)
    mod, p = model.module, model.parameters()
    grid = np.linspace(0.0, 10.0, 501)
    reference = springc.simulate(model, solver="dop853", stop=10.0, rtol=1e-6,
                                 error_control="off")  # the run itself, not rerun
    run = dop853(mod.rhs, grid, initial_state(model, p), p, mod.guesses(p), rtol=1e-6,
                 atol=1e-9, observed=mod.observed, scipy_arithmetic=False)  # as simulate
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


def test_vector_layout_module_runs_on_the_compiled_engine() -> None:
    # 100 masses: over 300 assignments, the vector layout (loops over index tables)
    model = springc.compile_model([CHAIN], "Scenes.Chain", backend="numba", cache=False,
                                  parameters={"N": 100})
    assert "\n_I = " in model.source
    compiled = springc.simulate(model, solver="dop853", stop=2.0, rtol=1e-10,
                                engine="compiled")
    scipy_run = springc.simulate(model, solver="dop853", stop=2.0, rtol=1e-10,
                                 engine="scipy")
    assert compiled.stats.engine == "compiled" and scipy_run.stats.engine == "scipy"
    # the same generated functions and scipy's method (plain-loop sums), observed too
    assert len(compiled.names) > 2 * 100
    assert_same_method(compiled, scipy_run, 1e-10)
    # against an independent tight reference: the same chain as a hand-written ODE
    k, rest, mass, ds, n = 100.0, 1.0, 1.0, 0.5, 100

    def chain(t: float, x: np.ndarray) -> np.ndarray:
        s, v = x[0::2], x[1::2]
        tension = k * (np.diff(np.concatenate(([0.0], s))) - rest)  # spring i pulls m[i]
        force = np.concatenate((tension[1:], [0.0])) - tension
        return np.column_stack((v, force / mass)).ravel()

    x0 = np.zeros(2 * n)
    x0[0::2] = rest * np.arange(1, n + 1)
    x0[0] += ds
    tight = scipy.integrate.solve_ivp(chain, (0.0, 2.0), x0, method="DOP853", rtol=1e-12,
                                      atol=1e-12, t_eval=compiled.time)
    for i in (0, 1, 2 * n - 2, 2 * n - 1):  # m[1].s, m[1].v, m[N].s, m[N].v
        np.testing.assert_allclose(compiled[model.states[i]], tight.y[i], rtol=0, atol=1e-8)
