"""Start values set at run time (``--set NAME=VALUE``, ``parameters={...}``): a fixed
start is the initial value, a free one the guess of the initial problem; the model is
not compiled again."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import SimulationError, UsageError

G = 9.81
FALL = f"""model Fall "A body falling from rest"
  parameter Real g = {G};
  Real h(start = 1, fixed = true, unit = "m");
  Real v(start = 0, fixed = true, unit = "m/s");
  Real e(unit = "J/kg") "energy per mass";
equation
  der(h) = v;
  der(v) = -g;
  e = g*h + v^2/2;
end Fall;
"""

ROOT = """model Root "x*x = 4 has two roots: the start value of x chooses one"
  Real x(start = 0.5, fixed = false);
initial equation
  x*x = 4;
equation
  der(x) = 0;
end Root;
"""

DECAY = """model Decay "y, not a state, has a fixed start: h(0) = y(0)/2"
  Real h;
  Real y(start = 1, fixed = true);
equation
  der(h) = -h;
  y = 2*h;
end Decay;
"""


@pytest.fixture
def files(tmp_path: Path) -> dict[str, str]:
    out = {}
    for name, text in (("fall", FALL), ("root", ROOT), ("decay", DECAY)):
        path = tmp_path / f"{name}.mo"
        path.write_text(text)
        out[name] = str(path)
    return out


def test_a_state_start_is_its_initial_value(files: dict[str, str]) -> None:
    model = springc.compile_model(files["fall"])
    result = springc.simulate(model, parameters={"h": 2.0}, stop=1.0, rtol=1e-10)
    t = result.time
    # the closed form of the fall from h = 2 at rest; dop853 is exact to rounding here
    assert np.max(np.abs(result["h"] - (2.0 - G * t**2 / 2))) < 1e-9
    assert np.max(np.abs(result["v"] + G * t)) < 1e-9
    assert "h" not in result.parameters  # a start value, not a parameter
    default = springc.simulate(model, stop=1.0, rtol=1e-10)
    assert abs(default["h"][-1] - (1.0 - G / 2)) < 1e-9  # the model's own start again


def test_cli_set_sets_a_start(files: dict[str, str]) -> None:
    result = CliRunner().invoke(main, ["simulate", files["fall"], "--stop", "1", "--interval",
                                       "0.5", "--quiet", "--set", "h=2", "--set", "v=1"])
    assert result.exit_code == 0, result.output
    rows = [[float(v) for v in line.split(",")] for line in result.stdout.splitlines()[1:]]
    for t, h, v, _e in rows:
        assert abs(h - (2.0 + t - G * t**2 / 2)) < 1e-9
        assert abs(v - (1.0 - G * t)) < 1e-9


def test_a_free_start_is_the_guess_of_the_initial_problem(files: dict[str, str]) -> None:
    model = springc.compile_model(files["root"])
    assert abs(springc.simulate(model, stop=1.0)["x"][0] - 2.0) < 1e-9
    assert abs(springc.simulate(model, stop=1.0, parameters={"x": -1.0})["x"][0] + 2.0) < 1e-9


def test_a_fixed_start_of_a_variable_that_is_not_a_state(files: dict[str, str]) -> None:
    model = springc.compile_model(files["decay"])
    assert model.start_names == ("h", "y")
    result = springc.simulate(model, parameters={"y": 4.0}, stop=1.0, rtol=1e-10)
    assert np.max(np.abs(result["h"] - 2.0 * np.exp(-result.time))) < 1e-8


def test_a_start_value_in_a_sweep(files: dict[str, str]) -> None:
    table = springc.sweep(files["fall"], params={"g": [1.0, 4.0]}, parameters={"h": 3.0},
                          stop=1.0, interval=0.5, rtol=1e-10, workers=1, as_="dataframe")
    final = table[table["time"] == 1.0].sort_values("g")
    assert np.allclose(final["h"], [3.0 - 1.0 / 2, 3.0 - 4.0 / 2], rtol=0, atol=1e-9)
    with pytest.raises(UsageError) as info:
        springc.sweep(files["fall"], params={"h": [1.0, 3.0]}, workers=1)
    assert info.value.message == ("--param h: 'h' is a start value, not a parameter; a "
                                  "study sweeps parameters")


def test_unknown_names_get_a_suggestion(files: dict[str, str]) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(files["fall"], parameters={"hh": 2.0})
    assert info.value.message == "'hh' is not a parameter or a state of Fall"
    assert info.value.hint == "did you mean 'h'?"


def test_an_observed_variable_has_no_start_to_set(files: dict[str, str]) -> None:
    with pytest.raises(SimulationError) as info:
        springc.simulate(files["fall"], parameters={"e": 2.0})
    assert info.value.message == (
        "'e' is not a parameter or a state of Fall: it is computed from the states, so "
        "its start value is not an initial value")
    assert info.value.hint == "set a parameter or the start of a state (h, v)"
