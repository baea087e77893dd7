"""Hostile input to ``simulate`` (issue 10): unbalanced models, extreme parameters,
non-finite observed values, a step that does not fit the output grid. Each case ends
with a clear, located error (CLI exit 1, no traceback, no output file) or a stated
behaviour, never a hang, an internal error or a silent wrong answer."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import BalanceError, SimulationError, render

ROOT = Path(__file__).resolve().parents[2]
SEED_TEXT = (ROOT / "models" / "SpringMass.mdl").read_text()
SCENES = str(ROOT / "models" / "Scenes.mdl")


def simulate_cli(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["simulate", *args, "-q"])
    assert "Traceback" not in result.output and "internal error" not in result.output
    return result.exit_code, result.output


# ------------------------------------------------------------------ balance


def test_simulate_reports_a_missing_equation_as_check_does(tmp_path: Path) -> None:
    path = tmp_path / "missing.mdl"
    path.write_text(SEED_TEXT.replace("  spring.x = sqrt(spring.dir * spring.dir);\n", ""))
    with pytest.raises(BalanceError) as info:
        springc.simulate([path], cache=False)
    text = render(info.value)
    assert text.startswith(f"{path}:18:1: error: model 'SpringMass' is under-determined: "
                           "7 unknowns, 6 equations\n")
    assert f"{path}:14:8: note: 'spring.x' (in spring) is left undetermined" in text
    out = tmp_path / "out.csv"
    code, output = simulate_cli(str(path), "-o", str(out), "--no-cache")
    assert code == 1 and not out.exists()
    check = CliRunner().invoke(main, ["check", str(path)])
    assert output == check.output  # the same diagnostic as `springc check`


def test_simulate_names_a_surplus_equation(tmp_path: Path) -> None:
    path = tmp_path / "extra.mdl"
    path.write_text(SEED_TEXT.replace("  der(pos) = v;\n", "  der(pos) = v;\n  v[1] = 0;\n"))
    code, output = simulate_cli(str(path), "--no-cache")
    assert code == 1
    assert output.startswith(f"{path}:19:1: error: model 'SpringMass' is over-determined: "
                             "7 unknowns, 8 equations\n")
    assert (f"{path}:9:3: note: equation in mass `mass.v[1] = 0` is one of 8 equations "
            "for only 7 unknowns") in output


# ------------------------------------------------------------------ run limits

SEED = str(ROOT / "models" / "SpringMass.mdl")
HARMONIC = """
model Harmonic
  parameter Real k = 4;
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  der(v) = -k * x;
end Harmonic;
"""


def test_a_hopeless_stiffness_stops_with_the_time_the_stiffness_and_a_solver() -> None:
    # k = 1e29: a period of 2e-14 s over 10 s. The projection stops the run within the
    # first thousand steps instead of spending the whole step budget.
    with pytest.raises(SimulationError) as info:
        springc.simulate(SEED, parameters={"spring.k": 1e29}, max_steps=2_000_000)
    err = info.value
    assert err.message.startswith("the simulation stopped at time ")
    assert "far over the step limit (--max-steps 2000000)" in err.message
    notes = [n.message for n in err.notes]
    assert notes[0].startswith("reached time ") and " of 10 (" in notes[0]
    # the spring's fast mode: rho = sqrt(k/m) = sqrt(1e29) = 3.16e14 1/s
    assert "spectral radius of the Jacobian rho = 3.16e+14 1/s" in notes[1]
    assert err.hint is not None and "radau" in err.hint


def test_the_step_limit_and_the_time_limit_end_a_run_with_their_option(
        tmp_path: Path) -> None:
    path = tmp_path / "h.mdl"
    path.write_text(HARMONIC)
    with pytest.raises(SimulationError) as info:
        springc.simulate(path, solver="rk45", stop=1000.0, max_steps=500, cache=False)
    assert "500 steps of rk45 reached the step limit (--max-steps 500)" in info.value.message
    # rho = sqrt(k) = 2 for this oscillator; not stiff, so the advice is the limits
    assert "rho = 2 1/s" in info.value.notes[1].message
    assert info.value.hint is not None and info.value.hint.startswith(
        "the run is long rather than stiff: raise --max-steps / --time-limit")
    with pytest.raises(SimulationError, match=r"s of wall clock reached the time limit "
                       r"\(--time-limit\)"):
        springc.simulate(path, stop=1000.0, time_limit=1e-9, cache=False)
    code, output = simulate_cli(str(path), "--max-steps", "0", "--no-cache")
    assert code == 2 and "--max-steps" in output


# ------------------------------------------------------------------ pendulum


def test_pendulum_with_a_zero_rod_length(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    code, output = simulate_cli(SCENES, "--model", "Scenes.Pendulum", "--set", "L=0",
                                "-o", str(out))
    assert code == 1 and not out.exists()
    assert output.startswith(f"{SCENES}:163:10: error: the start value of 'lambda' cannot "
                             "be computed: division by zero\n")


def test_a_parameter_binding_that_overflows_is_named(tmp_path: Path) -> None:
    # --set values are checked by the CLI (finite numbers); a binding computed from
    # finite ones can still overflow: the run refuses it before starting. (With the
    # default k = 1e200 flattening already reports 'c' at its declaration.)
    path = tmp_path / "big.mdl"
    path.write_text("model Big\n  parameter Real k = 1;\n  parameter Real c = k * k;\n"
                    "  Real x(start = 1);\nequation\n  der(x) = -c * x;\nend Big;\n")
    code, output = simulate_cli(str(path), "--no-cache", "--set", "k=1e200")
    assert code == 1
    assert output.startswith("error: parameter 'c' = infinite: parameters must be finite "
                             "numbers\n")


# ------------------------------------------------------------------ observed values

OBSERVED = """
model Obs
  Real x(start = 0);
  Real big;
  Real root;
