"""A model not in the cache is compiled in a forked child (``pipeline.apart``): this
process derives nothing and loads the child's cache entry; a model in the cache forks
nothing; a model with an error raises the error of an in-process compile."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import SpringcError
from springc.pipeline import apart, generation
from springc.pipeline.closed import MODULE_PREFIX
from springc.pipeline.notes import functions_cached

MODEL = ("model Decay\n  parameter Real k = 2;\n  Real x(start = 3, fixed = true);\n"
         "equation\n  der(x) = -k*x;\nend Decay;\n")


def _derivations(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The models this process derives from now on (a forked child's are not seen)."""
    calls: list[str] = []
    derive = generation.derive_system

    def counted(options: springc.pipeline.CompileOptions,
                parsed: Callable[[], None] | None = None) -> springc.pipeline.Derived:
        calls.append(str(options.model))
        return derive(options, parsed)

    monkeypatch.setattr(generation, "derive_system", counted)
    return calls


@pytest.fixture
def decay(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "decay.mo"
    path.write_text(MODEL)
    return path


def test_a_missed_model_is_compiled_in_a_child_and_loaded_from_the_cache(
        decay: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _derivations(monkeypatch)
    model = apart.compiled_apart(lambda: springc.compile_model(str(decay), backend="python"))
    assert calls == []  # derived in the child only
    assert model.cached and model.states == ("x",)
    here = springc.compile_model(str(decay), backend="python", cache=False)
    assert calls == ["None"]
    assert model.source == here.source
    result = springc.simulate(model, stop=1.0, solver="dop853", rtol=1e-10, atol=1e-12)
    assert result["x"][-1] == pytest.approx(3 * np.exp(-2.0), rel=1e-8)


def test_a_cached_model_forks_nothing(decay: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    springc.compile_model(str(decay), backend="python")

    def no_fork() -> int:
        raise AssertionError("forked for a cached model")

    monkeypatch.setattr(os, "fork", no_fork)
    model = apart.compiled_apart(lambda: springc.compile_model(str(decay), backend="python"))
    assert model.cached and model.states == ("x",)


def test_the_error_of_a_model_is_the_in_process_one(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "bad.mo"
    path.write_text(MODEL.replace("-k*x", "-k*y"))
    with pytest.raises(SpringcError) as here:
        springc.compile_model(str(path), cache=False)
    calls = _derivations(monkeypatch)
    with pytest.raises(SpringcError) as apart_error:
        apart.compiled_apart(lambda: springc.compile_model(str(path)))
    assert calls == []  # the child's error, sent back: the model is not compiled again
    assert str(apart_error.value) == str(here.value)
    assert str(here.value) == (f"{path}:5:15: error: undefined name 'y'\n"
                               "    5 |   der(x) = -k*y;\n"
                               "      |               ^\n"
                               "help: declare it, or check the spelling")


def test_a_miss_under_cached_only_raises_and_keeps_no_module(
        decay: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _derivations(monkeypatch)
    before = {name for name in sys.modules if name.startswith(MODULE_PREFIX)}
    with apart.cached_only(), pytest.raises(apart.CacheMiss):
        springc.compile_model(str(decay), backend="python")
    assert calls == []
    assert {name for name in sys.modules if name.startswith(MODULE_PREFIX)} == before


def test_an_in_memory_stderr_compiles_here(decay: Path, monkeypatch: pytest.MonkeyPatch,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    calls = _derivations(monkeypatch)
    model = apart.compiled_apart(lambda: springc.compile_model(str(decay), backend="python"))
    assert not model.cached and calls == ["None"]


def test_an_interrupted_caller_ends_its_child(monkeypatch: pytest.MonkeyPatch) -> None:
    # Ctrl-C or SIGTERM while the child compiles: the child is killed and reaped, not
    # left compiling on its own
    forked: list[int] = []
    fork = os.fork

    def recorded() -> int:
        pid = fork()
        if pid:
            forked.append(pid)
        return pid

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "fork", recorded)
    monkeypatch.setattr(os, "fdopen", interrupted)
    with pytest.raises(KeyboardInterrupt):
        apart._child_status(lambda: time.sleep(600))
    (pid,) = forked
    with pytest.raises(ChildProcessError):  # reaped: no child of that id is left
        os.waitpid(pid, os.WNOHANG)


def _compiles(model: springc.pipeline.CompiledModel) -> dict[str, tuple[int, int]]:
    """(loads from numba's cache, compiles) in this process of each function of
    ``model``'s numba module that a run hands to the compiled loops."""
    counts = {}
    for name in (*apart.RUN_FUNCTIONS, *apart.JACOBIAN_FUNCTIONS):
        stats = getattr(model.module, name).stats
        counts[name] = (sum(stats.cache_hits.values()), sum(stats.cache_misses.values()))
    return counts


def test_the_functions_a_run_compiles_are_compiled_in_a_child(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capfd: pytest.CaptureFixture[str]) -> None:
    decay = tmp_path / "decay.mo"  # with an observed variable, v
    decay.write_text(MODEL.replace("fixed = true);", "fixed = true);\n  Real v;")
                     .replace("-k*x;", "v;\n  v = -k*x;"))

    def run(model: springc.pipeline.CompiledModel, solver: str = "dop853") -> float:
        result = springc.simulate(model, stop=1.0, solver=solver, engine="compiled",
                                  rtol=1e-10, atol=1e-12)
        assert result["v"][-1] == pytest.approx(-2 * result["x"][-1], rel=1e-12)
        return float(result["x"][-1])

    # the reference: a model whose functions this process compiles at the run
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "here"))
    here = springc.compile_model(str(decay), backend="numba")
    assert run(here) == pytest.approx(3 * np.exp(-2.0), rel=1e-8)
    assert _compiles(here) == {"rhs": (0, 1), "jacobian_values": (0, 0), "observed": (0, 1)}
    assert not apart.jacobian_apart(here.module)  # not given to functions_apart: here
    assert run(here, "radau") == pytest.approx(3 * np.exp(-2.0), rel=1e-8)
    assert _compiles(here)["jacobian_values"] == (0, 1)

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "apart"))
    model = apart.compiled_apart(lambda: springc.compile_model(str(decay), backend="numba"))
    assert model.cached and model.module.BACKEND == "numba"
    assert apart.functions_apart(model.module, model.path)  # the child compiled them
    assert run(model) == pytest.approx(3 * np.exp(-2.0), rel=1e-8)
    # each loaded from numba's cache, none compiled here; jacobian_values, which this
    # run does not call, was not compiled (by the child either: not in numba's cache)
    assert _compiles(model) == {"rhs": (1, 0), "jacobian_values": (0, 0), "observed": (1, 0)}
    assert not apart.functions_apart(model.module, model.path)  # cached: no child
    assert not functions_cached(model.module, model.path, apart.JACOBIAN_FUNCTIONS)
    # a run that needs the Jacobian: a child compiles it at the first use, saying so,
    # and this process loads it from numba's cache
    capfd.readouterr()
    monkeypatch.delenv("SPRINGC_QUIET", raising=False)  # (the suite silences them)
    assert run(model, "radau") == pytest.approx(3 * np.exp(-2.0), rel=1e-8)
    assert capfd.readouterr().err == ("springc: compiling the Jacobian of Decay for this "
                                      "machine (once)\n")
    assert _compiles(model) == {"rhs": (1, 0), "jacobian_values": (1, 0), "observed": (1, 0)}
    assert functions_cached(model.module, model.path, apart.JACOBIAN_FUNCTIONS)
    assert not apart.jacobian_apart(model.module)  # once per module
