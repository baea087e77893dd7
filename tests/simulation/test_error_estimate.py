"""The estimated global error (``error_control="warn"``: estimated, never tightened)
against the true error (a run at rtol 1e-13), the Richardson estimate of the fixed-step
solvers, the API attribute, the deprecated ``error_estimate`` and the CSV side file."""

from __future__ import annotations

import csv
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.errors import UsageError
from springc.pipeline import CompiledModel
from springc.simulation.error_control import short

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
MODELS = {"seed": (SEED, None), "chain": (SCENES, "Scenes.Chain"),
          "pendulum": (SCENES, "Scenes.Pendulum")}


@cache
def model(name: str) -> CompiledModel:
    files, model_name = MODELS[name]
    return springc.compile_model(files, model_name, backend="numba")


@cache
def reference(name: str) -> springc.SimulationResult:
    return springc.simulate(model(name), solver="dop853", rtol=1e-13, atol=1e-16,
                            error_control="off")


def true_relative_error(result: springc.SimulationResult, ref: springc.SimulationResult
                        ) -> np.ndarray:
    """Per variable: max |x - x_ref| over the grid / max |x| (the estimate's measure)."""
    columns = [result.names.index(s) for s in result.error_estimate.names]
    values = result.values[:, columns]
    error = np.abs(values - ref.values[:, columns]).max(axis=0)
    magnitude = np.abs(values).max(axis=0)
    return error / np.where(magnitude > 0, magnitude, 1.0)


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("rtol", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9])
def test_estimate_is_within_a_factor_3_of_the_true_error(name: str, rtol: float) -> None:
    result = springc.simulate(model(name), solver="dop853", rtol=rtol, error_control="warn")
    estimate = result.error_estimate
    assert estimate is not None
    true = true_relative_error(result, reference(name))
    assert 1 / 3 <= estimate.error / true.max() <= 3
    # every state whose error stands above the reference's own (1e-11) is within 3x too
    above = true > 1e-11
    assert (np.abs(np.log(estimate.relative[above] / true[above])) <= np.log(3)).all()


@pytest.mark.parametrize("solver, step", [("rk4", 2e-3), ("verlet", 2e-4)])
def test_richardson_estimate_of_the_fixed_step_solvers(solver: str, step: float) -> None:
    result = springc.simulate(model("seed"), solver=solver, step=step, error_control="warn")
    estimate = result.error_estimate
    assert estimate is not None and estimate.method.startswith(f"Richardson against {solver}")
    true = true_relative_error(result, reference("seed"))
    assert 1 / 3 <= estimate.error / true.max() <= 3


@dataclass
class _Blocks:
    """A deferred result's outputs, read ``rows`` rows at a time."""

    values: np.ndarray
    rows: int

    def blocks(self):
        for begin in range(0, len(self.values), self.rows):
            yield self.values[begin:begin + self.rows]


@dataclass
class _Run:
    """What :func:`error_estimate.compare` reads of a run."""

    time: np.ndarray
    names: tuple[str, ...]
    values: np.ndarray
    events: tuple[()] = ()
    deferred: _Blocks | None = None

def test_api_attribute_summary_and_off() -> None:
    on = springc.simulate(model("seed"), solver="dop853", error_control="warn")
    off = springc.simulate(model("seed"), solver="dop853", error_control="off")
    estimate = on.error_estimate
    assert estimate is not None and off.error_estimate is None
    assert estimate.names == model("seed").outputs  # every output, observed ones too
    assert estimate.tolerance is not None
    # the rule: 10 * (rtol * the variable's largest magnitude + atol), rtol 1e-6, atol 1e-9
    np.testing.assert_allclose(estimate.tolerance,
                               10 * (1e-6 * np.abs(on.values).max(axis=0) + 1e-9), rtol=1e-12)
    i = estimate.worst
    ratio = estimate.absolute / estimate.tolerance
    assert ratio[i] == ratio.max() > 1  # dop853 at rtol 1e-6 misses it on the seed
    assert on.stats.summary("S").endswith(
        f"; est. error {short(estimate.absolute[i])} > tolerance "
        f"{short(estimate.tolerance[i])} ({estimate.names[i]} at t = "
        f"{estimate.times[i]:.4g} s; companion dop853 at rtol 1e-9, {estimate.seconds:.3f} s)")
    assert on.stats.estimated_error == estimate.absolute[i]
    assert on.stats.error_tolerance == estimate.tolerance[i]
    assert on.stats.rtol == 1e-6 and on.stats.atol == pytest.approx(1e-9, rel=1e-12)
    assert "est. error" not in off.stats.summary("S") and off.stats.estimated_error is None
    np.testing.assert_array_equal(on.values, off.values)  # the run itself is unchanged


