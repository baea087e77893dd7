"""``springc tradeoff``: errors against closed forms, the reference check, the
recommendation text, the CSV table, the work-precision PNG, and the CLI."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.tradeoff.model import (
    CSV_COLUMNS,
    SCIPY_DEFAULT,
    SCIPY_RK45,
    Reference,
    Run,
    Tradeoff,
    TradeoffError,
    TradeoffOptions,
)
from springc.tradeoff.plot import write_work_precision
from springc.tradeoff.report import recommend, write_table_csv
from springc.tradeoff.setup import relative_errors, variable_scales
from springc.tradeoff.study import compare_states, fixed_step_solvers, run_tradeoff

OSCILLATOR = """
model Oscillator "x'' = -4 x: x = cos(2 t), v = -2 sin(2 t)"
  parameter Real k = 4;
  parameter Real m = 1;
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  m * der(v) = -k * x;
  annotation(experiment(StartTime = 0, StopTime = 2, Interval = 0.1));
end Oscillator;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def oscillator(tmp_path: Path) -> str:
    path = tmp_path / "Oscillator.mdl"
    path.write_text(OSCILLATOR)
    return str(path)


def closed_form(path: Path) -> None:
    """The exact solution on the output grid, as a reference CSV."""
    with path.open("w") as f:
        f.write("time,x,v\n")
        for ti in np.linspace(0.0, 2.0, 21).tolist():
            f.write(f"{ti!r},{math.cos(2 * ti)!r},{-2 * math.sin(2 * ti)!r}\n")


