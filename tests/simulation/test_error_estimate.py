"""``error_estimate`` / ``--error-estimate``: the estimated global error against the true
error (a run at rtol 1e-13), the Richardson estimate of the fixed-step solvers, auto's
budget, the API attribute, the summary line and the CSV side file."""

from __future__ import annotations

import csv
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline import CompiledModel
from springc.simulation.error_estimate import AUTO_BUDGET, wanted

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
MODELS = {"seed": (SEED, None), "chain": (SCENES, "Scenes.Chain"),
          "pendulum": (SCENES, "Scenes.Pendulum")}


@cache
def model(name: str) -> CompiledModel:
    files, model_name = MODELS[name]
    return springc.compile_model(files, model_name, backend="numba")


@cache
def reference(name: str) -> springc.SimulationResult:
    return springc.simulate(model(name), solver="dop853", rtol=1e-13, atol=1e-16,
                            error_estimate="off")


def true_relative_error(result: springc.SimulationResult, ref: springc.SimulationResult
                        ) -> np.ndarray:
    """Per state: max |x - x_ref| over the grid / max |x| (the estimate's measure)."""
    columns = [result.names.index(s) for s in result.error_estimate.names]
    values = result.values[:, columns]
    error = np.abs(values - ref.values[:, columns]).max(axis=0)
    return error / np.abs(values).max(axis=0)


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("rtol", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9])
def test_estimate_is_within_a_factor_3_of_the_true_error(name: str, rtol: float) -> None:
    result = springc.simulate(model(name), solver="dop853", rtol=rtol, error_estimate="on")
    estimate = result.error_estimate
    assert estimate is not None
    true = true_relative_error(result, reference(name))
    assert 1 / 3 <= estimate.error / true.max() <= 3
    # every state whose error stands above the reference's own (1e-11) is within 3x too
    above = true > 1e-11
    assert (np.abs(np.log(estimate.relative[above] / true[above])) <= np.log(3)).all()


@pytest.mark.parametrize("solver, step", [("rk4", 2e-3), ("verlet", 2e-4)])
def test_richardson_estimate_of_the_fixed_step_solvers(solver: str, step: float) -> None:
    result = springc.simulate(model("seed"), solver=solver, step=step, error_estimate="on")
    estimate = result.error_estimate
    assert estimate is not None and estimate.method.startswith(f"Richardson against {solver}")
    true = true_relative_error(result, reference("seed"))
    assert 1 / 3 <= estimate.error / true.max() <= 3


def test_auto_estimates_within_its_budget_of_the_run() -> None:
    # a compiled dop853 companion at a 1000x tighter tolerance: 1000^(1/8) ~ 2.37x the loop
    assert wanted("auto", "dop853", True, loop_time=0.01, elapsed=0.0238 / AUTO_BUDGET)
    assert not wanted("auto", "dop853", True, loop_time=0.01, elapsed=0.0236 / AUTO_BUDGET)
    assert wanted("auto", "rk4", True, loop_time=0.01, elapsed=0.02 / AUTO_BUDGET)
    assert not wanted("auto", "radau", False, loop_time=0.0, elapsed=100.0)  # scipy: off
    assert not wanted("off", "dop853", True, loop_time=0.01, elapsed=100.0)
    assert wanted("on", "radau", False, loop_time=0.0, elapsed=0.0)


def test_api_attribute_summary_and_off() -> None:
    on = springc.simulate(model("seed"), solver="dop853", error_estimate="on")
    off = springc.simulate(model("seed"), solver="dop853", error_estimate="off")
    estimate = on.error_estimate
    assert estimate is not None and off.error_estimate is None
    assert estimate.names == model("seed").states
    i = estimate.worst
    assert on.stats.summary("S").endswith(
        f"; estimated error {estimate.relative[i]:.2g} (relative; {estimate.absolute[i]:.2g} "
        f"in {estimate.names[i]} at t = {estimate.times[i]:.4g} s; companion dop853 run at "
        f"rtol 1e-09, {estimate.seconds:.3f} s)")
    assert "estimated error" not in off.stats.summary("S")
    np.testing.assert_array_equal(on.values, off.values)  # the run itself is unchanged


def test_bad_mode_names_the_option() -> None:
    with pytest.raises(UsageError, match="error_estimate must be one of off, on, auto, "
                                         "not 'sometimes'"):
        springc.simulate(model("seed"), error_estimate="sometimes")
    result = CliRunner().invoke(main, ["simulate", SEED, "--error-estimate", "sometimes"])
    assert result.exit_code == 2 and "--error-estimate" in result.stderr


def test_error_output_table_and_unchanged_csv(tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    result = CliRunner().invoke(main, ["simulate", SEED, "--backend", "numba", "--solver",
                                       "dop853", "-o", str(out), "--error-output",
                                       str(tmp_path / "errors.csv")])
    assert result.exit_code == 0, result.output
    assert "; estimated error " in result.stderr
    with out.open() as f:
        rows = list(csv.reader(f))
    assert rows[0][:5] == ["time", "mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["errors.csv", "run.csv"]
    with (tmp_path / "errors.csv").open() as f:
        side = list(csv.reader(f))
    assert side[0] == ["variable", "max_abs_error", "relative_error", "at_time", "method"]
    assert [row[0] for row in side[1:]] == list(model("seed").states)
    table = np.array([[float(v) for v in row[1:4]] for row in side[1:]])
    values = np.array([[float(v) for v in row] for row in rows[1:]])
    # relative = absolute / the state's largest magnitude in the trajectory written
    np.testing.assert_allclose(table[:, 1], table[:, 0] / np.abs(values[:, 1:5]).max(axis=0),
                               rtol=1e-12)
    assert all(row[4] == "companion dop853 run at rtol 1e-09" for row in side[1:])
    refused = CliRunner().invoke(main, ["simulate", SEED, "--error-estimate", "off",
                                        "--error-output", str(tmp_path / "off.csv")])
    assert refused.exit_code == 2 and refused.stderr.endswith(
        "Error: --error-output needs an error estimate, which --error-estimate off turns "
        "off\n")
    assert not (tmp_path / "off.csv").exists()
