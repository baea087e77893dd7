"""A warm run imports only what it uses (docs/architecture.md, "Dependency rules").

``springc simulate`` of a model already in the cache loads the module and runs it: the
compile path (the parser and lark, the flattener, the unit check, simplify, codegen's
generator; pipeline.derive and pipeline.generation) and the libraries a small run never
needs (scipy.sparse, sympy, matplotlib) stay unloaded.
The test asserts which modules a fresh process holds after such a run, not a time.
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

import springc
from pendulum_text import PENDULUM

ROOT = Path(__file__).resolve().parents[1]
SEED = str(ROOT / "models" / "SpringMass.mdl")

FORBIDDEN = ("lark", "springc.flatten", "springc.units", "springc.simplify",
             "springc.codegen.generator", "springc.pipeline.derive",
             "springc.pipeline.generation", "scipy.sparse", "sympy", "matplotlib")
"""Packages (with their submodules) that a warm simulate of the seed must not import."""

PARSE_ALLOWED = {"springc.parse", "springc.parse.library", "springc.parse.lookups"}
"""Of ``springc.parse``, the face, the library file walk and the lookups record (the cache
key asks again what the compile read) load; the parser does not."""

WARM_RUN = """
import sys
from springc.cli import main
main(["simulate", sys.argv[1], "-o", sys.argv[2], "-q"], standalone_mode=False)
print("\\n".join(sorted(sys.modules)))
"""


def _loaded(name: str, modules: set[str]) -> list[str]:
    return sorted(m for m in modules if m == name or m.startswith(name + "."))


def test_a_warm_simulate_imports_no_compile_path(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    cache = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(cache))
    first = springc.compile_model(SEED)  # fills the cache as the CLI's run would
    assert not first.cached
    springc.simulate(first, stop=0.1)  # (and the C loop library, where a compiler is)
    out = tmp_path / "seed.csv"
    paths = [str(ROOT / "src"), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "SPRINGC_CACHE_DIR": str(cache), "PYTHONPATH": os.pathsep.join(paths)}
    run = subprocess.run([sys.executable, "-c", WARM_RUN, SEED, str(out)], env=env,
                         capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stderr
    modules = set(run.stdout.split())
    assert "springc.pipeline.compiler" in modules  # the run went through the pipeline
    assert {name: _loaded(name, modules) for name in FORBIDDEN} == \
        {name: [] for name in FORBIDDEN}
    assert set(_loaded("springc.parse", modules)) == PARSE_ALLOWED
    with out.open(newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0][:5] == ["time", "mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]"]
    assert [float(v) for v in rows[1][:5]] == [0.0, 1.0, -1.0, 0.0, 0.0]  # the start values



WARM_LOAD = """
import sys
import springc
model = springc.compile_model(sys.argv[1], backend="python")
derived = model.derive()
print(model.cached, model.run_system is not None, derived.flat_model.name,
      derived.switchable)
print("\\n".join(sorted(sys.modules)))
"""


def test_a_cached_model_with_a_captured_system_loads_without_the_compile_path(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cache = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(cache))
    path = tmp_path / "pendulum.mo"
    path.write_text(PENDULUM)
    first = springc.compile_model(str(path), backend="python")
    assert not first.cached and first.run_system is not None
    paths = [str(ROOT / "src"), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "SPRINGC_CACHE_DIR": str(cache), "PYTHONPATH": os.pathsep.join(paths)}
    run = subprocess.run([sys.executable, "-c", WARM_LOAD, str(path)], env=env,
                         capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stderr
    first_line, *names = run.stdout.splitlines()
    assert first_line == "True True Pendulum True"  # its equations from the captured system
    modules = set(names)
    assert {name: _loaded(name, modules) for name in FORBIDDEN} == \
        {name: [] for name in FORBIDDEN}
    assert set(_loaded("springc.parse", modules)) == PARSE_ALLOWED


LAUNCHED = """
import atexit, sys
atexit.register(lambda: print("\\n".join(sorted(sys.modules))))
from springc.launcher import main
main(["simulate", sys.argv[1], "-o", sys.argv[2], "-q"])
"""

REPLAY_FORBIDDEN = (*FORBIDDEN, "numpy", "numba", "scipy", "click", "springc.cli",
                    "springc.pipeline", "springc.codegen", "springc.api")
"""What a replayed run (:mod:`springc.launcher`) never imports: nothing beyond the
standard library, ctypes and springc's standard-library modules."""


def test_a_replayed_simulate_imports_neither_numpy_nor_click(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cache = tmp_path / "cache"
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(cache))
    out = tmp_path / "seed.csv"
    paths = [str(ROOT / "src"), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "SPRINGC_CACHE_DIR": str(cache), "PYTHONPATH": os.pathsep.join(paths),
           "SPRINGC_LOOP": "c"}  # the C loop (the suite's default is numba's)
    runs = [subprocess.run([sys.executable, "-c", LAUNCHED, SEED, str(out)], env=env,
                           capture_output=True, text=True, timeout=600, check=False)
            for _ in range(2)]  # the command line (it keeps the record), the replay
    assert [r.returncode for r in runs] == [0, 0], runs[0].stderr + runs[1].stderr
    first, replayed = (set(r.stdout.split()) for r in runs)
    assert {"numpy", "click"} <= first
    assert "springc.native.runner" in replayed  # the run was replayed on the C loop
    assert {name: _loaded(name, replayed) for name in REPLAY_FORBIDDEN} == \
        {name: [] for name in REPLAY_FORBIDDEN}
    with out.open(newline="") as f:
        rows = list(csv.reader(f))
    assert [float(v) for v in rows[1][:5]] == [0.0, 1.0, -1.0, 0.0, 0.0]  # the start values


WARM_CHECK = """
import sys
from springc.cli import main
main(["check", "-L", sys.argv[1], sys.argv[2], "-q"], standalone_mode=False)
print("\\n".join(sorted(sys.modules)))
"""


def test_a_warm_check_parses_nothing_and_imports_no_scipy(tmp_path: Path) -> None:
    """A check whose files a first check parsed reads their trees from the cache
    (``parse.parsed_store``): neither lark nor the parser load, and the balance check of
    a small model needs no scipy (issue 25: a warm check of an MSL example)."""
    lib = tmp_path / "lib" / "Lib"
    lib.mkdir(parents=True)
    (lib / "package.mo").write_text(
        "within;\npackage Lib\n  model Decay\n    parameter Real k = 2;\n"
        "    Real x(start = 1);\n  equation\n    der(x) = -k * x;\n  end Decay;\nend Lib;\n")
    user = tmp_path / "m.mo"
    user.write_text("model M\n  Lib.Decay d;\n  Real y = d.x;\nend M;\n")
    paths = [str(ROOT / "src"), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "SPRINGC_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join(paths)}
    runs = [subprocess.run([sys.executable, "-c", WARM_CHECK, str(tmp_path / "lib"),
                            str(user)], env=env, capture_output=True, text=True,
                           timeout=600, check=False) for _ in range(2)]
    assert [r.returncode for r in runs] == [0, 0], runs[1].stderr
    assert runs[1].stdout.split("\n")[0] == \
        "M: 2 unknowns, 2 equations, 1 parameter: balanced"
    cold, warm = (set(r.stdout.split("\n")[1:]) for r in runs)
    assert "springc.parse.parser" in cold
    assert [m for m in sorted(warm) if m == "lark" or m.startswith("lark.")
            or m == "springc.parse.parser" or m.startswith("scipy")] == []
    assert len(os.listdir(tmp_path / "cache" / "parsed")) == 2
