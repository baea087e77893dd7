"""The run plan: RunSettings built once (the API's keywords and the command line's
shared option group give the same value), plan() resolving grid, tolerances,
parameters, start state, limits and driver from the closed compiled model, the driver
chosen by the KIND the generated module declares, and the budget as a limit."""

from __future__ import annotations

import math

import numpy as np
import pytest

import springc
from springc.cli.options import cli_settings
from springc.errors import UsageError
from springc.simulation import OverBudget, RunSettings, plan, run_settings
from springc.simulation.steps import Progress
from springc.studies import StudyOptions, parse_parameter

DECAY = """
model Decay
  parameter Real a = 2;
  Real x(start = 3, fixed = true);
equation
  der(x) = -a * x;
end Decay;
"""

BALL = """
model Ball
  Real h(start = 1, fixed = true);
  Real v(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -9.81;
  when h < 0 then
    reinit(v, -0.8 * pre(v));
  end when;
end Ball;
"""


def test_the_api_and_the_command_line_build_the_same_settings() -> None:
    given = {"start": None, "stop": 2.0, "interval": 0.5, "parameters": ("a=4", "x=1"),
             "solver": "RK4", "step": 0.1, "rtol": None, "atol": None, "max_steps": 50,
             "time_limit": None, "error_control": "Warn", "engine": "Scipy"}
    assert cli_settings(given) == run_settings(
        stop=2.0, interval=0.5, parameters={"a": 4.0, "x": 1.0}, solver="rk4", step=0.1,
        max_steps=50, error_control="warn", engine="scipy") == RunSettings(
        stop=2.0, interval=0.5, parameters={"a": 4.0, "x": 1.0}, solver="rk4", step=0.1,
        max_steps=50, error_control="warn", engine="scipy")


def test_the_checks_name_the_option_as_the_caller_spells_it() -> None:
    with pytest.raises(UsageError) as api:
        run_settings(rtol=2.0)
    with pytest.raises(UsageError) as cli:
        cli_settings({"rtol": 2.0})
    assert api.value.message == "rtol must be a finite number in (0, 1), not 2.0"
    assert cli.value.message == "--rtol must be a finite number in (0, 1), not 2.0"


def test_plan_resolves_the_run_once() -> None:
    model = springc.load_model_from_string(DECAY, backend="python")
    assert model.kind == "continuous" and model.module.KIND == "continuous"
    planned = plan(model, RunSettings(stop=1.0, interval=0.25, parameters={"a": 4.0,
                                                                            "x": 5.0}))
    assert planned.grid.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert (planned.rtol, planned.atol) == (1e-6, 1e-6 / 1000)
    assert planned.p.tolist() == [4.0] and planned.x0 is not None
    assert planned.x0.tolist() == [5.0]
    assert (planned.parameters, planned.starts) == ({"a": 4.0}, {"x": 5.0})
    assert (planned.limits.max_steps, planned.limits.time_limit) == (20_000_000, 3600.0)
    assert planned.driver == "continuous" and planned.solver == "auto"
    result = springc.simulate(model, stop=1.0, interval=0.25, parameters={"a": 4.0})
    assert np.allclose(result["x"], 3 * np.exp(-4 * result.time), rtol=1e-5)


def test_a_hybrid_module_declares_its_driver() -> None:
    model = springc.load_model_from_string(BALL, backend="python")
    assert model.module.KIND == "hybrid"
    assert plan(model, RunSettings(stop=0.5)).driver == "hybrid"


def test_the_budget_stops_a_run_at_a_progress_update() -> None:
    progress = Progress(None, 0.0, 1.0, budget=0.0)
    assert progress.next < math.inf  # watched from the first second on
    progress.next = 0.0  # that second is over
    with pytest.raises(OverBudget):
        progress.update(0.5)
    quiet = Progress(None, 0.0, 1.0)
    assert quiet.next == math.inf  # no stream, no budget: never updated


def test_a_study_keeps_the_limits_it_was_not_given() -> None:
    settings = run_settings(stop=1.0, solver="dop853")
    options = StudyOptions((parse_parameter("a=1,2"),)).running(settings)
    assert (options.stop, options.solver, options.max_steps, options.time_limit) == \
        (1.0, "dop853", None, None)
    assert options.run == settings
