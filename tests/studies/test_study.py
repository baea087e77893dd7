"""Studies of the seed on local worker processes and on a Dask LocalCluster: every
run equals a single ``springc.simulate`` bit for bit, failures are recorded, an
interrupted study resumes without recomputing, and the Parquet layout is as documented."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import springc
from springc.errors import UsageError
from springc.studies import (
    Study,
    StudyOptions,
    parse_parameter,
    partial_folder,
    run_study,
    to_dataset,
)

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
STIFFNESS = "spring.k=1e3:1e5:log:6"
STOP = 2.0
OUTPUTS = ("mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]", "spring.dir[1]",
           "spring.dir[2]", "spring.x")
COLUMNS = ["run", "time", "spring.k", *OUTPUTS, "status", "error", "solver", "steps",
           "rhs_evaluations", "jacobian_evaluations", "rtol", "estimated_error",
           "warning"]


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    folder = tmp_path_factory.mktemp("cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(folder))
        yield folder


@pytest.fixture(scope="module")
def study(cache: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Study, Path]:
    """The seed over six stiffness values on two local workers, written to Parquet."""
    output = tmp_path_factory.mktemp("out") / "study.parquet"
    model = springc.compile_model(SEED)
    options = StudyOptions((parse_parameter(STIFFNESS),), stop=STOP, workers=2)
    return run_study(model, options, str(output)), output


def test_every_run_equals_a_single_simulate_bit_for_bit(study: tuple[Study, Path]
                                                        ) -> None:
    result, _ = study
    data = to_dataset(result)
    assert list(result.summary.column("status").to_pylist()) == ["ok"] * 6
    for run, k in enumerate(np.geomspace(1e3, 1e5, 6)):
        single = springc.simulate(SEED, stop=STOP, parameters={"spring.k": float(k)})
        assert float(data["spring.k"][run]) == k
        for j, name in enumerate(single.names):
            assert np.array_equal(data[name].values[run], single.values[:, j]), name
        assert int(data["steps"][run]) == single.stats.steps
        assert str(data["solver"].values[run]) == single.stats.solver


def test_parquet_files_have_the_documented_columns(study: tuple[Study, Path]) -> None:
    _, output = study
    table = pd.read_parquet(output)
    assert table.columns.tolist() == COLUMNS
    assert len(table) == 6 * 501
    assert table["run"].tolist() == [r for r in range(6) for _ in range(501)]
    assert table["time"].iloc[500] == STOP
    assert table["error"].isna().all()
    summary = pd.read_parquet(output.with_name("study.summary.parquet"))
    metrics = [f"{n}.{m}" for n in OUTPUTS for m in ("final", "min", "max")]
    assert summary.columns.tolist() == ["run", "spring.k", *COLUMNS[-9:], *metrics]
    pos = table["mass.pos[1]"].to_numpy().reshape(6, 501)
    assert np.array_equal(summary["mass.pos[1].final"], pos[:, -1])
    assert np.array_equal(summary["mass.pos[1].max"], pos.max(axis=1))
    assert pq.read_schema(output).field("spring.x").metadata == {b"unit": b""}
    assert not partial_folder(output).exists()


def test_the_same_study_on_a_dask_local_cluster_is_identical(
        study: tuple[Study, Path]) -> None:
    from distributed import LocalCluster

    local, _ = study
    model = springc.compile_model(SEED)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                      dashboard_address=None) as cluster:
        options = StudyOptions((parse_parameter(STIFFNESS),), stop=STOP,
                               scheduler=cluster.scheduler_address)
        remote = run_study(model, options)
    assert remote.engine.startswith("Dask at ")
    assert remote.table.equals(local.table)


def test_failing_runs_are_recorded_and_the_study_finishes(cache: Path) -> None:
    model = springc.compile_model(SEED)
    options = StudyOptions((parse_parameter("mass.m=1,0,-1,2"),), stop=5.0, workers=2)
    result = run_study(model, options)
    summary = result.summary.to_pandas()
    assert summary["status"].tolist() == ["ok", "failed", "failed", "ok"]
    assert summary["error"][1].startswith("error: division by zero while computing "
                                          "der(mass.v[1])")
    # a negative mass: the motion grows like exp(t sqrt(k/|m|)) until it overflows
    assert summary["error"][2].startswith("error: der(mass.v[")
    assert "infinite at time" in summary["error"][2]
    assert summary["error"][[0, 3]].isna().all()
    assert summary["mass.pos[1].final"].isna().tolist() == [False, True, True, False]
    single = springc.simulate(SEED, stop=5.0, parameters={"mass.m": 2.0})
    assert summary["mass.pos[1].final"][3] == single["mass.pos[1]"][-1]
    assert result.failed == 2


def test_an_interrupted_study_resumes_without_recomputing(cache: Path, tmp_path: Path
                                                          ) -> None:
    output = str(tmp_path / "resumed.parquet")
    model = springc.compile_model(SEED)
    options = StudyOptions((parse_parameter("spring.k=1e3:1e4:log:8"),), stop=1.0,
                           workers=2)

    def stop_after_three(done: int, total: int) -> None:
        if done >= 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(model, options, output, callback=stop_after_three)
    shards = pd.concat(pd.read_parquet(p) for p in
                       sorted(partial_folder(output).glob("shard-*.parquet")))
    finished = sorted(set(shards["run"]))
    assert 3 <= len(finished) < 8
    with pytest.raises(UsageError, match="partial results of an earlier study"):
        run_study(model, options, output)
    resumed = run_study(model, options, output, resume=True)
    assert sorted(resumed.computed) == sorted(set(range(8)) - set(finished))
    table = pd.read_parquet(output)
    first = table[table["run"].isin(finished)].reset_index(drop=True)
    assert first.equals(shards.sort_values(["run", "time"]).reset_index(drop=True))
    assert table["status"].eq("ok").all() and len(table) == 8 * 501
    assert not partial_folder(output).exists()


def test_resume_refuses_the_partial_results_of_another_study(cache: Path,
                                                             tmp_path: Path) -> None:
    output = str(tmp_path / "other.parquet")
    model = springc.compile_model(SEED)
    options = StudyOptions((parse_parameter("spring.k=1e3,2e3,3e3"),), stop=0.5,
                           workers=1)

    def interrupt(done: int, total: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(model, options, output, callback=interrupt)
    changed = StudyOptions((parse_parameter("spring.k=1e3,2e3,4e3"),), stop=0.5,
                           workers=1)
    with pytest.raises(UsageError, match="are of another study"):
        run_study(model, changed, output, resume=True)


def test_bad_studies_are_refused_before_any_run(cache: Path) -> None:
    model = springc.compile_model(SEED)
    with pytest.raises(UsageError) as unknown:
        run_study(model, StudyOptions((parse_parameter("spring.q=1,2"),)))
    assert (unknown.value.option, unknown.value.message) == (
        "--param", "--param spring.q: 'spring.q' is not a parameter or a state of SpringMass")
    assert unknown.value.hint == "did you mean 'spring.k' or 'spring.l'?"
    with pytest.raises(UsageError, match="both swept"):
        run_study(model, StudyOptions((parse_parameter("spring.k=1,2"),),
                                      fixed=(("spring.k", 3.0),)))
