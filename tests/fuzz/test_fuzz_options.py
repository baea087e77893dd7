"""Fuzzing the option values of ``springc simulate`` and ``springc sweep`` (issue 22).

Each option draws from its domain and past it: 0, negatives, ±1e308, nan, ±inf, tiny and
huge counts, text that is not a number. Every run must end with exit code 0, 1 or 2
(2 naming an option), with no traceback or "internal error", within a per-case time
cap (``SECONDS``) and 3 GiB of extra address space. Runs ask for
``--time-limit 5`` unless the case draws its own, and cases whose output grid would have
between 200,000 (sweep: 2,000) and 10,000,000 rows are skipped (valid, only slow to
write); grids past 10,000,000 rows are kept: they must be refused before any work.

CI runs a fixed, derandomized set (``SPRINGC_FUZZ_OPTION_EXAMPLES``, default 30 for
simulate and a third of that for sweep, about a minute in all).
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from fuzz.test_fuzz import RANDOM, SECONDS_PER_RUN, limits
from springc.cli import main

EXAMPLES = int(os.environ.get("SPRINGC_FUZZ_OPTION_EXAMPLES", "30"))

MODEL = """
model Fuzzed
  parameter Real k = 2;
  parameter Integer n = 2;
  Real x[n](each start = 1, each fixed = true);
  discrete Real h(start = 0);
equation
  der(x) = -k * x;
  when sample(0, 0.25) then
    h = x[1];
  end when;
end Fuzzed;
"""

REALS = ["0", "-0", "1", "-1", "0.5", "2", "10", "1e6", "1e-12", "1e-300", "1e308",
         "-1e308", "nan", "inf", "-inf", "abc", "", "1e309"]
COUNTS = ["0", "1", "-1", "3", "1000", "1e3", "99999999999999999999", "abc"]
SOLVERS = ["auto", "dop853", "rk45", "radau", "bdf", "lsoda", "rk4", "euler", "nope"]


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _rows(args: list[str]) -> float:
    """The output rows ``args`` ask for (0 when the values cannot be read)."""
    values = dict(zip(args[::2], args[1::2]))
    start = _number(values.get("--start", "0")) or 0.0
    stop = _number(values.get("--stop", "10"))
    interval = _number(values.get("--interval", "nan"))
    if stop is None or not math.isfinite(stop - start) or stop <= start:
        return 0.0
    if interval is None or not math.isfinite(interval) or interval <= 0:
        return 500.0
    return (stop - start) / interval


@st.composite
def options(draw: st.DrawFn, max_rows: int = 200_000) -> list[str]:
    args: list[str] = []
    for option, domain in (("--start", REALS), ("--stop", REALS), ("--interval", REALS),
                           ("--rtol", REALS), ("--atol", REALS), ("--step", REALS),
                           ("--max-steps", COUNTS), ("--time-limit", REALS),
                           ("--solver", SOLVERS)):
        if draw(st.integers(0, 2)) == 0:
            args += [option, draw(st.sampled_from(domain))]
    # (not the array size n: each new size is a new module, whose numba compilation
    # alone can outlast the per-case cap on a loaded machine)
    for name in draw(st.lists(st.sampled_from(["k", "x[1]", "h", "nope"]), max_size=2)):
        args += ["--set", f"{name}={draw(st.sampled_from(REALS + COUNTS))}"]
    if "--time-limit" not in args:
        args += ["--time-limit", "5"]
    if "--stop" not in args:
        args += ["--stop", "1"]
    rows = _rows(args)
    assume(not max_rows < rows <= 10_000_000)
    return args


SECONDS = 4 * SECONDS_PER_RUN
"""The per-case cap: a case may compile a solver kernel of springc.integrate first (numba,
tens of seconds on a loaded machine); a case past this is a hang."""


def _run(args: list[str], seconds: int = SECONDS) -> tuple[int, str]:
    with limits(seconds, 3 << 30):
        result = CliRunner().invoke(main, args, prog_name="springc", catch_exceptions=False,
                                    env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.output


def _check(code: int, output: str, args: list[str]) -> None:
    shown = " ".join(repr(a) for a in args)
    assert code in (0, 1, 2), f"exit {code} for {shown}:\n{output[-2000:]}"
    assert "Traceback" not in output and "internal error" not in output, (
        f"{shown}:\n{output[-2000:]}")


SETTINGS = settings(max_examples=EXAMPLES, derandomize=not RANDOM, deadline=None,
                    database=None, suppress_health_check=[
                        HealthCheck.too_slow, HealthCheck.filter_too_much,
                        HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("options") / "fuzzed.mo"
    path.write_text(MODEL)
    return path


@SETTINGS
@given(args=options(), event_rows=st.booleans())
def test_simulate_options_never_crash(model: Path, args: list[str],
                                      event_rows: bool) -> None:
    out = model.parent / "out.csv"
    full = ["simulate", str(model), "-q", "-o", str(out), *args] + (
        ["--event-rows"] if event_rows else [])
    code, output = _run(full)
    _check(code, output, full)


@settings(SETTINGS, max_examples=max(1, EXAMPLES // 3))
@given(args=options(max_rows=2_000), values=st.sampled_from(
    ["1,2", "0,nan", "-1e308,1e308", "1:3:2", "inf", "1e308:1e308:3", "abc"]))
def test_sweep_options_never_crash(model: Path, args: list[str], values: str) -> None:
    out = model.parent / "study.parquet"
    for stale in model.parent.glob("study*"):  # our own outputs of the last case
        shutil.rmtree(stale) if stale.is_dir() else stale.unlink()
    full = ["sweep", str(model), "-q", "--workers", "1", "--param", f"k={values}",
            "-o", str(out), *[a for a in args if a != "--event-rows"]]
    code, output = _run(full)
    _check(code, output, full)