equation
  der(x) = 1;
  big = 1e308 * x;
  root = sqrt(OFFSET - x);
end Obs;
"""


def test_an_infinite_observed_value_fails_where_it_happens(tmp_path: Path) -> None:
    path = tmp_path / "obs.mdl"
    path.write_text(OBSERVED.replace("OFFSET", "10"))
    out = tmp_path / "out.csv"
    code, output = simulate_cli(str(path), "--stop", "3", "--interval", "0.1", "-o",
                                str(out), "--no-cache")
    assert code == 1 and not out.exists()
    # 1e308 * x overflows once x > 1.797...: the first output time after is 1.8
    assert output.startswith("error: big is infinite at time 1.8\n")


def test_an_observed_domain_error_is_reported_at_its_first_time(tmp_path: Path) -> None:
    path = tmp_path / "obs.mdl"
    path.write_text(OBSERVED.replace("OFFSET", "1.05"))
    code, output = simulate_cli(str(path), "--stop", "3", "--interval", "0.1",
                                "--vars", "root", "--no-cache")
    assert code == 1
    assert output.startswith(f"error: math domain error while computing root ({path}:9) "
                             "at time 1.1\n")


# ------------------------------------------------------------------ fixed step


def test_a_step_longer_than_the_output_interval_is_refused(tmp_path: Path) -> None:
    code, output = simulate_cli(SEED, "--solver", "verlet", "--step", "0.05", "-o",
                                str(tmp_path / "out.csv"))
    assert code == 1
    assert output.startswith("error: --step 0.05 is longer than the output interval 0.02: "
                             "the fixed-step solvers step to every output time\n")
    assert "--interval 0.05" in output


def test_a_step_that_does_not_divide_the_interval_is_shortened_and_says_so() -> None:
    result = springc.simulate(SEED, solver="verlet", step=0.015, stop=1.0, interval=0.02)
    assert result.stats.steps == 100  # 50 intervals of 0.02 s, two steps of 0.01 s each
    assert result.stats.note == ("--step 0.015 does not divide the output interval 0.02; "
                                 "verlet took steps of 0.01 s to land on every output time")
    assert result.stats.summary("M").endswith("; note: " + result.stats.note)
    exact = springc.simulate(SEED, solver="verlet", step=0.01, stop=1.0, interval=0.02)
    assert exact.stats.note == "" and exact.stats.steps == 100


def test_a_zero_rod_length_is_located_not_an_internal_error(tmp_path: Path) -> None:
    # RigidPair runs on the switching driver (reference evaluator): a division by zero
    # in a step of the simplified system names the variable and its equation.
    code, output = simulate_cli(SCENES, "--model", "Scenes.RigidPair", "--set", "rod.l=0",
                                "-o", str(tmp_path / "out.csv"))
    assert code == 1
    planar = ROOT / "models" / "Planar.mdl"
    assert output.startswith(f"{planar}:44:5: error: division by zero while computing "
                             "p2.pos[1] at t = 0\n")
