"""``springc sweep --plot``: one variable across the runs, as lines (up to 12 runs) or a
fan chart (median and percentile bands), failed runs left out and counted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.studies import fan

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
MASSES = "0," + ",".join(str(1 + i / 10) for i in range(13))  # m = 0 fails


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def sweep(tmp_path: Path, *extra: str) -> tuple[int, str]:
    result = CliRunner().invoke(main, [
        "sweep", SEED, "--param", f"mass.m={MASSES}", "--stop", "0.5", "--interval", "0.05",
        "--vars", "mass.pos*", "--workers", "2", "-o", str(tmp_path / "study.parquet"),
        *extra])
    return result.exit_code, result.stderr


def test_a_fan_chart_of_thirteen_runs_with_one_failed(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    figures = []
    original = fan.fan_figure

    def keep(*args: object) -> object:
        figures.append(original(*args))  # type: ignore[arg-type]
        return figures[-1]

    monkeypatch.setattr(fan, "fan_figure", keep)
    code, err = sweep(tmp_path, "--plot", str(tmp_path / "fan.png"), "--plot-var",
                      "mass.pos[2]")
    assert code == 0, err
    assert err.splitlines()[-2] == (f"note: plot {tmp_path / 'fan.png'}: mass.pos[2]: median "
                                    "and percentile bands of 13 runs; 1 failed runs left out")
    assert (tmp_path / "fan.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    ((figure, _),) = figures
    (ax,) = figure.axes
    table = pd.read_parquet(tmp_path / "study.parquet")
    ok = table[table["status"] == "ok"]
    values = ok["mass.pos[2]"].to_numpy().reshape(13, 11)
    (median,) = ax.lines
    assert np.array_equal(median.get_ydata(), np.median(values, axis=0))
    assert [c.get_label() for c in ax.collections] == ["min - max", "5-95 %", "25-75 %"]
    assert ax.get_ylabel() == "mass.pos[2]"  # the seed declares no units


def test_few_runs_are_lines_labelled_with_their_values(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch
                                                       ) -> None:
    monkeypatch.setattr(fan, "MAX_LINES", 13)
    code, err = sweep(tmp_path, "--plot", str(tmp_path / "runs.svg"))
    assert code == 0, err
    assert err.splitlines()[-2] == (f"note: plot {tmp_path / 'runs.svg'}: mass.pos[1]: 13 "
                                    "runs as lines; 1 failed runs left out")
    assert (tmp_path / "runs.svg").read_text().count("mass.m=1.3") == 1


def test_plot_var_must_be_a_variable_of_the_study(tmp_path: Path) -> None:
    code, err = sweep(tmp_path, "--plot", str(tmp_path / "fan.png"), "--plot-var",
                      "spring.x")
    assert code == 2
    assert err == ("error: --plot-var spring.x: not among the study's variables "
                   "(mass.pos[1], mass.pos[2])\nhelp: select it with --vars\n")
    assert list(tmp_path.iterdir()) == []
    code, err = sweep(tmp_path, "--plot", str(tmp_path / "fan.gif"))
    assert code == 2 and err.startswith("error: --plot ")
