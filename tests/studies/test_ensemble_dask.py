"""The ensemble's chunks as Dask tasks (an in-process ``distributed.LocalCluster``):
the final values and statistics are the same bytes as the in-process engine's whatever
the chunk size and the number of worker threads, the runs come back in run order, a
failed run keeps its single-run message, and a scheduler that is not there is refused
by name before anything is written."""

from __future__ import annotations

import socket
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline import CompiledModel
from springc.studies import EnsembleOptions, parse_parameter, run_ensemble
from springc.studies.ensemble_tasks import dask_chunk_size, task_threads

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
STOP = 2.0
SPEC = "spring.k=1e3:1e5:log:37"


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> Iterator[CompiledModel]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        yield springc.compile_model(SEED)


def _options(spec: str = SPEC, **more: object) -> EnsembleOptions:
    return EnsembleOptions((parse_parameter(spec),), stop=STOP, rtol=1e-6, atol=1e-9,
                           **more)  # type: ignore[arg-type]


@pytest.mark.parametrize("engine", ["c", "numba"])
def test_dask_tasks_give_the_bytes_of_the_in_process_engine(model: CompiledModel,
                                                            tmp_path: Path,
                                                            engine: str) -> None:
    from distributed import LocalCluster

    local = tmp_path / "local.parquet"
    run_ensemble(model, _options(engine=engine, chunk=100), str(local))
    expected = pq.read_table(local)
    for workers, threads, chunk in ((1, 2, 5), (2, 1, None), (1, 3, 11)):
        with LocalCluster(n_workers=workers, threads_per_worker=threads, processes=False,
                          dashboard_address=None) as cluster:
            path = tmp_path / f"dask-{workers}-{threads}-{chunk}.parquet"
            summary = run_ensemble(model, _options(engine=engine, chunk=chunk,
                                                   scheduler=cluster.scheduler_address),
                                   str(path))
        assert (summary.runs, summary.failed, summary.engine) == (37, 0, engine)
        got = pq.read_table(path)
        groups = pq.ParquetFile(path).metadata.num_row_groups
        # chunk None: about four tasks per worker thread (37 runs on 2 threads: 5 each)
        assert groups == {5: 8, None: 8, 11: 4}[chunk]
        assert got.column_names == expected.column_names
        for name in got.column_names:
            a, b = got.column(name).to_numpy(zero_copy_only=False), \
                expected.column(name).to_numpy(zero_copy_only=False)
            if a.dtype.kind == "f":
                assert a.tobytes() == b.tobytes(), name
            else:
                assert a.tolist() == b.tolist(), name


def test_a_failed_run_on_dask_keeps_the_single_run_message(model: CompiledModel,
                                                           tmp_path: Path) -> None:
    from distributed import LocalCluster

    local, remote = tmp_path / "l.parquet", tmp_path / "r.parquet"
    run_ensemble(model, _options("mass.m=0.5,0,2,0"), str(local))
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                      dashboard_address=None) as cluster:
        run_ensemble(model, _options("mass.m=0.5,0,2,0", chunk=1, explain=1,
                                     scheduler=cluster.scheduler_address), str(remote))
    table = pq.read_table(remote).to_pydict()
    assert table["status"] == ["ok", "failed", "ok", "failed"]
    first = pq.read_table(local).to_pydict()["error"][1]
    assert first is not None and first.startswith("error: division by zero while "
                                                  "computing der(mass.v[1]) (")
    # the first failed run of the ensemble gets the single-run message (explain=1),
    # the next the words of its kind, whatever the chunks
    assert table["error"] == [None, first, None,
                              "dop853 failed at time 0: the derivatives are not finite"]
    np.testing.assert_array_equal(table["mass.v[2].final"],
                                  pq.read_table(local).to_pydict()["mass.v[2].final"])


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def test_a_scheduler_that_is_not_there_is_refused_and_nothing_is_written(
        model: CompiledModel, tmp_path: Path) -> None:
    port = _closed_port()
    path = tmp_path / "e.parquet"
    with pytest.raises(UsageError) as refused:
        run_ensemble(model, _options(scheduler=f"127.0.0.1:{port}"), str(path))
    assert refused.value.option == "--scheduler"
    assert str(refused.value).startswith(f"error: --scheduler 127.0.0.1:{port}: cannot "
                                         "connect to a Dask scheduler (")
    assert not path.exists() and list(tmp_path.iterdir()) == []
    result = CliRunner().invoke(main, ["ensemble", SEED, "--param", "spring.k=1e3,2e3",
                                       "--scheduler", f"127.0.0.1:{port}", "-o", str(path)])
    assert result.exit_code == 2
    assert f"error: --scheduler 127.0.0.1:{port}: cannot connect" in result.output
    assert not path.exists()


def test_task_sizes_and_threads() -> None:
    assert dask_chunk_size(37, 2, 100_000) == 5
    assert dask_chunk_size(10**6, 16, 100_000) == 15_625
    assert dask_chunk_size(10**7, 2, 100_000) == 100_000
    assert dask_chunk_size(3, 8, 100_000) == 1
    assert (task_threads(None, None), task_threads(None, "tcp://x:1"),
            task_threads(3, "tcp://x:1")) == (0, 1, 3)
