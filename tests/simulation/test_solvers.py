"""springc.simulation.solvers: position/velocity pairs, the auto choice, fixed-step runs and their
failures (API and CLI)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import SimulationError, UsageError
from springc.pipeline.files import flatten_files
from springc.simplify.passes import simplify
from springc.simulation import race
from springc.simulation.solvers import choose, detect_pairs, pairs_from_ode

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")

MODELS = """
model Harmonic
  parameter Real k = 4;
  parameter Real m = 1;
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  m * der(v) = -k * x;
end Harmonic;

model StiffPair "wall -k0- m1 -k- m2 -k2- wall: with k2 = k0 the stiff mode stays at rest"
  parameter Real k0 = 1;
  parameter Real k2 = 1;
  parameter Real k = 1e8;
  Real x1(start = 1);
  Real x2(start = 1);
  Real v1(start = 0);
  Real v2(start = 0);
equation
  der(x1) = v1;
  der(x2) = v2;
  der(v1) = -k0 * x1 + k * (x2 - x1);
  der(v2) = -k2 * x2 - k * (x2 - x1);
end StiffPair;

model Chained "der(a) = b, der(b) = c: b is not a velocity of a mechanical pair"
  Real a(start = 1);
  Real b(start = 0);
  Real c(start = 0);
equation
  der(a) = b;
  der(b) = c;
  der(c) = -a;
