"""``engine="compiled"`` (springc.integrate) against ``engine="scipy"``: the same values on
the output grid, the same failures, and the option checks."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from float_text import assert_same_text
from same_method import assert_same_method
from springc.cli import main
from springc.errors import SimulationError, UsageError
from springc.simulation import initial_state, write_csv

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
MODELS = {"seed": (SEED, None), "chain": (SCENES, "Scenes.Chain")}

FAILING = """
model Blowup
  Real x(start = 1);
equation
  der(x) = x * x;
end Blowup;

model Circle
  Real x(start = 0);
  Real y(start = -1);
equation
  der(x) = 1;
  x^2 + y^2 = 1;
end Circle;

model DivZero
  Real x(start = 1);
  Real y;
equation
  y = 1 / (x - 1);
  der(x) = y;
end DivZero;

model Overflow
  parameter Real a = 1e308;
  Real x(start = 1);
equation
  der(x) = a * x * 10 - a * x * 10;
end Overflow;

model Drift
  Real x(start = 0);
equation
  der(x) = 1e308;
end Drift;
"""


@pytest.fixture(scope="module")
def failing(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("engine") / "failing.mdl"
    path.write_text(FAILING)
    return str(path)


def csv_text(result: springc.SimulationResult) -> str:
    out = io.StringIO()
    write_csv(result, out)
    return out.getvalue()


@pytest.mark.parametrize("rtol", [1e-6, 1e-9])
@pytest.mark.parametrize("name", sorted(MODELS))
def test_compiled_dop853_is_scipys_method(name: str, rtol: float) -> None:
    files, model_name = MODELS[name]
    model = springc.compile_model(files, model_name, backend="numba")
    reference = springc.simulate(model, solver="dop853", rtol=1e-13, atol=1e-16)
    for solver in ("auto", "dop853"):
        compiled = springc.simulate(model, solver=solver, rtol=rtol, engine="compiled")
        scipy_run = springc.simulate(model, solver=solver, rtol=rtol, engine="scipy")
        assert compiled.stats.engine == "compiled" and scipy_run.stats.engine == "scipy"
        assert compiled.stats.solver == scipy_run.stats.solver == "dop853"
        # the same generated functions and controller; sums in plain loops, not BLAS
        assert_same_method(compiled, scipy_run, rtol, reference)
    # auto picks the compiled engine for the numba backend (the default), scipy for
    # the python backend
    default = springc.simulate(files, model_name=model_name, rtol=rtol)
    python = springc.simulate(files, model_name=model_name, rtol=rtol, backend="python")
    assert default.stats.engine == "compiled" and python.stats.engine == "scipy"
    assert_same_method(default, python, rtol, reference)


def test_the_kernel_with_scipys_sums_equals_scipy_bit_for_bit() -> None:
    """springc.integrate.dop853(scipy_arithmetic=True) on the generated seed: scipy's
    steps and values exactly (simulate's plain-loop sums are within rounding of it)."""
    from springc.integrate import dop853

    model = springc.compile_model(SEED, backend="numba")
    mod, p = model.module, model.parameters()
    scipy_run = springc.simulate(model, solver="dop853", engine="scipy", error_control="off")
    run = dop853(mod.rhs, scipy_run.time, initial_state(model, p), p, mod.guesses(p),
                 rtol=1e-6, atol=1e-9, scipy_arithmetic=True)
    assert run.accepted_steps == scipy_run.stats.steps == 972
    for i, name in enumerate(model.states):
        np.testing.assert_array_equal(run.states[:, i], scipy_run[name])


@pytest.mark.parametrize("name", sorted(MODELS))
def test_compiled_rk45_equals_scipy(name: str) -> None:
    files, model_name = MODELS[name]
    model = springc.compile_model(files, model_name, backend="numba")
    compiled = springc.simulate(model, solver="rk45", engine="compiled", stop=2.0,
                                error_control="off")
    scipy_run = springc.simulate(model, solver="rk45", engine="scipy", stop=2.0,
                                 error_control="off")
    assert compiled.stats.engine == "compiled" and scipy_run.stats.engine == "scipy"
    assert compiled.stats.steps == scipy_run.stats.steps
    # scipy's sums (BLAS): the same steps; the dense output's matrix product may round
    # differently (numba's and numpy's BLAS calls for K^T P)
    scale = np.abs(scipy_run.values).max(axis=0)
    assert (np.abs(compiled.values - scipy_run.values) <= 1e-13 * np.maximum(scale, 1)).all()


@pytest.mark.parametrize("solver", ["dop853", "rk45"])
def test_long_runs_go_on_where_a_stretch_stopped(monkeypatch: pytest.MonkeyPatch,
                                                  solver: str) -> None:
    # stretches of 50 steps (then 500, 5000): each goes on from the time, state and next
    # step size where the one before stopped, so the run takes one whole run's steps
    # and values exactly, with one more RHS evaluation per stretch (its start), not the whole run
    # again per stretch
    import springc.simulation.compiled as compiled_engine

    model = springc.compile_model(SEED, backend="numba")
    whole = springc.simulate(model, solver=solver, rtol=1e-8, engine="compiled")
    monkeypatch.setattr(compiled_engine, "FIRST_CHUNK", 50)
    compiled = springc.simulate(model, solver=solver, rtol=1e-8, engine="compiled")
    assert compiled.stats.engine == "compiled"
    assert compiled.stats.steps == whole.stats.steps > 550
    # stretches of 50, 500, 5,000 and 50,000 steps (rejected ones included): 3 to 5
    extra = compiled.stats.rhs_evaluations - whole.stats.rhs_evaluations
    assert 2 <= extra <= 4, extra
    np.testing.assert_array_equal(compiled.values, whole.values)  # the same run


@pytest.mark.parametrize("solver", ["radau", "bdf"])
@pytest.mark.parametrize("name", sorted(MODELS))
def test_compiled_implicit_agrees_with_scipy(name: str, solver: str) -> None:
    # the same method and controller from scipy's initial step; the LU's rounding moves
    # BDF's Newton decisions (scipy's own dense and sparse runs differ by 1 % in steps on
    # the chain), so the steps agree within 5 % and the values within the tolerance
    files, model_name = MODELS[name]
    model = springc.compile_model(files, model_name, backend="numba")
    compiled = springc.simulate(model, solver=solver, rtol=1e-6, engine="compiled",
                                stop=2.0)
    scipy_run = springc.simulate(model, solver=solver, rtol=1e-6, engine="scipy", stop=2.0)
    assert compiled.stats.engine == "compiled" and scipy_run.stats.engine == "scipy"
    assert abs(compiled.stats.steps / scipy_run.stats.steps - 1) < 0.05
    scale = np.abs(scipy_run.values).max(axis=0)
    assert (np.abs(compiled.values - scipy_run.values) <= 1e-4 * np.maximum(scale, 1)).all()


@pytest.mark.parametrize("solver", ["verlet", "symplectic-euler", "rk4"])
@pytest.mark.parametrize("name", sorted(MODELS))
def test_compiled_fixed_step_equals_python_integrators(name: str, solver: str) -> None:
    files, model_name = MODELS[name]
    model = springc.compile_model(files, model_name, backend="numba")
    compiled = springc.simulate(model, solver=solver, step=1e-3, stop=2.0, engine="compiled")
    python = springc.simulate(model, solver=solver, step=1e-3, stop=2.0, engine="scipy")
    assert compiled.stats.engine == "compiled" and python.stats.engine == "scipy"
    assert compiled.stats.steps == python.stats.steps == 2000
    scale = np.abs(python.values).max(axis=0)
    assert (np.abs(compiled.values - python.values) <= 1e-13 * np.maximum(scale, 1.0)).all()


FAILURE_RTOL = 1e-2
"""The states in a failure's notes near a blow-up (x = 1/(1 - t) at 1.5e14: 1.46726e+14
compiled, 1.46777e+14 on scipy's loop) differ far more than the runs before it."""
FAILURES = [
    # (model, simulate's keywords, the start of the message)
    ("Blowup", {"solver": "dop853", "stop": 2.0}, "the step size of dop853 collapsed at time 1"),
    ("Circle", {"stop": 3.0, "interval": 0.001},
     "the nonlinear system for y did not converge at time 1"),
    ("DivZero", {}, "division by zero while computing y ("),
    ("Overflow", {"solver": "dop853"}, "der(x) is NaN at time 0"),
    ("Blowup", {"solver": "rk4", "step": 0.01, "stop": 2.0, "interval": 0.01},
     "der(x) is infinite at time 1.02\n"),
    ("Drift", {"solver": "verlet", "step": 0.1, "stop": 3.0, "interval": 0.1},
     "the states became non-finite by time 1.8 (verlet, --step 0.1)\n"),
]


@pytest.mark.parametrize(("model_name", "keywords", "message"), FAILURES,
                         ids=[f"{m}-{k.get('solver', 'auto')}" for m, k, _ in FAILURES])
def test_failures_read_as_on_the_scipy_engine(failing: str, model_name: str,
                                              keywords: dict[str, object],
                                              message: str) -> None:
    errors = []
    for engine in ("compiled", "scipy"):
        with pytest.raises(SimulationError) as info:
            springc.simulate(failing, model_name=model_name, engine=engine,
                             **keywords)  # type: ignore[arg-type]
        errors.append(str(info.value))
    # the same words; the numbers (times, states) within FAILURE_RTOL: two differently
    # compiled loops reach a blow-up or a singularity by other roundings
    assert_same_text(errors[0], errors[1], FAILURE_RTOL)
    assert errors[0].startswith(f"error: {message}")


def test_step_limit_counts_the_same_steps() -> None:
    errors = []
    for engine in ("compiled", "scipy"):
        with pytest.raises(SimulationError) as info:
            springc.simulate(SEED, solver="dop853", max_steps=100, engine=engine)
        errors.append(str(info.value))
    assert_same_text(errors[0], errors[1], 1e-6)  # the states after 100 steps
    assert "100 steps of dop853 reached the step limit (--max-steps 100)" in errors[0]


def test_hopeless_step_size_stops_the_compiled_loop() -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(SEED, solver="dop853", parameters={"spring.k": 1e29},
                         engine="compiled")
    assert "far over the step limit (--max-steps 20000000)" in info.value.message
    assert info.value.hint == "the system is stiff: use --solver radau (or bdf)"


@pytest.mark.parametrize(("arguments", "message"), [
    (["--engine", "compiled", "--solver", "lsoda"],
     "error: --engine compiled: the lsoda solver has no compiled loop\n"),
    (["--engine", "compiled", "--backend", "python"],
     "error: --engine compiled runs the numba backend's functions, not --backend python\n"),
])
def test_compiled_requests_that_cannot_be_met_exit_2(arguments: list[str],
                                                     message: str) -> None:
    result = CliRunner().invoke(main, ["simulate", SEED, *arguments])
    assert result.exit_code == 2 and result.output.startswith(message)


def test_api_names_the_engine_argument() -> None:
    model = springc.compile_model(SEED, backend="python")  # no numba functions
    with pytest.raises(UsageError, match="engine compiled runs the numba backend") as info:
        springc.simulate(model, engine="compiled")
    assert info.value.option == "engine"
    with pytest.raises(UsageError, match="engine must be one of auto, compiled, scipy"):
        springc.simulate(model, engine="fast")
    assert springc.simulate(model, stop=0.5).stats.engine == "scipy"  # auto: scipy here


def test_switching_models_are_refused_on_the_compiled_engine() -> None:
    with pytest.raises(SimulationError, match=r"may switch its states during the run "
                                              r"\(dynamic state selection\), which only "
                                              "the scipy engine does"):
        springc.simulate(SCENES, model_name="Scenes.RigidPair", stop=0.1, engine="compiled")


def test_fixed_step_stretches_join_exactly(monkeypatch: pytest.MonkeyPatch) -> None:
    from springc.simulation import compiled as engine_module

    model = springc.compile_model(SEED, backend="numba")
    whole = springc.simulate(model, solver="verlet", step=1e-3, stop=2.0, engine="compiled")
    monkeypatch.setattr(engine_module, "FIXED_CHUNK", 300)  # 2000 steps in 7 stretches
    pieces = springc.simulate(model, solver="verlet", step=1e-3, stop=2.0, engine="compiled")
    assert pieces.stats.steps == whole.stats.steps == 2000
    # the seed's right-hand side does not read the clock: the same values, bit for bit
    np.testing.assert_array_equal(pieces.values, whole.values)
