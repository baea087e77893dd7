"""``springc tradeoff`` output files (issue 10): checked before the study, written all
or nothing, the plot's format by suffix, the inputs (model and --reference) protected."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main

OSCILLATOR = """
model Oscillator "x'' = -4 x"
  parameter Real k = 4;
  Real x(start = 1);
  Real v(start = 0);
equation
  der(x) = v;
  der(v) = -k * x;
  annotation(experiment(StartTime = 0, StopTime = 1, Interval = 0.1));
end Oscillator;
"""
QUICK = ("--solvers", "rk4", "--steps", "0.05", "--repeats", "1", "--max-error", "1e-3",
         "-q")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def oscillator(tmp_path: Path) -> Path:
    path = tmp_path / "Oscillator.mdl"
    path.write_text(OSCILLATOR)
    return path


def run(*args: str | Path) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, [str(a) for a in args])
    return result.exit_code, result.stdout, result.stderr


def test_outputs_that_name_one_file_are_refused_before_the_study(oscillator: Path,
                                                                  tmp_path: Path) -> None:
    same = tmp_path / "same.csv"
    code, out, err = run("tradeoff", oscillator, *QUICK, "-o", same,
                         "--save-reference", same)
    assert code == 2 and out == ""
    assert err == (f"error: -o and --save-reference name the same file '{same}'\n"
                   "help: give each output its own file\n")
    assert not same.exists()


def test_the_reference_input_is_never_overwritten(oscillator: Path, tmp_path: Path) -> None:
    ref = tmp_path / "ref.csv"
    ref.write_text("time,x,v\n")
    code, _, err = run("tradeoff", oscillator, *QUICK, "--reference", ref,
                       "--save-reference", ref)
    assert code == 2
    assert err.startswith(f"error: --save-reference: refusing to write '{ref}': it is an "
                          "input of this run")
    assert ref.read_text() == "time,x,v\n"


def test_plot_suffix_is_checked_and_chooses_the_format(oscillator: Path,
                                                       tmp_path: Path) -> None:
    code, _, err = run("tradeoff", oscillator, *QUICK, "--plot", tmp_path / "wp.jpg")
    assert code == 2 and "--plot" in err and ".png, .svg, .pdf" in err
    table, plot, ref = tmp_path / "t.csv", tmp_path / "wp.svg", tmp_path / "r.csv"
    code, _, err = run("tradeoff", oscillator, *QUICK, "-o", table, "--plot", plot,
                       "--save-reference", ref)
    assert code == 0, err
    assert b"<svg" in plot.read_bytes()[:2000]
    rows = list(csv.reader(table.open()))
    assert rows[0][:3] == ["solver", "setting", "value"] and rows[1][:2] == ["rk4", "step"]
    assert next(csv.reader(ref.open())) == ["time", "x", "v"]


def test_a_failing_plot_leaves_no_table(oscillator: Path, tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    import springc.tradeoff.outputs as outputs

    def broken(*args: object) -> bytes:
        raise ValueError("cannot draw")

    monkeypatch.setattr(outputs, "render_work_precision", broken)
    code, _, err = run("tradeoff", oscillator, *QUICK, "-o", tmp_path / "t.csv",
                       "--plot", tmp_path / "wp.png")
    assert code == 3 and "cannot draw" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Oscillator.mdl"]
