"""The generated-module contract (``GeneratedModule``) and codegen's errors."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.codegen import MODULE_NAMES, CodegenBug, CodegenOptions, generate
from springc.errors import CodegenError, SimulationError, SpringcError
from springc.ir import ode
from springc.ir.expr import Var
from springc.pipeline import flatten_files
from springc.simplify import simplify

ROOT = Path(__file__).resolve().parents[2]
SCENES = str(ROOT / "models" / "Scenes.mdl")


def defined_names(source: str) -> set[str]:
    """Names a module's top level binds (assignments, functions, imports)."""
    names: set[str] = set()
    for stmt in ast.parse(source).body:
        if isinstance(stmt, ast.Assign):
            names |= {t.id for t in stmt.targets if isinstance(t, ast.Name)}
        elif isinstance(stmt, ast.FunctionDef):
            names.add(stmt.name)
    return names


@pytest.mark.parametrize("backend", ["python", "numba"])
@pytest.mark.parametrize(("model", "vector"), [("Scenes.Pendulum", False),
                                               ("Scenes.Chain", True)])
def test_generated_text_defines_the_contract(backend: str, model: str, vector: bool) -> None:
    flat_model = flatten_files([SCENES], model)
    system = simplify(flat_model).ode
    source = generate(system, flat_model, CodegenOptions(backend, vector=vector)).source
    public = {n for n in defined_names(source) if not n.startswith("_")}
    assert public == set(MODULE_NAMES)


def test_codegen_errors_are_springc_errors_not_simulation_errors() -> None:
    assert issubclass(CodegenError, SpringcError)
    assert not issubclass(CodegenError, SimulationError)
    system = simplify(flatten_files([SCENES], "Scenes.Oscillator")).ode
    with pytest.raises(CodegenError, match="unknown backend 'fortran'") as caught:
        generate(system, None, CodegenOptions("fortran"))
    assert caught.value.hint == "choose one of python, numba"


def test_a_broken_invariant_is_an_internal_error() -> None:
    """A simplified system that reads a name nothing computes is springc's bug: not a
    SpringcError (the CLI reports those as the user's), so the CLI exits 3."""
    system = simplify(flatten_files([SCENES], "Scenes.Oscillator")).ode
    first = system.steps[0]
    assert isinstance(first, ode.Assign)
    broken = dataclasses.replace(system, steps=(
        dataclasses.replace(first, expr=Var("nowhere")), *system.steps[1:]))
    with pytest.raises(CodegenBug, match="the simplified system reads 'nowhere' but "
                       "nothing computes it") as caught:
        generate(broken)
    assert not isinstance(caught.value, SpringcError)


def test_cli_reports_a_codegen_bug_with_exit_code_3(monkeypatch: pytest.MonkeyPatch,
                                                    tmp_path: Path) -> None:
    import springc.pipeline.generation as generation

    def broken(*args: object, **kwargs: object) -> object:
        raise CodegenBug("nothing computes der(x)")

    monkeypatch.setattr(generation, "generate", broken)
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    run = CliRunner().invoke(main, ["compile", SCENES, "--model", "Scenes.Oscillator"])
    assert run.exit_code == 3
    assert "internal error: CodegenBug: nothing computes der(x)" in run.output
