"""``springc ensemble`` on the command line: the table it writes, its summary line, and
the exit code and message of bad options."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_ensemble_writes_a_row_per_run(tmp_path: Path) -> None:
    output = tmp_path / "e.parquet"
    result = CliRunner().invoke(main, [
        "ensemble", SEED, "--param", "spring.k=1e3,1e4", "--param", "mass.m=0,1",
        "--stop", "0.5", "--interval", "0.5", "--vars", "mass.pos*", "-o", str(output)])
    assert result.exit_code == 0, result.output
    assert result.stdout == ""
    assert result.stderr == f"SpringMass: 4 runs, 2 ok, 2 failed -> {output}\n"
    table = pd.read_parquet(output)
    assert table.columns.tolist()[:9] == ["run", "spring.k", "mass.m", "status", "error",
                                          "solver", "steps", "rhs_evaluations",
                                          "mass.pos[1].final"]
    assert table["status"].tolist() == ["failed", "ok", "failed", "ok"]
    single = springc.simulate(SEED, stop=0.5, interval=0.5, solver="dop853",
                              parameters={"spring.k": 1e4, "mass.m": 1.0})
    np.testing.assert_allclose(table["mass.pos[2].final"][3], single.values[-1, 1],
                               rtol=1e-6)


def test_ensemble_takes_the_verbosity_levels_of_every_command(tmp_path: Path) -> None:
    output = tmp_path / "e.parquet"
    args = ["ensemble", SEED, "--param", "spring.k=1e3,1e4", "--stop", "0.5",
            "--interval", "0.5", "-o", str(output)]
    quiet = CliRunner().invoke(main, [*args, "-q"])
    assert (quiet.exit_code, quiet.stdout, quiet.stderr) == (0, "", "")
    assert pd.read_parquet(output)["status"].tolist() == ["ok", "ok"]
    loud = CliRunner().invoke(main, [*args, "-v"])
    assert loud.exit_code == 0, loud.output
    assert loud.stderr == f"SpringMass: 2 runs, 2 ok, 0 failed -> {output}\n"


def test_ensemble_refuses_a_table_and_params_together(tmp_path: Path) -> None:
    csv = tmp_path / "runs.csv"
    csv.write_text("spring.k\n1000\n")
    result = CliRunner().invoke(main, ["ensemble", SEED, "--param", "spring.k=1,2",
                                       "--table", str(csv), "-o", str(tmp_path / "e.parquet")])
    assert result.exit_code == 2
    assert result.stderr.splitlines()[-1] == ("Error: --table and --param exclude each "
                                              "other (the table gives every run's values)")


def test_ensemble_writes_chosen_statistics_and_trajectories(tmp_path: Path) -> None:
    output, traj = tmp_path / "e.parquet", tmp_path / "t.parquet"
    result = CliRunner().invoke(main, [
        "ensemble", SEED, "--param", "spring.k=1e3,1e4", "--stop", "0.5", "--interval",
        "0.05", "--vars", "mass.pos*", "--stats", "final,max", "--trajectories", str(traj),
        "--traj-vars", "mass.pos[2]", "--every", "4", "--threads", "1", "-o", str(output)])
    assert result.exit_code == 0, result.output
    assert result.stderr == f"SpringMass: 2 runs, 2 ok, 0 failed -> {output} and {traj}\n"
    table = pd.read_parquet(output)
    assert table.columns.tolist()[7:] == ["mass.pos[1].final", "mass.pos[1].max",
                                          "mass.pos[2].final", "mass.pos[2].max"]
    frame = pd.read_parquet(traj)
    assert frame["run"].tolist() == [0] * 4 + [1] * 4
    np.testing.assert_allclose(frame["time"][:4], [0.0, 0.2, 0.4, 0.5], rtol=1e-12)
    single = springc.simulate(SEED, stop=0.5, interval=0.05, solver="dop853",
                              parameters={"spring.k": 1e4}, error_control="off")
    np.testing.assert_allclose(frame["mass.pos[2]"][4:], single.values[[0, 4, 8, 10], 1],
                               rtol=1e-6)
    np.testing.assert_allclose(table["mass.pos[2].final"][1], single.values[-1, 1],
                               rtol=1e-6)


def test_ensemble_names_a_bad_statistic(tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["ensemble", SEED, "--param", "spring.k=1,2",
                                       "--stats", "final,median",
                                       "-o", str(tmp_path / "e.parquet")])
    assert result.exit_code == 2
    assert result.stderr.splitlines()[0] == ("error: --stats median: not one of final, min, "
                                             "max, mean, time_of_max")
    assert not (tmp_path / "e.parquet").exists()
