"""The rules that keep a study short: the cost limit (a solver's tighter settings
skipped once it costs far more than the pilot's fastest run meeting the targets, each
skipped row and a note saying why), contenders timed again and other runs once, the
compiled rk45 probe that starts scipy's RK45 sweep near the rtol it needs, and the
compiled loop for every solver that has one."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import solve_ivp

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline import CompiledModel
from springc.simulation import COMPILED_SOLVERS
from springc.tradeoff import baselines
from springc.tradeoff.baselines import baseline_runs, probe_errors
from springc.tradeoff.chains import Chain, Pilot, cost_ceiling, solver_runs
from springc.tradeoff.model import SCIPY_DEFAULT, SCIPY_RK45, Run, Tradeoff, TradeoffOptions
from springc.tradeoff.reference import read_reference
from springc.tradeoff.report import (
    format_table,
    recommend,
    skipped_notes,
    summary,
    table_rows,
)
from springc.tradeoff.runs import MAX_REPEATS, retimed
from springc.tradeoff.setup import study_setup, variable_scales
from springc.tradeoff.study import available_solvers, compare_states, run_tradeoff

OSCILLATOR = """
model Oscillator "x'' = -4 x: x = cos(2 t), v = -2 sin(2 t)"
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  der(v) = -4 * x;
  annotation(experiment(StartTime = 0, StopTime = 2, Interval = 0.1));
