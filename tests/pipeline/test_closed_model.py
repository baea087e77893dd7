"""A compiled model is closed: its runs never read its source files again (issue 28).

Editing or deleting the files after compiling changes nothing in its runs, whether the
model was just generated or loaded from the cache; it pickles, and the unpickled model
runs in another process where the files do not exist.
"""

from __future__ import annotations

import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from pendulum_text import PENDULUM
from springc.errors import SimulationError
from springc.pipeline import CompiledModel
from springc.pipeline.cache import SYSTEM_FILE

DECAY = """model Decay
  Real x;
initial equation
  x = {start};
equation
  der(x) = -x;
end Decay;
"""

SRC = str(Path(springc.__file__).resolve().parents[1])


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(folder))
    return folder


def _decay(tmp_path: Path, start: float = 1.0) -> Path:
    path = tmp_path / "decay.mo"
    path.write_text(DECAY.format(start=start))
    return path


@pytest.mark.parametrize("cached", [False, True])
def test_editing_the_initial_equation_after_compiling_changes_nothing(
        tmp_path: Path, cache: Path, cached: bool) -> None:
    path = _decay(tmp_path)
    model = springc.compile_model(str(path), backend="python")
    if cached:  # the same model loaded from its verified cache entry
        model = springc.compile_model(str(path), backend="python")
        assert model.cached and (model.path.parent / SYSTEM_FILE).exists()
    path.write_text(DECAY.format(start=5.0))  # x = 1 -> x = 5
    result = springc.simulate(model, stop=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert result["x"][0] == 1.0
    assert abs(result["x"][-1] - np.exp(-1.0)) < 1e-8
    # The edited file is another model: compiled anew, it starts at 5.
    edited = springc.simulate(str(path), stop=1.0, interval=0.5, backend="python")
    assert edited["x"][0] == 5.0


def test_a_compiled_model_runs_with_its_source_deleted(tmp_path: Path, cache: Path) -> None:
    path = _decay(tmp_path, 2.0)
    model = springc.compile_model(str(path), backend="python")
    path.unlink()
    result = springc.simulate(model, stop=2.0, interval=1.0, rtol=1e-10, atol=1e-12)
    assert np.allclose(result["x"], 2.0 * np.exp(-result.time), rtol=1e-8, atol=0)
    with pytest.raises(SimulationError) as info:  # its equations are not those of no file
        model.equations()
    assert info.value.message == ("the files of Decay changed since it was compiled: its "
                                  "equations are no longer those of the files")


def _run_elsewhere(tmp_path: Path, model: CompiledModel, variable: str,
                   stop: float) -> np.ndarray:
    """``variable`` of the unpickled ``model`` simulated in a new Python process whose
    working folder and cache are empty (the files are deleted by then)."""
    pickled = tmp_path / "model.pickle"
    pickled.write_bytes(pickle.dumps(model))
    out = tmp_path / "values.npy"
    script = ("import pickle, sys, numpy, springc\n"
              "model = pickle.loads(open(sys.argv[1], 'rb').read())\n"
              f"r = springc.simulate(model, stop={stop}, interval=0.1, rtol=1e-10, "
              "atol=1e-12)\n"
              f"numpy.save(sys.argv[2], r[{variable!r}])\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {"PYTHONPATH": SRC, "SPRINGC_CACHE_DIR": str(elsewhere / "cache"),
           "PATH": "/usr/bin:/bin", "HOME": str(elsewhere)}
    done = subprocess.run([sys.executable, "-c", script, str(pickled), str(out)], cwd=elsewhere,
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return np.load(out)


def test_a_pickled_model_runs_in_another_process_without_its_source(
        tmp_path: Path, cache: Path) -> None:
    path = _decay(tmp_path, 3.0)
    model = springc.compile_model(str(path), backend="python")
    here = springc.simulate(model, stop=1.0, interval=0.1, rtol=1e-10, atol=1e-12)["x"]
    path.unlink()
    there = _run_elsewhere(tmp_path, model, "x", 1.0)
    assert np.allclose(there, 3.0 * np.exp(-np.linspace(0.0, 1.0, 11)), rtol=1e-8, atol=0)
    assert np.allclose(there, here, rtol=1e-12, atol=0)


def test_a_pickled_switching_model_runs_in_another_process_without_its_source(
        tmp_path: Path, cache: Path) -> None:
    path = tmp_path / "pendulum.mo"
    path.write_text(PENDULUM)
    model = springc.compile_model(str(path), backend="python")
    assert model.module.SWITCHABLE
    here = springc.simulate(model, stop=1.0, interval=0.1, rtol=1e-10, atol=1e-12)
    assert here.stats.reason.startswith("dynamic state selection, ")
    path.unlink()
    there = _run_elsewhere(tmp_path, model, "y", 1.0)
    assert np.allclose(there, here["y"], rtol=0, atol=1e-9)
    # The rod's length is kept (the constraint solved by each choice of states).
    assert np.allclose(here["x"] ** 2 + here["y"] ** 2, 1.0, rtol=0, atol=1e-9)


def test_a_damaged_system_record_is_regenerated(tmp_path: Path, cache: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    path = _decay(tmp_path, 4.0)
    first = springc.compile_model(str(path), backend="python")
    record = first.path.parent / SYSTEM_FILE
    record.write_bytes(record.read_bytes()[:-1])
    capsys.readouterr()
    again = springc.compile_model(str(path), backend="python")
    assert capsys.readouterr().err == (f"note: cache entry {first.path.parent} does not "
                                       "match its recorded hash; regenerating it\n")
    assert not again.cached and record.exists()
    assert springc.simulate(again, stop=1.0, interval=1.0)["x"][0] == 4.0


def test_a_sweep_in_worker_processes_runs_the_model_as_compiled(tmp_path: Path,
                                                                cache: Path) -> None:
    path = tmp_path / "rate.mo"
    path.write_text("model Rate\n  parameter Real k = 1;\n  Real x;\ninitial equation\n"
                    "  x = 2;\nequation\n  der(x) = -k*x;\nend Rate;\n")
    model = springc.compile_model(str(path), backend="python")
    path.write_text("model Rate\n  parameter Real k = 1;\n  Real x;\ninitial equation\n"
                    "  x = 7;\nequation\n  der(x) = -k*x;\nend Rate;\n")
    data = springc.sweep(model, params={"k": [1.0, 3.0]}, stop=1.0, interval=0.5,
                         rtol=1e-10, atol=1e-12, workers=2, solver="dop853")
    t = np.array([0.0, 0.5, 1.0])
    for run, k in enumerate((1.0, 3.0)):  # the workers never saw x = 7
        assert np.allclose(data["x"].values[run], 2.0 * np.exp(-k * t), rtol=1e-8, atol=0)


def test_a_structural_value_never_compiles_edited_files(tmp_path: Path, cache: Path) -> None:
    path = tmp_path / "arr.mo"
    text = ("model Arr\n  parameter Integer n = 2;\n  Real x[n](each start = {start});\n"
            "equation\n  der(x) = -x;\nend Arr;\n")
    path.write_text(text.format(start=1))
    model = springc.compile_model(str(path), backend="python")
    assert springc.simulate(model, parameters={"n": 3}, stop=1.0).names == (
        "x[1]", "x[2]", "x[3]")  # the files unchanged: compiled again with n = 3
    path.write_text(text.format(start=5))
    with pytest.raises(SimulationError) as info:
        springc.simulate(model, parameters={"n": 3}, stop=1.0)
    assert info.value.message == (
        "the files of Arr changed since it was compiled: a new value of the structural "
        "parameter 'n' would compile another model")
    assert springc.simulate(model, stop=1.0)["x[1]"][0] == 1.0  # itself: unchanged
