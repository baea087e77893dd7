"""``tradeoff`` through the studies executor: each solver's runs (and the scipy
baselines) are one task on local worker processes; the table equals the one computed
in the calling process, except the measured times."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

import springc
from springc.studies import Executor
from springc.tradeoff import TradeoffOptions, compare_states, run_tradeoff
from springc.tradeoff.model import Run

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


def untimed(run: Run) -> str:
    """A run without what depends on the clock (its time and how often it was timed),
    as text: every float written to round-trip, NaN equal to NaN."""
    return repr(dataclasses.replace(run, wall_time=0.0, repeats=0))


def test_the_executor_gives_the_table_of_the_calling_process(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))  # the workers' too
    model = compare_states(springc.compile_model(SEED))
    options = TradeoffOptions(solvers=("dop853", "rk4", "radau"), tolerances=(1e-3, 1e-5),
                              steps=(0.01, 0.005), stop=1.0, interval=0.01, repeats=1,
                              parameters={"spring.k": 2e3}, cost_limit=math.inf)
    here = run_tradeoff(model, options)
    there = run_tradeoff(model, options, Executor(workers=2))
    assert [(r.solver, r.label()) for r in there.runs] == [
        ("dop853", "rtol 1e-03"), ("dop853", "rtol 1e-05"), ("rk4", "step 0.01"),
        ("rk4", "step 0.005"), ("radau", "rtol 1e-03"), ("radau", "rtol 1e-05")]
    assert all(r.ok and r.steps > 0 for r in there.runs)
    assert [untimed(r) for r in there.runs] == [untimed(r) for r in here.runs]
    assert [untimed(r) for r in there.baselines] == [untimed(r) for r in here.baselines]
    assert there.baselines[0].solver == "scipy-default"
    assert there.reference.agreement == here.reference.agreement


def test_tradeoff_refuses_workers_with_a_scheduler() -> None:
    from click.testing import CliRunner

    from springc.cli import main

    out = CliRunner().invoke(main, ["tradeoff", SEED, "--workers", "2", "--scheduler",
                                    "tcp://127.0.0.1:1"])
    assert out.exit_code == 2
    assert out.stderr == ("error: --workers and --scheduler exclude each other (a Dask "
                          "cluster has its own workers)\n")


def test_the_executor_on_a_dask_local_cluster_gives_the_same_table(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from distributed import LocalCluster

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    model = compare_states(springc.compile_model(SEED))
    options = TradeoffOptions(solvers=("dop853", "verlet"), tolerances=(1e-4,),
                              steps=(0.005,), stop=0.5, interval=0.01, repeats=1,
                              cost_limit=math.inf)
    here = run_tradeoff(model, options)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                      dashboard_address=None) as cluster:
        executor = Executor(scheduler=cluster.scheduler_address)
        there = run_tradeoff(model, options, executor)
    assert executor.describe(3) == f"Dask at {cluster.scheduler_address}"
    assert [untimed(r) for r in (*there.runs, *there.baselines)] == [
        untimed(r) for r in (*here.runs, *here.baselines)]
    assert [(r.solver, r.label()) for r in there.runs] == [("dop853", "rtol 1e-04"),
                                                           ("verlet", "step 0.005")]


class Recording:
    """An executor running the tasks here, in order, and recording their count."""

    def __init__(self) -> None:
        self.tasks: list[int] = []

    def map(self, function, items):  # type: ignore[no-untyped-def]
        self.tasks.append(len(items))
        for i, item in enumerate(items):
            yield i, function(item)


def test_a_study_whose_pilot_is_quick_stays_in_the_calling_process(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import io

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    model = compare_states(springc.compile_model(SEED))
    log = io.StringIO()
    options = TradeoffOptions(solvers=("rk4", "dop853"), tolerances=(1e-3, 1e-5),
                              steps=(0.01,), stop=1.0, interval=0.01, repeats=1,
                              cost_limit=math.inf, log=log)
    # dop853 runs first (the pilot); its runs take far less than an hour, so the
    # other tasks (rk4, the scipy baselines) are not given to the executor.
    executor = Recording()
    here = run_tradeoff(model, options, executor, spread_above=3600.0)
    assert executor.tasks == []
    pilot_seconds = sum(r.wall_time for r in here.runs if r.solver == "dop853")
    assert (f"the other solvers run in this process: dop853's runs took "
            f"{pilot_seconds:.2g} s, less than starting worker processes costs\n"
            in log.getvalue())
    assert here.pilot == "dop853"
    assert [(r.solver, r.label()) for r in here.runs] == [
        ("rk4", "step 0.01"), ("dop853", "rtol 1e-03"), ("dop853", "rtol 1e-05")]
    # Spread from 0 s on, the two other tasks go to the executor: the same table.
    there = run_tradeoff(model, dataclasses.replace(options, log=None), executor)
    assert executor.tasks == [2]
    assert [untimed(r) for r in (*there.runs, *there.baselines)] == [
        untimed(r) for r in (*here.runs, *here.baselines)]