end Oscillator;
"""
TIMES = np.linspace(0.0, 2.0, 21)
EXACT = np.column_stack([np.cos(2 * TIMES), -2 * np.sin(2 * TIMES)])
SCALES = np.max(np.abs(EXACT), axis=0)  # max |x|, max |v| on the grid


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def exact_csv(tmp_path: Path) -> str:
    path = tmp_path / "exact.csv"
    with path.open("w") as f:
        f.write("time,x,v\n")
        for t, (x, v) in zip(TIMES.tolist(), EXACT.tolist()):
            f.write(f"{t!r},{x!r},{v!r}\n")
    return str(path)


def oscillator(tmp_path: Path, backend: str = "python") -> CompiledModel:
    path = tmp_path / "Oscillator.mdl"
    path.write_text(OSCILLATOR)
    return compare_states(springc.compile_model(str(path), backend=backend))


def pilot_run(seconds: float, error: float) -> Run:
    return Run("dop853", "rtol", 1e-6, seconds, 3, 100, 1000, 0, error, error / 3)


def study_parts(model: CompiledModel, reference: str, **options: object):  # type: ignore[no-untyped-def]
    setup = study_setup(model, TradeoffOptions(reference=reference, **options))  # type: ignore[arg-type]
    ref = read_reference(reference, setup.grid, model.outputs)
    return setup, ref, variable_scales(ref.values, setup.units)


def errors_of(values: np.ndarray) -> float:
    return float(np.max(np.abs(values - EXACT) / SCALES))


# ------------------------------------------------------------------ cost limit

def test_the_cost_limit_skips_the_tighter_settings_and_says_why(tmp_path: Path,
                                                                exact_csv: str) -> None:
    model = oscillator(tmp_path)
    setup, ref, scales = study_parts(model, exact_csv, repeats=1)
    chain = Chain("lsoda", (1e-3, 1e-6, 1e-9))
    # A pilot meeting 1e-4 in a microsecond: any real run of lsoda costs more than
    # 10x that, so its tighter settings cannot win and are skipped.
    pilot = Pilot("dop853", (pilot_run(1e-6, 5e-5),))
    assert cost_ceiling(pilot, (1e-4,), 10.0) == (
        pytest.approx(1e-5), "10x the fastest dop853 run meeting 1e-04 (rtol 1e-06, 1e-06 s)")
    runs = solver_runs(setup, ref, scales, None, chain, pilot)
    first = runs[0]
    assert first.ok and first.label() == "rtol 1e-03" and first.engine == "scipy"
    assert first.max_error == pytest.approx(
        errors_of(springc.simulate(model, solver="lsoda", rtol=1e-3, atol=1e-6).values),
        rel=1e-12)
    skip = f"skipped: cost limit (rtol 1e-03 took {first.wall_time:.3g} s > 10 x 1e-06 s)"
    assert [(r.label(), r.status, r.repeats) for r in runs[1:]] == [
        ("rtol 1e-06", skip, 0), ("rtol 1e-09", skip, 0)]
    study = Tradeoff("Oscillator", 2, ref, scales, tuple(runs), (), (1e-4,),
                     cost_limit=cost_ceiling(pilot, (1e-4,), 10.0)[1], pilot="dop853")
    assert [n.message for n in skipped_notes(study)] == [
        "2 settings were not run (lsoda rtol 1e-06 to 1e-09): a looser setting of the same "
        "solver took over 10x the fastest dop853 run meeting 1e-04 (rtol 1e-06, 1e-06 s), "
        "and tighter settings cost more (--cost-limit)"]
    assert "\nnote: 2 settings were not run (lsoda rtol 1e-06 to 1e-09): " in summary(study)
    # the printed table leaves them out (the note names them), the CSV keeps their rows
    assert [line.split()[:3] for line in format_table(study).splitlines()[1:]] == [
        ["lsoda", "rtol", "1e-03"]]
    assert [(row[0], row[1], row[10]) for row in table_rows(study)] == [
        ("lsoda", "rtol", "ok"), ("lsoda", "rtol", skip), ("lsoda", "rtol", skip)]
    # A pilot that meets no target sets no limit: a slower solver may be the only one
    # to meet it. Errors then fall with the tolerance against the closed form.
    missing = solver_runs(setup, ref, scales, None, chain,
                          Pilot("dop853", (pilot_run(1e-6, 2e-4),)))
    errors = [r.max_error for r in missing]
    assert all(r.ok for r in missing) and errors[0] > errors[1] > errors[2]
    assert cost_ceiling(Pilot("dop853", (pilot_run(1e-6, 2e-4),)), (1e-4,), 10.0) == (
        math.inf, "")
    assert cost_ceiling(pilot, (1e-4,), math.inf) == (math.inf, "")


def test_contenders_are_timed_again_and_other_runs_once(tmp_path: Path,
                                                        exact_csv: str) -> None:
    model = oscillator(tmp_path)
    setup, ref, scales = study_parts(model, exact_csv, repeats=3, targets=(1e-4,),
                                     cost_limit=math.inf)
    chain = Chain("rk45", (1e-3, 1e-6))
    # Alone, rk45 at rtol 1e-6 is the fastest meeting 1e-4 (rtol 1e-3 misses it).
    alone = solver_runs(setup, ref, scales, None, chain)
    assert alone[0].max_error > 1e-4 >= alone[1].max_error
    assert alone[0].repeats == 1 and 3 <= alone[1].repeats <= MAX_REPEATS
    # Against a pilot a million times faster it cannot be recommended: timed once.
    beaten = solver_runs(setup, ref, scales, None, chain,
                         Pilot("dop853", (pilot_run(1e-9, 5e-5),)))
    assert [r.repeats for r in beaten] == [1, 1]


def test_contenders_are_timed_in_rounds_short_ones_more() -> None:
    calls: list[str] = []

    def once(name: str, times: list[float]):  # type: ignore[no-untyped-def]
        def run(budget: float):  # type: ignore[no-untyped-def]
            calls.append(name)
            return times.pop(0), (1, 1, 0), np.zeros((1, 1)), "compiled"
        return run

    def timed_once(seconds: float) -> Run:
        return dataclasses.replace(pilot_run(seconds, 1e-5), repeats=1)

    short = timed_once(0.05)  # 0.2 s of timings: 4 in all
    medium = timed_once(0.5)  # the 3 of --repeats
    long = timed_once(3.0)  # over 2 s: timed once
    failed = dataclasses.replace(short, status="failed: x", wall_time=math.nan)
    done = retimed([(short, once("short", [0.05, 0.03, 0.01])),
                    (medium, once("medium", [0.7, 0.9])), (long, once("long", [])),
                    (failed, once("failed", []))], repeats=3)
    assert calls == ["short", "medium", "short", "medium", "short"]
    assert [(r.wall_time, r.repeats) for r in done[:3]] == [
        (0.01, 4), (0.5, 3), (3.0, 1)]
    assert done[3] is failed
    assert retimed([(short, once("short", []))], repeats=1) == [short]


def test_the_cost_limit_option_is_checked() -> None:
    with pytest.raises(UsageError, match=r"cost_limit must be a factor of at least 1 "
                       r"\(inf: no limit\), not 0.5"):
        TradeoffOptions(cost_limit=0.5)
    out = CliRunner().invoke(main, ["tradeoff", "x.mdl", "--cost-limit", "0.5"])
    assert out.exit_code == 2 and "--cost-limit" in out.stderr


# ------------------------------------------------------------------ scipy baselines

def test_the_rk45_probe_starts_scipys_sweep_where_it_needs_to(
        tmp_path: Path, exact_csv: str, monkeypatch: pytest.MonkeyPatch) -> None:
    model = oscillator(tmp_path, "numba")
    tolerances = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
    setup, ref, scales = study_parts(model, exact_csv, repeats=1, targets=(1e-7,),
                                     tolerances=tolerances)
    rows = baseline_runs(setup, ref, scales, None)
    assert rows[0].solver == SCIPY_DEFAULT and rows[0].ok

    def scipy_error(rtol: float) -> float:
        sol = solve_ivp(lambda t, x: np.array([x[1], -4 * x[0]]), (0.0, 2.0), [1.0, 0.0],
                        t_eval=TIMES, rtol=rtol, atol=rtol / 1000)
        return errors_of(sol.y.T)

    def compiled_error(rtol: float) -> float:
        result = springc.simulate(model, solver="rk45", rtol=rtol, atol=rtol / 1000,
                                  engine="compiled")
        assert result.stats.engine == "compiled"
        return errors_of(result.values)

    # The full sweep, loosest first: scipy's RK45 first meets 1e-7 at rtol 1e-7.
    full = [scipy_error(r) for r in tolerances[1:]]
    assert [e <= 1e-7 for e in full] == [False, False, False, True, True]
    tightened = rows[1:]
    assert [(r.solver, r.label()) for r in tightened] == [
        (SCIPY_RK45, f"rtol {r:.0e}") for r in (1e-4, 1e-5, 1e-6, 1e-7)]
    assert [r.status for r in tightened[:3]] == [
        f"skipped: probe (rk45 reaches {compiled_error(r):.1e} > 1e-07)"
        for r in (1e-4, 1e-5, 1e-6)]
    assert (tightened[3].status, tightened[3].engine) == ("ok", "scipy")
    assert tightened[3].max_error == pytest.approx(full[3], rel=1e-9)
    # The recommendation quotes the rtol scipy needs, past the skipped rows.
    fast = pilot_run(1e-3, 1e-8)
    seconds = tightened[3].wall_time
    assert (f"; scipy's RK45 needs rtol 1e-07 for it ({seconds:.3g} s: dop853 is "
            f"{seconds / 1e-3:.1f}x faster); scipy's default RK45 (rtol 1e-3) reaches "
            "only ") in recommend((fast,), rows, 1e-7)
    # A probe that scipy's run contradicts is not believed: every rtol is run.
    monkeypatch.setattr(baselines, "probe_errors", lambda *args: [1.0, 1.0, 1.0, 5e-8])
    rows = baseline_runs(setup, ref, scales, None)
    assert [(r.label(), r.status) for r in rows[1:]] == [
        (f"rtol {r:.0e}", "ok") for r in (1e-4, 1e-5, 1e-6, 1e-7)]
    assert [r.max_error for r in rows[1:]] == pytest.approx(full[:4], rel=1e-9)


def test_without_a_compiled_rk45_every_rtol_of_scipys_rk45_is_run(tmp_path: Path,
                                                                   exact_csv: str) -> None:
    model = oscillator(tmp_path, "python")  # the python backend: rk45 in scipy's loop
    tolerances = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
    setup, ref, scales = study_parts(model, exact_csv, repeats=1, targets=(1e-7,),
                                     tolerances=tolerances)
    assert probe_errors(setup, ref, scales, list(tolerances[1:]), 1e-7) is None
    rows = baseline_runs(setup, ref, scales, None)
    assert [(r.label(), r.status, r.engine) for r in rows[1:]] == [
        (f"rtol {r:.0e}", "ok", "scipy") for r in (1e-4, 1e-5, 1e-6, 1e-7)]
    assert rows[-2].max_error > 1e-7 >= rows[-1].max_error


# ------------------------------------------------------------------ engines

def test_solvers_with_a_compiled_loop_run_compiled(tmp_path: Path) -> None:
    model = oscillator(tmp_path, "numba")
    study = run_tradeoff(model, TradeoffOptions(tolerances=(1e-6,), steps=(0.01,),
                                                repeats=1, cost_limit=math.inf))
    engines = {r.solver: r.engine for r in study.runs}
    assert set(engines) == set(available_solvers())
    assert engines == {s: "compiled" if s in COMPILED_SOLVERS else "scipy" for s in engines}
    assert engines["lsoda"] == "scipy"
    assert {b.engine for b in study.baselines} == {"scipy"}
    assert study.reference.description.startswith("dop853 (compiled) at rtol 1e-12 (")
    assert study.pilot == "dop853"
