"""Degenerate runs: a state exactly at equilibrium, a zero-length time span, extreme
``--set`` values. Each returns an exact result or stops with a clear error (CLI:
exit 1, a diagnostic, no traceback, no CSV)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline.compiler import CompiledModel


@pytest.mark.parametrize("solver", ["auto", "dop853", "radau", "bdf", "verlet", "rk4"])
def test_exactly_at_equilibrium(compiled: dict[str, CompiledModel], solver: str) -> None:
    result = springc.simulate(compiled["Harmonic"], parameters={"a": 0.0}, solver=solver,
                              step=0.01)
    assert not result.values.any()  # exactly zero, every output time


def test_stiff_equilibrium_costs_nothing(compiled: dict[str, CompiledModel]) -> None:
    # rho*T = 1e7 says stiff, but nothing moves: dop853 finishes in a few steps.
    result = springc.simulate(compiled["Harmonic"], parameters={"a": 0.0, "k": 1e12})
    assert result.stats.solver == "dop853" and not result.values.any()
    assert result.stats.steps < 20
    assert result.stats.reason == f"non-stiff: dop853 finished in {result.stats.steps} steps"


@pytest.mark.parametrize("solver", ["auto", "verlet"])
def test_zero_length_span(compiled: dict[str, CompiledModel], solver: str) -> None:
    with pytest.raises(UsageError, match=r"^error: stop \(1\) must be after start \(1\)$"):
        springc.simulate(compiled["Harmonic"], start=1.0, stop=1.0, solver=solver, step=0.1)


SET_CASES = [
    # (--set, exit code, text in the output)
    ("m=0", 1, "error: division by zero while computing der(v) ("),
    ("m=nan", 2, "error: --set: the value of 'm' must be a finite number, not nan"),
    ("k=inf", 2, "error: --set: the value of 'k' must be a finite number, not inf"),
    ("a=1e308", 1, "error: der(x) is NaN at time "),
    ("a=inf", 2, "error: --set: the value of 'a' must be a finite number, not inf"),
    ("k=-1", 0, ""),  # an unstable spring: exponential growth, finite over 10 s
    ("k=1e300", 1, "note: radau, tried next by auto, failed too: the radau solver failed "
                   "at time 0: the Newton matrix is not finite (the Jacobian overflows)"),
    # (dop853's 10 compiled probe steps do not collapse yet: the Jacobian, not finite,
    # sends auto to radau, whose error is the run's)
    ("m=1e-300", 1, "the radau solver failed at time 0: the Newton matrix"),
    ("m=1e300", 0, ""),  # a motionless mass
    ("k=abc", 2, "'abc' is not a number"),
]


@pytest.mark.parametrize(("assignment", "code", "text"), SET_CASES)
def test_extreme_set_values(models_file: str, tmp_path: Path, assignment: str, code: int,
                            text: str) -> None:
    out = tmp_path / "out.csv"
    result = CliRunner().invoke(main, ["simulate", models_file, "--model", "Harmonic",
                                       "--set", assignment, "-o", str(out), "-q"])
    assert result.exit_code == code, result.output
    assert text in result.output
    assert "Traceback" not in result.output and "internal error" not in result.output
    assert out.exists() == (code == 0)
    if code == 0:
        values = np.loadtxt(out, delimiter=",", skiprows=1)
        assert np.isfinite(values).all()
