"""springc.native.runner: a model's C loop library from its cache entry, run with the
standard library only (no numpy imported), giving the engine's values."""

from __future__ import annotations

import array
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.integrate import native_loop
from springc.native import LIBRARY_FILE, LoopLibrary, cached_library, runner
from springc.pipeline import c_library, loop_library

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
STDLIB_RUN = """
import array, json, sys
from pathlib import Path
from springc.native import LoopLibrary, cached_library
lib = LoopLibrary(cached_library(Path(sys.argv[1])))
p = lib.parameters({5: 400.0})  # spring.k
code, x0, z = lib.start(p)
grid = array.array("d", [0.05 * k for k in range(41)])
run = lib.run("dop853", grid, x0, p, z, rtol=1e-8, atol=1e-11)
row, obs = lib.observed(grid, run.states, p, z)
print(json.dumps({"status": run.status, "steps": run.accepted_steps, "row": row,
                  "names": lib.names("observed"), "states": list(run.states),
                  "observed": list(obs), "numpy": "numpy" in sys.modules}))
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def test_the_runner_runs_the_cached_library_without_numpy(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_LOOP", "c")  # the reference run below on the C loop too
    model = springc.compile_model(SEED, backend="python")
    loop_library(model)  # built into the entry
    entry = model.path.parent
    assert sorted(p.name for p in entry.iterdir() if p.name.startswith("cloop.")) == [
        "cloop.lock", "cloop.sha256", "cloop.so"]
    done = subprocess.run([sys.executable, "-c", STDLIB_RUN, str(entry)],
                          env={"PYTHONPATH": str(ROOT / "src")}, capture_output=True,
                          text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert (out["status"], out["row"], out["numpy"]) == (0, -1, False)
    assert out["names"] == ["spring.dir[1]", "spring.dir[2]", "spring.x"]
    reference = springc.simulate(model, solver="dop853", stop=2.0, interval=0.05,
                                 rtol=1e-8, atol=1e-11, parameters={"spring.k": 400.0},
                                 error_control="off")
    assert out["steps"] == reference.stats.steps
    states = np.array(out["states"]).reshape(41, 4)
    observed = np.array(out["observed"]).reshape(41, 3)
    expected = np.column_stack([reference[n] for n in model.states])
    np.testing.assert_allclose(states, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(observed, np.column_stack(
        [reference[n] for n in model.observed]), rtol=1e-12, atol=1e-12)


def test_a_damaged_library_is_not_loaded_and_is_built_again(
        capsys: pytest.CaptureFixture[str]) -> None:
    model = springc.compile_model(SEED, backend="python")
    loop_library(model)
    path = model.path.parent / LIBRARY_FILE
    original = path.read_bytes()
    path.write_bytes(b"planted")
    assert cached_library(model.path.parent) is None
    capsys.readouterr()
    lib = loop_library(model)
    assert capsys.readouterr().err == (f"note: {path} does not match its recorded hash; "
                                       "building it again\n")
    assert lib.n_states == 4 and path.read_bytes() == original  # one text, one build


def test_only_a_loop_library_loads_and_z_must_be_a_writable_buffer() -> None:
    assert runner.ABI == native_loop.ABI
    model = springc.compile_model(SEED, backend="python")
    with pytest.raises(runner.LibraryMismatch, match="is not a springc loop library"):
        c_model = c_library(model)  # the C model alone
        LoopLibrary(c_model.path.read_bytes())
    lib = loop_library(model)
    with pytest.raises(TypeError, match="z must be a writable contiguous buffer of 1 "):
        lib.run("dop853", [0.0, 1.0], [1, -1, 0, 0], lib.parameters(), (0.0,),
                rtol=1e-6, atol=1e-9)


def test_a_run_writes_its_rows_into_the_buffer_given_and_no_other_row() -> None:
    model = springc.compile_model(SEED, backend="python")
    lib = loop_library(model)
    p = lib.parameters()
    _, x0, z = lib.start(p)
    grid = np.linspace(0.0, 2.0, 41)
    alone = lib.run("dop853", grid, x0, p, array.array("d", z), rtol=1e-8, atol=1e-11)
    out = np.full((43, 4), np.nan)  # two rows more than the grid's
    into = lib.run("dop853", grid, x0, p, array.array("d", z), rtol=1e-8, atol=1e-11,
                   out=out)
    assert into.states is out and (into.filled, alone.filled) == (41, 41)
    assert (out[:41] == np.array(alone.states).reshape(41, 4)).all()  # the same code
    assert np.isnan(out[41:]).all()
    stopped = np.full((41, 4), np.nan)  # a run stopped by the step limit: its rows only
    short = lib.run("dop853", grid, x0, p, array.array("d", z), rtol=1e-8, atol=1e-11,
                    max_steps=20, out=stopped)
    assert short.status == runner.MAX_STEPS and 1 < short.filled < 41
    assert (stopped[:short.filled] == out[:short.filled]).all()
    assert np.isnan(stopped[short.filled:]).all()
    with pytest.raises(TypeError, match="out must be a writable contiguous buffer of 164 "):
        lib.run("dop853", grid, x0, p, array.array("d", z), rtol=1e-8, atol=1e-11,
                out=np.zeros((41, 4))[:, :2])