end Chained;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def models(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = tmp_path_factory.mktemp("models") / "solvers.mdl"
    path.write_text(MODELS)
    return str(path)


def _pairs_by_name(files: str, name: str) -> tuple[set[tuple[str, str]], set[tuple[str, str]]]:
    compiled = springc.compile_model(files, name)
    p = compiled.parameters()
    x0 = np.asarray(compiled.module.start(p), dtype=float)
    pairs = detect_pairs(compiled.module, p, x0, 0.0)
    states = compiled.states
    runtime = {(states[q], states[v]) for q, v in zip(pairs.positions, pairs.velocities)}
    symbolic = set(pairs_from_ode(simplify(flatten_files([files], name)).ode))
    return runtime, symbolic


@pytest.mark.parametrize(("files", "name", "count"), [
    (SEED, "SpringMass", 2), (SCENES, "Scenes.Oscillator", 2), (SCENES, "Scenes.Chain", 10),
    (SCENES, "Scenes.Cloth", 200), (SCENES, "Scenes.Pendulum", 1)])
def test_pairs_from_the_jacobian_match_the_ode(files: str, name: str, count: int) -> None:
    runtime, symbolic = _pairs_by_name(files, name)
    assert runtime == symbolic
    assert len(runtime) == count


def test_chains_of_derivatives_are_not_pairs(models: str) -> None:
    runtime, symbolic = _pairs_by_name(models, "Chained")
    assert runtime == symbolic == set()


def test_auto_choice_on_linear_systems() -> None:
    w = 1e3
    osc = np.array([[0.0, 1.0], [-w * w, 0.0]])
    slow = choose(osc / 1e3, 10.0)
    assert slow.solver == "dop853"
    assert slow.reason == "non-stiff: spectral radius 1 1/s over 10 s (rho*T = 10 <= 2000)"
    fast = choose(osc, 10.0)
    assert fast.solver == "race" and fast.spectral_radius == pytest.approx(w)
    assert fast.reason == ("stiff: fastest time scale 1/1e+03 s is 1e+04x shorter than "
                           "the 10 s span")
    assert choose(np.array([[0.0, 1.0], [-np.inf, 0.0]]), 10.0).solver == "radau"
    assert choose(osc, 0.0).reason == "no dynamics to integrate"


def test_auto_keeps_the_explicit_method_while_the_fast_mode_rests(models: str) -> None:
    result = springc.simulate(models, model_name="StiffPair", stop=1.0)
    assert result.stats.solver == "dop853"
    assert re.fullmatch(
        r"StiffPair: auto -> dop853 \(compiled\) \(non-stiff: dop853 finished in (\d+) "
        r"steps; dop853 ran in the compiled loop \(numba, no Python per step\)\), \1 "
        r"steps, .*", result.stats.summary("StiffPair"))
    assert result.stats.steps <= race.EXPLICIT_PROBE
    assert np.max(np.abs(result["x1"] - np.cos(result.time))) < 1e-5
    chosen = springc.simulate(models, model_name="StiffPair", stop=1.0, solver="bdf")
    assert chosen.stats.summary("StiffPair").startswith("StiffPair: bdf (compiled), ")


def test_auto_races_to_the_implicit_method_when_the_explicit_one_is_held(
        models: str) -> None:
    # Uneven walls: rounding and the static offset (~1/k) keep the stiff mode below
    # the tolerance, but dop853 is held at its stability limit 1/rho.
    result = springc.simulate(models, model_name="StiffPair",
                              parameters={"k": 1e12, "k2": 2.0})
    assert result.stats.solver == "radau"
    # (counted after radau's 20 probe steps: far below a quarter of dop853's work to go)
    assert result.stats.reason == (
        "stiff: fastest time scale 1/1.41e+06 s is 1.41e+07x shorter than the 10 s span; "
        "counted: radau ~1.4e+02 steps x 16.5 = ~2.3e+03 RHS evaluations to go, dop853 "
        "~5.8e+06 steps x 26.4 = ~1.5e+08")
    assert result.stats.steps == 129  # dop853's 10 probe steps, then radau's run
    slow = np.sqrt(2 + 3e12) / np.sqrt(1e12) / np.sqrt(2)  # the slow mode, 1 + O(1/k)
    assert np.max(np.abs(result["x1"] - np.cos(slow * result.time))) < 2e-5


def test_auto_falls_back_to_the_implicit_method_when_the_explicit_probe_fails(
        models: str, monkeypatch: pytest.MonkeyPatch) -> None:
    from springc.simulation import steps

    real = steps.StepLoop.advance

    def failing(run: object, integrator: object, max_steps: int | None = None) -> object:
        # scipy's integrator, or the compiled engine's handle
        if "dop853" in (type(integrator).__name__.lower(), getattr(integrator, "method", "")):
            raise steps.Stop(SimulationError("overflow in a trial stage"))
        return real(run, integrator, max_steps)  # type: ignore[arg-type]

    monkeypatch.setattr(steps.StepLoop, "advance", failing)
    result = springc.simulate(models, model_name="StiffPair", stop=1.0)
    assert result.stats.solver == "radau"
    assert result.stats.reason == "dop853 failed in its first steps (overflow in a trial stage)"
    assert np.max(np.abs(result["x1"] - np.cos(result.time))) < 1e-5


@pytest.mark.parametrize("solver", ["verlet", "symplectic-euler", "rk4"])
def test_fixed_step_solvers_against_the_closed_form(models: str, solver: str) -> None:
    result = springc.simulate(models, model_name="Harmonic", stop=5.0, solver=solver,
                              step=1e-3)
    error = np.max(np.abs(result["x"] - np.cos(2.0 * result.time)))
    bound = {"verlet": 2e-6, "symplectic-euler": 3e-3, "rk4": 3e-12}[solver]
    assert error < bound
    assert result.stats.steps == 5000 and result.stats.solver == solver


def test_fixed_step_needs_a_step(models: str) -> None:
    with pytest.raises(SimulationError, match="the fixed-step solver verlet needs a step"):
        springc.simulate(models, model_name="Harmonic", solver="verlet")
    with pytest.raises(SimulationError, match="more than 2e\\+07"):
        springc.simulate(models, model_name="Harmonic", solver="verlet", step=1e-9)
    with pytest.raises(UsageError, match="step must be a finite number, not inf"):
        springc.simulate(models, model_name="Harmonic", solver="rk4", step=float("inf"))


def test_cli_fixed_step_usage_errors(models: str) -> None:
    runner = CliRunner()
    result = runner.invoke(main, ["simulate", models, "--model", "Harmonic", "--solver",
                                  "verlet"])
    assert result.exit_code == 2
    assert "--solver verlet is a fixed-step solver and needs --step H" in result.output
    result = runner.invoke(main, ["simulate", models, "--model", "Harmonic", "--solver",
                                  "rk4", "--step", "-1"])
    assert result.exit_code == 2
    assert "error: --step must be a finite number > 0, not -1.0" in result.output


def test_unstable_step_fails_with_the_remedy_and_no_csv(models: str, tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    result = CliRunner().invoke(main, [
        "simulate", models, "--model", "Harmonic", "--solver", "verlet", "--step", "1.5",
        "--interval", "1.5", "--stop", "3000", "--set", "k=4", "-o", str(out)])
    assert result.exit_code == 1, result.output
    assert "error: der(v) is infinite at time " in result.output
    assert "note: v = " in result.output
    assert "help: reduce --step or use --solver radau" in result.output
    assert list(tmp_path.iterdir()) == []


def test_auto_without_states(tmp_path: Path) -> None:
    path = tmp_path / "NoStates.mdl"
    path.write_text("model NoStates\n  parameter Real a = 2;\n  Real y;\nequation\n"
                    "  y = a * time;\nend NoStates;\n")
    result = springc.simulate(str(path))
    assert result.stats.reason == "no states to integrate" and result.stats.steps == 0
    assert np.array_equal(result["y"], 2 * result.time)
