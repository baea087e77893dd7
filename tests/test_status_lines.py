"""Never silent: a step that compiles says so on stderr, once, unless --quiet.

Whether a step compiles is read from the disk (a model not in the cache, numba's cache
of a model's functions or of a kernel), never from the clock; the kernel check is
injected here rather than compiling a numba kernel in the test.
"""

from __future__ import annotations

import types
from pathlib import Path

import pytest
from click.testing import CliRunner

import springc.integrate
from springc.cli import main
from springc.pipeline.notes import announce_functions, functions_cached
from springc.simulation.compiled import load_kernel
from springc.status_line import silenced

MODEL = """model Decay
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
end Decay;
"""

COMPILING = "springc: compiling Decay for this machine (once; later runs load it from the cache)"


@pytest.fixture(autouse=True)
def _status_on(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_QUIET", raising=False)  # the suite silences them
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))


def _simulate(tmp_path: Path, *extra: str) -> list[str]:
    model = tmp_path / "Decay.mdl"
    model.write_text(MODEL)
    out = tmp_path / "out.csv"
    run = CliRunner().invoke(main, ["simulate", str(model), "--engine", "scipy", "--stop",
                                    "1", "-o", str(out), *extra])
    assert run.exit_code == 0, run.output
    rows = out.read_text().splitlines()
    assert abs(float(rows[-1].split(",")[1]) - 0.36787944) < 1e-4  # x(1) = exp(-1)
    return run.stderr.splitlines()


def test_a_model_not_in_the_cache_says_it_compiles_once(tmp_path: Path) -> None:
    first = _simulate(tmp_path)
    assert first[0] == COMPILING and len(first) == 2  # then the summary line
    again = _simulate(tmp_path)
    assert not any(line.startswith("springc: ") for line in again)


@pytest.mark.parametrize("no_cache", [[], ["--no-cache"]])
def test_no_status_line_before_a_syntax_error_or_a_file_without_a_model(
        tmp_path: Path, no_cache: list[str]) -> None:
    """The line says a model compiles: not said for files that hold none."""
    bad = tmp_path / "bad.mo"
    bad.write_text("model Bad\n  Real x\nend Bad;\n")
    run = CliRunner().invoke(main, ["simulate", str(bad), *no_cache])
    assert (run.exit_code, run.stderr.splitlines()[0]) == (
        1, f"{bad}:3:1: error: unexpected 'end', expected one of: ';', ',', '=', '(', "
        "'[', ...")
    empty = tmp_path / "empty.mo"
    empty.write_text("")
    run = CliRunner().invoke(main, ["simulate", str(empty), *no_cache])
    assert (run.exit_code, run.stderr) == (
        1, f"error: no model found in {empty}\n"
        "help: name a file that defines a model, or use --model\n")


def test_quiet_silences_the_status_line(tmp_path: Path) -> None:
    assert _simulate(tmp_path, "--quiet") == []


def test_without_a_cache_every_run_says_it_compiles(tmp_path: Path) -> None:
    assert _simulate(tmp_path, "--no-cache")[0] == \
        "springc: compiling Decay (not cached: every run compiles it)"


def test_a_kernel_without_numba_cache_says_it_compiles(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    loaded = []
    monkeypatch.setattr(springc.integrate, "load", loaded.append)  # no numba compile here
    load_kernel("radau", cached=lambda method: False)
    assert capsys.readouterr().err == ("springc: compiling the radau loop for this machine "
                                       "(once), about 25 s\n")
    load_kernel("radau", cached=lambda method: True)
    with silenced():
        load_kernel("bdf", cached=lambda method: False)
    assert capsys.readouterr().err == ""
    assert loaded == ["radau", "radau", "bdf"]


def test_numba_functions_are_cached_where_their_index_is(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    path = tmp_path / "entry" / "model.py"
    (path.parent / "__pycache__").mkdir(parents=True)
    numba_module = types.SimpleNamespace(BACKEND="numba")
    assert not functions_cached(numba_module, path)  # type: ignore[arg-type]
    assert functions_cached(types.SimpleNamespace(BACKEND="python"), path)  # type: ignore[arg-type]
    (path.parent / "__pycache__" / "model.rhs-129.py311.nbi").write_bytes(b"")
    assert functions_cached(numba_module, path)  # type: ignore[arg-type]
    # by name: the function's own index, or its body's where the module passes its
    # index table (``_observed_indexed``)
    assert functions_cached(numba_module, path, ["rhs"])  # type: ignore[arg-type]
    assert not functions_cached(numba_module, path, ["rhs", "observed"])  # type: ignore[arg-type]
    assert not functions_cached(numba_module, path, ["jacobian_values"])  # type: ignore[arg-type]
    (path.parent / "__pycache__" / "model._observed_indexed-80.py311.nbi").write_bytes(b"")
    assert functions_cached(numba_module, path, ["rhs", "observed"])  # type: ignore[arg-type]


def test_a_cached_module_whose_functions_numba_has_not_cached_says_so(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    path = tmp_path / "entry" / "model.py"
    (path.parent / "__pycache__").mkdir(parents=True)
    module = types.SimpleNamespace(BACKEND="numba", MODEL="Decay")
    announce_functions(module, path, cached=False)  # type: ignore[arg-type]
    assert capsys.readouterr().err == ""  # compiled just now: announced as a model
    announce_functions(module, path, cached=True)  # type: ignore[arg-type]
    assert capsys.readouterr().err == ("springc: compiling the functions of Decay for this "
                                       "machine (once)\n")
    announce_functions(module, path, cached=True)  # type: ignore[arg-type]
    assert capsys.readouterr().err == ""  # the probe's and the run's problems: one line
