"""Every command-line and API value is checked up front (issue 10): a message naming the
option, exit 2 on the command line, springc's own typed error from the Python API with
the same rendered text."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import SpringcError, UsageError

MODEL = """
model Chain
  parameter Integer N = 3;
  parameter Real k = 2;
  Real x[N](each start = 1);
equation
  der(x) = -k*x;
end Chain;
"""

SRC = str(Path(__file__).resolve().parents[2] / "src")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def model(tmp_path: Path) -> str:
    path = tmp_path / "Chain.mdl"
    path.write_text(MODEL)
    return str(path)


OPTION_CASES = [
    (["--rtol", "0"], "error: --rtol must be a finite number in (0, 1), not 0.0"),
    (["--rtol", "nan"], "error: --rtol must be a finite number in (0, 1), not nan"),
    (["--rtol", "inf"], "error: --rtol must be a finite number in (0, 1), not inf"),
    (["--rtol", "-1"], "error: --rtol must be a finite number in (0, 1), not -1.0"),
    (["--atol", "nan"], "error: --atol must be a finite number, not nan"),
    (["--atol", "0"], "error: --atol must be a finite number > 0, not 0.0"),
    (["--interval", "inf"], "error: --interval must be a finite number, not inf"),
    (["--interval", "0"], "error: --interval must be a finite number > 0, not 0.0"),
    (["--interval", "-1"], "error: --interval must be a finite number > 0, not -1.0"),
    (["--start", "2", "--stop", "1"], "error: --stop (1) must be after --start (2)"),
    (["--stop", "nan"], "error: --stop must be a finite number, not nan"),
    (["--start", "-inf"], "error: --start must be a finite number, not -inf"),
    (["--solver", "rk4", "--step", "nan"], "error: --step must be a finite number, not nan"),
    (["--solver", "rk4", "--step", "inf"], "error: --step must be a finite number, not inf"),
    (["--set", "N=nan"], "error: --set: the value of 'N' must be a finite number, not nan"),
    (["--set", "k=-inf"], "error: --set: the value of 'k' must be a finite number, not -inf"),
    (["--set", "N=2.5"], "error: 'N' is an Integer parameter: 2.5 is not a whole number of "
                         "magnitude at most 2147483647"),
    (["--start", "-1e308", "--stop", "1e308"], "error: --start -1e+308 to --stop 1e+308: "
     "the span is too large for a floating-point number"),
    (["--stop", "1e6", "--interval", "1e-12"], "error: --interval 1e-12: 1e+18 output "
     "intervals are too many (at most 10,000,000)\nhelp: use a larger --interval"),
]


@pytest.mark.parametrize(("args", "message"), OPTION_CASES,
                         ids=[" ".join(a) for a, _ in OPTION_CASES])
def test_bad_values_exit_2_naming_the_option(model: str, tmp_path: Path, args: list[str],
                                             message: str) -> None:
    out = tmp_path / "out.csv"
    result = CliRunner().invoke(main, ["simulate", model, "-q", "-o", str(out), *args])
    assert result.exit_code == 2, result.output
    assert result.stderr == message + "\n"
    assert not out.exists()


@pytest.mark.parametrize("command", ["simulate", "sweep"])
@pytest.mark.parametrize(("args", "message"), [
    (["--start", "-1e308", "--stop", "1e308"], "error: --start -1e+308 to --stop 1e+308: "
     "the span is too large for a floating-point number"),
    (["--time-limit", "nan"], "Error: Invalid value for '--time-limit': 'nan' is not a "
     "number"),
])
def test_span_and_time_limit_of_simulate_and_sweep(model: str, tmp_path: Path,
                                                   command: str, args: list[str],
                                                   message: str) -> None:
    out = tmp_path / ("out.csv" if command == "simulate" else "out.parquet")
    extra = ["--param", "k=1,2"] if command == "sweep" else []
    result = CliRunner().invoke(main, [command, model, "-q", "-o", str(out), *extra, *args])
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines()[-1] == message
    assert list(tmp_path.iterdir()) == [Path(model)]


@pytest.mark.parametrize("item", ["=3", "k", "k=abc"])
def test_malformed_set(model: str, item: str) -> None:
    result = CliRunner().invoke(main, ["simulate", model, "-q", "--set", item])
    assert result.exit_code == 2
    assert "Invalid value for --set" in result.stderr


def test_array_size_out_of_range_is_refused_before_flattening(model: str) -> None:
    """``--set N=1e30`` used to flatten a 10^30-element array (killed for memory). The
    child runs under an address-space limit so that a regression fails, not hangs."""
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))

    done = subprocess.run(
        [sys.executable, "-m", "springc", "simulate", model, "-q", "--set", "N=1e30"],
        capture_output=True, text=True, timeout=120, preexec_fn=limit,
        env={**os.environ, "PYTHONPATH": SRC})
    assert done.returncode == 2, done.stderr
    assert done.stderr == ("error: 'N' is an Integer parameter: 1e+30 is not a whole number "
                           "of magnitude at most 2147483647\n")


def test_tradeoff_checks_its_run_values_too(model: str) -> None:
    result = CliRunner().invoke(main, ["tradeoff", model, "--interval", "inf"])
    assert result.exit_code == 2
    assert result.stderr == "error: --interval must be a finite number, not inf\n"


def test_api_raises_typed_errors_rendered_like_the_cli(model: str) -> None:
    compiled = springc.compile_model(model)
    with pytest.raises(UsageError) as caught:
        springc.simulate(compiled, rtol=0.0)
    error = caught.value
    assert isinstance(error, SpringcError)
    assert error.option == "rtol"
    assert error.message == "rtol must be a finite number in (0, 1), not 0.0"
    assert str(error) == "error: rtol must be a finite number in (0, 1), not 0.0"
    with pytest.raises(UsageError, match=r"^error: interval must be a finite number, not "
                                         r"inf$"):
        springc.simulate(compiled, interval=float("inf"))
    with pytest.raises(UsageError, match=r"the value of 'k' must be a finite number"):
        springc.simulate(compiled, parameters={"k": float("nan")})
    with pytest.raises(UsageError, match=r"'N' is an Integer parameter: 1e\+30"):
        springc.simulate(compiled, parameters={"N": 1e30})
    with pytest.raises(UsageError, match=r"^error: rtol must be a number, not 'tight'$"):
        springc.simulate(compiled, rtol="tight")  # type: ignore[arg-type]


def test_api_errors_render_file_line_notes_and_help(tmp_path: Path) -> None:
    bad = tmp_path / "Bad.mdl"
    bad.write_text("model Bad\n  Real x(start = 1);\nequation\n  der(x) = -y;\nend Bad;\n")
    with pytest.raises(SpringcError) as caught:
        springc.compile_model(bad)
    text = str(caught.value)
    assert text.startswith(f"{bad}:4:")
    assert "\n    4 |   der(x) = -y;\n" in text


def test_tradeoff_options_are_checked() -> None:
    from springc.tradeoff import TradeoffOptions

    with pytest.raises(UsageError, match=r"tolerances must be finite numbers in \(0, 1\), "
                                         r"not nan"):
        TradeoffOptions(tolerances=(1e-3, float("nan")))
    with pytest.raises(UsageError, match=r"steps must be positive finite numbers, not 0"):
        TradeoffOptions(steps=(0.0,))
    with pytest.raises(UsageError, match=r"repeats must be an integer >= 1, not 0"):
        TradeoffOptions(repeats=0)
    with pytest.raises(UsageError, match=r"^error: interval must be a finite number, not inf$"):
        TradeoffOptions(interval=float("inf"))
    with pytest.raises(UsageError, match=r"stop \(1\) must be after start \(2\)"):
        TradeoffOptions(start=2.0, stop=1.0)


def test_api_misuse_raises_springcs_own_errors(model: str) -> None:
    """A string of outputs is one pattern; files=None and an unknown result name are
    springc's errors (an unknown name is a KeyError too), with the CLI's words."""
    from springc.errors import UnknownNameError

    result = springc.simulate(model, stop=1.0, interval=0.5, outputs="x[2]")
    assert result.names == ("x[2]",)
    assert np.allclose(result["x[2]"], np.exp(-2 * np.array([0.0, 0.5, 1.0])), rtol=1e-5)
    with pytest.raises(UsageError) as caught:
        springc.compile_model(None)  # type: ignore[arg-type]
    assert str(caught.value) == ("error: files must be a file name or a list of file "
                                 "names, not None")
    assert caught.value.option == "files"
    with pytest.raises(UsageError, match=r"^error: outputs must be a name pattern or a "
                                         r"list of them, not 3$"):
        springc.compile_model(model, outputs=3)  # type: ignore[arg-type]
    with pytest.raises(UnknownNameError) as unknown:
        result["x[3]"]
    assert isinstance(unknown.value, KeyError) and isinstance(unknown.value, SpringcError)
    assert str(unknown.value) == ("error: 'x[3]' matches no state or observed variable of "
                                  "this result\nhelp: did you mean 'x[2]'?")


def test_a_library_that_is_a_fifo_is_a_bad_option(model: str, tmp_path: Path) -> None:
    # click's Path(file_okay=False) lets a FIFO through (it is no regular file); it was
    # then "library folder ... does not exist", exit 1
    fifo = tmp_path / "lib"
    os.mkfifo(fifo)
    result = CliRunner().invoke(main, ["check", model, "-L", str(fifo)])
    assert result.exit_code == 2
    assert result.stderr.splitlines()[-1] == (
        f"Error: Invalid value for '-L' / '--library': '{fifo}' is not a folder.")
