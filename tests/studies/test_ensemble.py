"""The compiled ensemble engine on the seed: final states and statistics equal single
``springc.simulate`` runs within 1e-6 relative (same solver, rtol 1e-6, atol 1e-9),
a failed run keeps the single run's message while the others succeed, the bytes do not
depend on the number of threads, and chunks stream into Parquet in run order."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import springc
from springc.errors import SimulationError, UsageError
from springc.integrate import Status, dop853
from springc.pipeline import CompiledModel
from springc.studies import EnsembleOptions, parse_parameter, read_table, run_ensemble

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
STOP = 2.0
RTOL, ATOL = 1e-6, 1e-9
STATES = ("mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]")


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> Iterator[CompiledModel]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        yield springc.compile_model(SEED)


def _run(model: CompiledModel, path: Path, spec: str, **options: object) -> dict[str, list]:
    settings = EnsembleOptions((parse_parameter(spec),), stop=STOP, rtol=RTOL, atol=ATOL,
                               **options)  # type: ignore[arg-type]
    run_ensemble(model, settings, str(path))
    return pq.read_table(path).to_pydict()


def test_fifty_runs_equal_single_simulate_runs(model: CompiledModel, tmp_path: Path) -> None:
    table = _run(model, tmp_path / "e.parquet", "spring.k=1e3:1e5:log:50")
    assert table["run"] == list(range(50))
    assert table["status"] == ["ok"] * 50 and table["error"] == [None] * 50
    for run, k in enumerate(np.geomspace(1e3, 1e5, 50)):
        assert table["spring.k"][run] == k
        single = springc.simulate(SEED, stop=STOP, solver="dop853", rtol=RTOL, atol=ATOL,
                                  error_control="off",
                                  parameters={"spring.k": float(k)})
        t = single.time
        for j, name in enumerate(single.names):
            values = single.values[:, j]
            got = [table[f"{name}.{s}"][run] for s in ("final", "min", "max", "mean")]
            expected = [values[-1], values.min(), values.max(),
                        np.trapezoid(values, t) / (t[-1] - t[0])]
            np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-12, err_msg=name)
            assert abs(table[f"{name}.time_of_max"][run] - t[values.argmax()]) <= 1e-12 \
                or np.isclose(values[t == table[f"{name}.time_of_max"][run]][0],
                              values.max(), rtol=1e-6, atol=0)


def test_a_failed_run_keeps_its_message_and_the_others_succeed(model: CompiledModel,
                                                                tmp_path: Path) -> None:
    table = _run(model, tmp_path / "e.parquet", "mass.m=0.5,0,2")
    assert table["status"] == ["ok", "failed", "ok"]
    with pytest.raises(SimulationError) as single:
        springc.simulate(SEED, stop=STOP, solver="dop853", rtol=RTOL, atol=ATOL,
                         error_control="off",
                         parameters={"mass.m": 0.0})
    assert table["error"] == [None, str(single.value), None]
    assert str(single.value).startswith("error: division by zero while computing "
                                        "der(mass.v[1]) (")
    assert table["mass.pos[1].final"][1] is None
    reference = springc.simulate(SEED, stop=STOP, solver="dop853", rtol=RTOL, atol=ATOL,
                                 error_control="off",
                                 parameters={"mass.m": 2.0})
    np.testing.assert_allclose(table["mass.v[2].final"][2], reference.values[-1, 3],
                               rtol=1e-6)


def test_failures_past_the_explained_ones_get_the_words_of_their_kind(
        model: CompiledModel, tmp_path: Path) -> None:
    table = _run(model, tmp_path / "e.parquet", "mass.m=0,0", explain=0)
    assert table["error"] == ["dop853 failed at time 0: the derivatives are not finite"] * 2
    table = _run(model, tmp_path / "s.parquet", "spring.k=1e4", max_steps=5, explain=0)
    mod = model.module
    p = mod.parameters({"spring.k": 1e4})
    single = dop853(mod.rhs, [0.0, STOP], mod.start(p), p, mod.guesses(p), rtol=RTOL,
                    atol=ATOL, max_steps=5, scipy_arithmetic=False)
    assert single.status == Status.MAX_STEPS and 0 < single.failure_time < STOP
    assert table["error"] == [f"dop853 failed at time {single.failure_time:g}: the run "
                              "reached the step limit (--max-steps 5)"]


@pytest.mark.parametrize("engine", ["c", "numba"])
def test_the_bytes_do_not_depend_on_the_number_of_threads(model: CompiledModel,
                                                          tmp_path: Path, engine: str) -> None:
    files = []
    for count in (1, 2):
        files.append(tmp_path / f"{count}.parquet")
        _run(model, files[-1], "spring.k=1e3:1e5:log:40", chunk=16, threads=count,
             engine=engine)
    assert files[0].read_bytes() == files[1].read_bytes()
    assert pq.read_table(files[0]).schema.metadata[b"springc"].count(
        f'"engine": "{engine}"'.encode()) == 1


def test_chunks_stream_every_run_in_order(model: CompiledModel, tmp_path: Path) -> None:
    path = tmp_path / "e.parquet"
    table = _run(model, path, "spring.k=1e3:1e4:23", chunk=5, variables=STATES)
    assert pq.ParquetFile(path).metadata.num_row_groups == 5
    assert table["run"] == list(range(23))
    assert table["spring.k"] == np.linspace(1e3, 1e4, 23).tolist()
    assert list(table)[-1] == "mass.v[2].time_of_max" and len(table) == 7 + 4 * 5


def test_a_table_of_runs_from_csv(model: CompiledModel, tmp_path: Path) -> None:
    csv = tmp_path / "runs.csv"
    csv.write_text("spring.k,mass.m\n1000,1\n\n20000,0.5\n")
    names, values = read_table(csv)
    assert names == ("spring.k", "mass.m") and values.tolist() == [[1e3, 1.0], [2e4, 0.5]]
    run_ensemble(model, EnsembleOptions(table=(names, values), stop=STOP, rtol=RTOL,
                                        atol=ATOL), str(tmp_path / "t.parquet"))
    table = pq.read_table(tmp_path / "t.parquet").to_pydict()
    single = springc.simulate(SEED, stop=STOP, solver="dop853", rtol=RTOL, atol=ATOL,
                              error_control="off",
                              parameters={"spring.k": 2e4, "mass.m": 0.5})
    np.testing.assert_allclose(table["spring.x.max"][1], single.values[:, 6].max(),
                               rtol=1e-6)
    csv.write_text("spring.k\n1e3\nstiff\n")
    with pytest.raises(UsageError) as bad:
        read_table(csv)
    assert str(bad.value) == (f"error: --table {csv}: run 1, spring.k: 'stiff' is not a "
                              "finite number")


def test_a_model_with_events_but_no_states_is_refused_by_name(tmp_path: Path) -> None:
    clock = springc.load_model_from_string(
        "model Clock\n  parameter Real step = 1;\n  discrete Real n(start = 0);\n"
        "  Real s = step;\nequation\n  when sample(0, 0.1) then\n"
        "    n = pre(n) + step;\n  end when;\nend Clock;\n")
    with pytest.raises(SimulationError) as refused:
        run_ensemble(clock, EnsembleOptions((parse_parameter("step=1,2"),)),
                     str(tmp_path / "e.parquet"))
    assert refused.value.message == ("Clock has events (sample(...)) but no "
                                     "states, which the ensemble engine does not run yet")
    assert not (tmp_path / "e.parquet").exists()


def test_a_variable_that_is_not_finite_fails_its_run(tmp_path: Path) -> None:
    text = ("model Decay\n  parameter Real a = 2;\n  Real x(start = 1);\n  Real y;\n"
            "equation\n  der(x) = -x;\n  y = sqrt(a - x);\nend Decay;\n")
    decay = springc.load_model_from_string(text)
    run_ensemble(decay, EnsembleOptions((parse_parameter("a=2,0.5"),), stop=1.0),
                 str(tmp_path / "e.parquet"))
    table = pq.read_table(tmp_path / "e.parquet").to_pydict()
    with pytest.raises(SimulationError) as single:
        springc.simulate(decay, stop=1.0, solver="dop853", parameters={"a": 0.5},
                         error_control="off")
    assert table["status"] == ["ok", "failed"]
    assert table["error"] == [None, str(single.value)]
    np.testing.assert_allclose(table["y.final"][0], np.sqrt(2 - np.exp(-1.0)), rtol=1e-6)
