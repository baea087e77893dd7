"""Output that scales: the default trajectory of a large scene is refused before the
run, with its size and how to ask for variables; variables asked for are written."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.simulation import output_size

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_a_default_trajectory_over_ten_million_values_is_refused(tmp_path: Path) -> None:
    # 7 outputs x 1,666,668 times = 11.7 million values: refused before any run.
    code, out, err = run("simulate", SEED, "--interval", "6e-6", "-o",
                         str(tmp_path / "seed.csv"))
    assert code == 2 and out == ""
    assert err == (
        f"error: -o {tmp_path / 'seed.csv'}: the default output of SpringMass is 7 "
        "variables x 1,666,668 times (12 million values, about 0.2 GB of CSV); a "
        "trajectory above 10,000,000 values is written only for the variables asked for\n"
        "help: select them with --vars (e.g. --vars 'mass.pos[*]'; --vars '*' writes "
        "every variable), use a larger --interval, or draw them with --plot alone\n")
    assert list(tmp_path.iterdir()) == []


def test_variables_asked_for_and_plots_are_written(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(output_size, "LARGE_TRAJECTORY", 1000)  # the seed: 7 x 501
    code, out, err = run("simulate", SEED, "-q")
    assert code == 2 and out == "" and err.startswith(
        "error: the CSV on stdout: the default output of SpringMass is 7 variables x 501 "
        "times (0 million values, about 0.0 GB of CSV); a trajectory above 1,000 values")
    code, out, _ = run("simulate", SEED, "-q", "--vars", "mass.pos[1]")
    assert code == 0 and out.splitlines()[0] == "time,mass.pos[1]"
    assert len(out.splitlines()) == 502
    code, out, _ = run("simulate", SEED, "-q", "--vars", "*", "--stop", "1")
    assert code == 0 and len(out.splitlines()[0].split(",")) == 8
    code, _, _ = run("simulate", SEED, "-q", "--plot", str(tmp_path / "seed.png"))
    assert code == 0 and (tmp_path / "seed.png").stat().st_size > 0


def test_changing_vars_does_not_compile_again() -> None:
    code, _, err = run("simulate", SEED, "--vars", "mass.pos[*]", "--stop", "0.1")
    assert code == 0
    code, out, err = run("simulate", SEED, "--vars", "mass.v[2]", "--stop", "0.1", "-v")
    assert code == 0 and out.splitlines()[0] == "time,mass.v[2]"
    assert "; cached in " in err.splitlines()[-1]