def test_bad_mode_names_the_option() -> None:
    with pytest.raises(UsageError, match=r"^error: error_control must be one of tighten, "
                                         r"warn, off, not 'sometimes'$"):
        springc.simulate(model("seed"), error_control="sometimes")
    with pytest.raises(UsageError, match=r"^error: error_estimate must be one of off, on, "
                                         r"auto, not 'sometimes'$"):
        springc.simulate(model("seed"), error_estimate="sometimes")
    for option in ("--error-control", "--error-estimate"):
        result = CliRunner().invoke(main, ["simulate", SEED, option, "sometimes"])
        assert result.exit_code == 2
        assert f"Invalid value for '{option}': 'sometimes' is not one of" in result.stderr


def test_deprecated_error_estimate_maps_to_error_control() -> None:
    with pytest.warns(DeprecationWarning, match="^error_estimate is deprecated: "
                      "error_estimate on is error_control warn$"):
        on = springc.simulate(model("seed"), solver="dop853", error_estimate="on")
    warned = springc.simulate(model("seed"), solver="dop853", error_control="warn")
    assert on.stats.rtol == warned.stats.rtol == 1e-6  # estimated, not tightened
    assert on.error_estimate is not None and warned.error_estimate is not None
    np.testing.assert_allclose(on.error_estimate.absolute, warned.error_estimate.absolute,
                               rtol=1e-12)
    with pytest.warns(DeprecationWarning, match="error_estimate auto is error_control "
                      "tighten$"):
        auto = springc.simulate(model("seed"), solver="dop853", error_estimate="auto")
    assert auto.stats.rtol == 1e-9
    with pytest.raises(UsageError, match=r"^error: error_estimate is deprecated and cannot be "
                       r"combined with error_control: use error_control alone$"):
        springc.simulate(model("seed"), error_estimate="off", error_control="off")
    result = CliRunner().invoke(main, ["simulate", SEED, "--stop", "0.1", "-q",
                                       "--error-estimate", "off"])
    assert result.exit_code == 0
    assert result.stderr == ("warning: --error-estimate is deprecated: --error-estimate off "
                             "is --error-control off\n")