def run_cli(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


# ------------------------------------------------------------------ measuring

def test_errors_decrease_with_tolerance_against_the_closed_form(oscillator: str,
                                                                 tmp_path: Path) -> None:
    reference = tmp_path / "exact.csv"
    closed_form(reference)
    model = compare_states(springc.compile_model(oscillator))
    fixed = fixed_step_solvers()
    study = run_tradeoff(model, TradeoffOptions(
        ("rk45", "dop853", "radau", "bdf", "lsoda", *fixed), (1e-3, 1e-6, 1e-9),
        (0.05, 0.0125), reference=str(reference), repeats=1, cost_limit=math.inf))
    assert study.reference.description == f"{reference} (not verified)"
    for solver in ("rk45", "dop853", "radau", "bdf", "lsoda"):
        errors = [r.max_error for r in study.runs if r.solver == solver]
        assert len(errors) == 3 and errors[0] > errors[1] > errors[2], (solver, errors)
        assert errors[2] < 1e-6
    for solver in fixed:
        errors = [r.max_error for r in study.runs if r.solver == solver]
        assert errors[0] > errors[1], (solver, errors)
    loose = next(r for r in study.runs if r.solver == "dop853")
    assert loose.label() == "rtol 1e-03" and loose.steps > 0 and loose.rhs_evaluations > 0
    radau = next(r for r in study.runs if r.solver == "radau")
    assert radau.jacobian_evaluations > 0
    assert study.baselines[0].solver == SCIPY_DEFAULT and study.baselines[0].ok


def test_tight_reference_is_verified_by_a_second_method(oscillator: str) -> None:
    model = compare_states(springc.compile_model(oscillator))
    study = run_tradeoff(model, TradeoffOptions(("dop853",), (1e-6,), repeats=1))
    ref = study.reference
    assert re.fullmatch(r"dop853 \((compiled|scipy)\) at rtol 1e-12 \([0-9.e-]+ s\), "
                        r"verified by VODE Adams at rtol 1e-12 \([0-9.e-]+ s\): they agree to "
                        r"\d\.\de-\d\d "
                        r"\(max relative difference on the grid\)", ref.description)
    assert 0 <= ref.agreement < 1e-9
    t = ref.time
    exact = np.column_stack([np.cos(2 * t), -2 * np.sin(2 * t)])
    assert np.max(np.abs(ref.values - exact)) < 1e-9


def test_reference_refused_when_the_methods_disagree_beyond_the_target(oscillator: str
                                                                       ) -> None:
    model = compare_states(springc.compile_model(oscillator))
    with pytest.raises(TradeoffError, match=r"the reference is not accurate enough: dop853 "
                       r"and VODE Adams at rtol 1e-12 differ by .*, more than the target "
                       r"error 1e-20"):
        run_tradeoff(model, TradeoffOptions(("dop853",), (1e-6,), targets=(1e-20,)))


def test_scales_are_floored_per_unit_and_errors_are_relative() -> None:
    values = np.array([[2.0, 0.0, 1e-12, 50.0], [-4.0, 0.0, 0.0, 10.0]])
    scales = variable_scales(values, ("m", "m", "m", "N"))
    assert scales.tolist() == [4.0, 4e-6, 4e-6, 50.0]
    assert variable_scales(np.zeros((2, 1)), ("",)).tolist() == [1.0]
    shifted = values + np.array([[0.4, 0, 0, 0], [0, 0, 0, 0]])
    worst, rms = relative_errors(shifted, values, scales)
    assert worst == pytest.approx(0.1) and rms == pytest.approx(0.1 / math.sqrt(8))


# ------------------------------------------------------------------ recommendation

def _run(solver: str, value: float, seconds: float, error: float, setting: str = "rtol",
         status: str = "ok") -> Run:
    return Run(solver, setting, value, seconds, 3, 10, 100, 0, error, error / 3, status)


RUNS = (_run("rk45", 1e-3, 0.05, 3e-2), _run("rk45", 1e-6, 0.30, 8e-5),
        _run("dop853", 1e-3, 0.08, 5e-3), _run("dop853", 1e-6, 0.12, 6e-5),
        _run("radau", 1e-6, 0.90, 2e-5), _run("verlet", 0.001, 0.10, 9e-5, "step"))


def test_recommendation_text() -> None:
    default = _run(SCIPY_DEFAULT, 1e-3, 0.41, 2.1e-2)
    tightened = (_run(SCIPY_RK45, 1e-4, 0.2, 1e-3), _run(SCIPY_RK45, 1e-6, 0.36, 9e-5))
    assert recommend(RUNS, (default, *tightened), 1e-4) == (
        "for max error <= 1e-04 the fastest is verlet at step 0.001 (0.1 s); scipy's RK45 "
        "needs rtol 1e-06 for it (0.36 s: verlet is 3.6x faster); scipy's default RK45 "
        "(rtol 1e-3) reaches only 2.1e-02, 210x the target")
    assert recommend(RUNS, (default, *tightened), 5e-5) == (
        "for max error <= 5e-05 the fastest is radau at rtol 1e-06 (0.9 s); scipy's RK45 "
        "does not reach it down to rtol 1e-06; scipy's default RK45 (rtol 1e-3) reaches "
        "only 2.1e-02, 420x the target")
    reached = _run(SCIPY_DEFAULT, 1e-3, 0.41, 1e-5)
    assert recommend(RUNS, (reached,), 1e-4) == (
        "for max error <= 1e-04 the fastest is verlet at step 0.001 (0.1 s, 4.1x faster "
        "than scipy's default RK45 at rtol 1e-3, which reaches 1.0e-05)")
    assert recommend(RUNS, (default,), 1e-6) == (
        "for max error <= 1e-06 no setting is accurate enough (the most accurate is radau "
        "at rtol 1e-06: 2.0e-05)")


# ------------------------------------------------------------------ outputs

def _study() -> Tradeoff:
    t = np.linspace(0, 1, 3)
    ref = Reference(t, ("x",), np.ones((3, 1)), "synthetic", 1e-11)
    baselines = (_run(SCIPY_DEFAULT, 1e-3, 0.41, 2.1e-2),)
    failed = Run("bdf", "rtol", 1e-3, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                 "over budget (> 30 s)")
    return Tradeoff("Synthetic", 1, ref, np.ones(1), (*RUNS, failed), baselines, (1e-4,))


def test_table_csv_columns(tmp_path: Path) -> None:
    path = tmp_path / "table.csv"
    write_table_csv(_study(), path)
    rows = list(csv.reader(path.open()))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert len(rows) == 1 + len(RUNS) + 2
    assert rows[1] == ["rk45", "rtol", "0.001", "0.05", "3", "10", "100", "0", "3.000e-02",
                       "1.000e-02", "ok", "", ""]  # no energy variable: no drift
    assert rows[-2] == ["bdf", "rtol", "0.001", "", "1", "", "", "", "", "",
                        "over budget (> 30 s)", "", ""]
    assert rows[-1][0] == SCIPY_DEFAULT


def test_work_precision_png_is_not_blank(tmp_path: Path) -> None:
    from matplotlib.image import imread

    path = tmp_path / "wp.png"
    write_work_precision(_study(), path)
    image = imread(path)
    assert image.shape[0] > 300 and image.shape[1] > 600
    assert len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 20


# ------------------------------------------------------------------ CLI

def test_cli_table_csv_plot_and_recommendation(oscillator: str, tmp_path: Path) -> None:
    table, plot, ref = tmp_path / "t.csv", tmp_path / "wp.png", tmp_path / "ref.csv"
    code, out, err = run_cli("tradeoff", oscillator, "--solvers", "dop853,lsoda",
                             "--tolerances", "1e-3, 1e-6", "--repeats", "1", "-o", str(table),
                             "--plot", str(plot), "--save-reference", str(ref))
    assert code == 0, err
    assert out.startswith("Oscillator: 2 states, 21 output times, 2 variables compared\n"
                          "reference: dop853 (compiled) at rtol 1e-12")
    assert re.search(r"^for max error <= 1e-04 the fastest is (dop853|lsoda) at rtol 1e-06 ",
                     out, re.M)
    assert "dop853 rtol 1e-03: " in err
    assert len(list(csv.reader(table.open()))) == 1 + 4 + 2
    assert plot.stat().st_size > 10_000
    # The saved reference is accepted back (and not verified again).
    code, out, err = run_cli("tradeoff", oscillator, "--solvers", "dop853", "--tolerances",
                             "1e-6", "--repeats", "1", "--reference", str(ref), "-q")
    assert code == 0, err
    assert f"reference: {ref} (not verified)" in out and err == ""


def test_cli_usage_errors(oscillator: str) -> None:
    code, _, err = run_cli("tradeoff", oscillator, "--solvers", "dop853,euler2")
    assert code == 2 and "unknown solver 'euler2'" in err
    code, _, err = run_cli("tradeoff", oscillator, "--tolerances", "1e-3,abc")
    assert code == 2 and "'abc' is not a number" in err
    code, _, err = run_cli("tradeoff", oscillator, "--max-error", "-1")
    assert code == 2 and "-1 is not positive" in err


def test_cli_bad_reference_csv(oscillator: str, tmp_path: Path) -> None:
    missing = tmp_path / "missing.csv"
    missing.write_text("time,x\n0.0,1.0\n")
    code, out, err = run_cli("tradeoff", oscillator, "--reference", str(missing))
    assert code == 1 and out == ""
    assert f"error: {missing}: missing columns: v" in err
    assert "note: the columns are: x" in err
    shifted = tmp_path / "shifted.csv"
    closed_form(shifted)
    text = shifted.read_text().replace("\n0.1,", "\n0.11,")
    shifted.write_text(text)
    code, _, err = run_cli("tradeoff", oscillator, "--reference", str(shifted))
    assert code == 1 and "line 3 is at time 0.11, the grid at 0.1" in err
    short = tmp_path / "short.csv"
    short.write_text("time,x,v\n0.0,1.0,0.0\n")
    code, _, err = run_cli("tradeoff", oscillator, "--reference", str(short))
    assert code == 1 and "1 output times, the study's grid has 21" in err


def test_budget_stops_runs(oscillator: str) -> None:
    from springc.tradeoff.model import OverBudget
    from springc.tradeoff.setup import Deadline

    with pytest.raises(OverBudget):
        Deadline(0.0).write("progress")
    Deadline(60.0).write("progress")
    # The scipy baselines check the budget every 64 RHS evaluations.
    model = compare_states(springc.compile_model(oscillator))
    study = run_tradeoff(model, TradeoffOptions(("dop853",), (1e-6,), repeats=1,
                                                budget=1e-9))
    assert study.runs[0].ok
    # The default call needs fewer than 64 evaluations; RK45 at rtol 1e-6 does not.
    assert [b.status for b in study.baselines] == ["ok", "over budget (> 1e-09 s)"]
    assert "; scipy's RK45 does not reach it down to rtol 1e-06 (over budget (> 1e-09 s)); " \
        "scipy's default RK45 (rtol 1e-3) reaches only " in recommend(study.runs,
                                                             study.baselines, 1e-4)