def test_error_output_table_and_unchanged_csv(tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    result = CliRunner().invoke(main, ["simulate", SEED, "--backend", "numba", "--solver",
                                       "dop853", "--error-control", "warn", "-o", str(out),
                                       "--error-output", str(tmp_path / "errors.csv"), "-v"])
    assert result.exit_code == 0, result.output
    assert "; est. error " in result.stderr
    with out.open() as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time", *model("seed").outputs]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["errors.csv", "run.csv"]
    with (tmp_path / "errors.csv").open() as f:
        side = list(csv.reader(f))
    assert side[0] == ["variable", "max_abs_error", "relative_error", "at_time", "method",
                       "tolerance"]
    assert [row[0] for row in side[1:]] == list(model("seed").outputs)
    table = np.array([[float(v) for v in row[1:4]] + [float(row[5])] for row in side[1:]])
    values = np.array([[float(v) for v in row] for row in rows[1:]])
    # relative = absolute / the variable's largest magnitude in the trajectory written
    magnitude = np.abs(values[:, 1:]).max(axis=0)
    np.testing.assert_allclose(table[:, 1], table[:, 0] / magnitude, rtol=1e-12)
    np.testing.assert_allclose(table[:, 3], 10 * (1e-6 * magnitude + 1e-9), rtol=1e-12)
    assert all(row[4] == "companion dop853 at rtol 1e-9" for row in side[1:])
    off = tmp_path / "off.csv"
    CliRunner().invoke(main, ["simulate", SEED, "--error-control", "off", "-o", str(off)])
    assert off.exists() and not (tmp_path / "off.error.csv").exists()
    refused = CliRunner().invoke(main, ["simulate", SEED, "--error-control", "off",
                                        "--error-output", str(tmp_path / "none.csv")])
    assert refused.exit_code == 2 and refused.stderr.endswith(
        "Error: --error-output needs an error estimate, which --error-control off turns "
        "off\n")
    assert not (tmp_path / "none.csv").exists()


def test_the_estimate_compares_a_few_columns_at_a_time(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The differences of two runs are taken COLUMNS_PER_PASS columns at a time (a large
    scene never holds a copy of both runs): the same largest errors, their rows and the
    scales as the whole arrays at once, the companion's columns in the run's order."""
    from springc.simulation import error_estimate

    rng = np.random.default_rng(7)
    grid = np.linspace(0.0, 1.0, 6)
    ours = rng.normal(size=(6, 5))
    theirs = rng.normal(size=(6, 5))
    names = ("a", "b", "c", "d", "e")
    order = [3, 0, 4, 1, 2]  # the companion's columns: d a e b c
    run = _Run(grid, names, ours)
    companion = _Run(grid, tuple(names[j] for j in order), theirs[:, order])
    monkeypatch.setattr(error_estimate, "COLUMNS_PER_PASS", 2)
    estimate = error_estimate.compare(run, companion, grid, "test", 2.0, 0.0)
    error = np.abs((ours - theirs) * 2.0)
    assert estimate.names == names
    assert (estimate.absolute == error.max(axis=0)).all()
    assert (estimate.times == grid[error.argmax(axis=0)]).all()
    assert (estimate.scales == np.abs(ours).max(axis=0)).all()


def test_a_deferred_companion_is_compared_block_by_block(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A companion whose outputs are read block by block (``deferred``: error control's
    companion of a large scene) gives the estimate of its whole array, bit for bit:
    ties keep the first row, a NaN wins as ``max`` and ``argmax`` take it."""
    from springc.simulation import error_estimate

    grid = np.linspace(0.0, 1.0, 9)
    ours = np.zeros((9, 4))
    theirs = np.zeros((9, 4))
    theirs[[2, 6], 0] = 1.0  # a tie: row 2 is the largest error's
    theirs[[1, 7], 1] = [1.0, 3.0]  # in a later block
    theirs[[3, 5], 2] = [2.0, np.nan]  # NaN after a larger value: NaN, at row 5
    ours[:, 3] = np.arange(9.0)
    names = ("a", "b", "c", "d")
    whole = error_estimate.compare(_Run(grid, names, ours), _Run(grid, names, theirs),
                                   grid, "test", 2.0, 0.0)
    for rows in (1, 2, 4, 9):
        streamed = error_estimate.compare(
            _Run(grid, names, ours),
            _Run(grid, names, theirs[:, :0], deferred=_Blocks(theirs, rows)), grid, "test",
            2.0, 0.0)
        for field in ("absolute", "relative", "times", "scales"):
            np.testing.assert_array_equal(getattr(streamed, field), getattr(whole, field))
    assert whole.absolute[:2].tolist() == [2.0, 6.0] and np.isnan(whole.absolute[2])
    assert whole.times.tolist() == [grid[2], grid[7], grid[5], grid[8]]


def test_error_controls_companion_defers_its_outputs(monkeypatch: pytest.MonkeyPatch
                                                    ) -> None:
    """A continuous run asked for deferred outputs (error control's companion) returns
    its states and computes the same outputs block by block, or all at once when it
    becomes the answer; the estimate from its blocks is the one from its whole array."""
    from dataclasses import replace

    from springc.simulation import continuous, error_estimate
    from springc.simulation.runner import simulate_once
    from springc.simulation.settings import RunSettings

    monkeypatch.setattr(continuous, "BLOCK_ROWS", 7)
    chain = model("chain")
    answer = simulate_once(chain, RunSettings(solver="dop853", rtol=1e-5, atol=1e-8,
                                              error_control="off"))
    settings = RunSettings(solver="dop853", rtol=1e-8, atol=1e-11, error_control="off")
    whole = simulate_once(chain, settings)
    deferred = simulate_once(chain, replace(settings, deferred_outputs=True))
    assert whole.deferred is None and deferred.deferred is not None
    assert deferred.values.shape == (len(whole.time), 0) and len(chain.observed) > 0
    np.testing.assert_array_equal(deferred.deferred.values(), whole.values)
    blocks = list(deferred.deferred.blocks())
    assert [len(b) for b in blocks[:2]] == [7, 7]
    np.testing.assert_array_equal(np.vstack(blocks), whole.values)
    first = error_estimate.compare(answer, whole, whole.time, "how", 1.0, 0.0)
    second = error_estimate.compare(answer, deferred, deferred.time, "how", 1.0, 0.0)
    assert first.absolute.max() > 0
    for field in ("absolute", "relative", "times", "scales"):
        np.testing.assert_array_equal(getattr(second, field), getattr(first, field))
