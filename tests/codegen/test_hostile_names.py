"""Model text is data: hostile names, units, descriptions and file names never run as
Python in a generated module (issue 10, item 1)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main

# Python that creates the marker file if it ever runs.
PAYLOAD = 'import os; open(os.environ["SPRINGC_TEST_MARKER"], "w").close()'
# Each breaks out of a docstring, a comment or a line, then runs PAYLOAD.
BREAKS = ['"""\n' + PAYLOAD + '\n"""', "\n" + PAYLOAD + "\n", "\r" + PAYLOAD + "\r",
          "\r\n" + PAYLOAD + "  #"]


def quoted(name: str) -> str:
    """``name`` as a Modelica quoted identifier (with Modelica's escapes)."""
    body = (name.replace("\\", "\\\\").replace("'", "\\'").replace("\n", "\\n")
            .replace("\r", "\\r"))
    return f"'{body}'"


def string(text: str) -> str:
    """``text`` as a Modelica string literal."""
    body = (text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
            .replace("\r", "\\r"))
    return f'"{body}"'


def hostile_model(index: int) -> tuple[str, dict[str, str]]:
    """A damped oscillator whose every name, unit and description carries a break."""
    brk = BREAKS[index]
    names = {"model": "M" + brk, "x": "x" + brk, "v": "v" + brk, "k": "k" + brk,
             "w": "w" + brk, "u": "_u = 1" + brk}
    x, v, k, w, u = (quoted(names[n]) for n in ("x", "v", "k", "w", "u"))
    unit, text = string("m" + brk), string("description" + brk)
    source = f"""model {quoted(names["model"])} {text}
  parameter Real {k}(unit = {unit}) = 4 {text};
  Real {x}(start = 1, fixed = true, unit = {unit}) {text};
  Real {v}(start = 0, fixed = true, unit = {unit}) {text};
  Real {u}(start = 0, fixed = true) {text};
  Real {w}(unit = {unit}) {text};
equation
  der({x}) = {v};
  der({v}) = -{k} * {x};
  der({u}) = 0;
  {w} = 2 * {x} + {u};
end {quoted(names["model"])};
"""
    return source, names


ALLOWED_IMPORTS = {"base64", "json", "math", "zlib", "numpy", "numba", "scipy.sparse"}


def assert_only_generated_code(source: str) -> None:
    """The module's statements are the generator's own: imports of its libraries,
    assignments and function definitions; no name ``os``, ``open`` or ``exec``."""
    tree = ast.parse(source)
    for stmt in tree.body:
        assert isinstance(stmt, (ast.Import, ast.ImportFrom, ast.Assign, ast.FunctionDef,
                                 ast.Expr)), ast.dump(stmt)[:200]
        if isinstance(stmt, ast.Expr):  # only the docstring
            assert stmt is tree.body[0] and isinstance(stmt.value, ast.Constant)
    imported = {a.name for s in ast.walk(tree) if isinstance(s, ast.Import) for a in s.names}
    imported |= {s.module or "" for s in ast.walk(tree) if isinstance(s, ast.ImportFrom)}
    assert imported <= ALLOWED_IMPORTS
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    assert not names & {"os", "open", "exec", "eval", "__import__"}


@pytest.mark.parametrize("backend", ["python", "numba"])
@pytest.mark.parametrize("index", range(len(BREAKS)))
def test_hostile_names_never_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                 backend: str, index: int) -> None:
    marker = tmp_path / "marker"
    monkeypatch.setenv("SPRINGC_TEST_MARKER", str(marker))
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    source, names = hostile_model(index)
    folder = tmp_path / "models"
    folder.mkdir()
    # The file name breaks out too (a file name may hold anything but '/' and NUL).
    path = folder / ('f"""\n' + PAYLOAD + '\n"""\r' + PAYLOAD + ".mdl")
    path.write_text(source, encoding="utf-8")

    compiled = springc.compile_model([path], backend=backend)  # imports the module
    assert_only_generated_code(compiled.source)
    assert not marker.exists()
    assert compiled.name == names["model"]
    assert set(compiled.states) == {names["x"], names["v"], names["u"]}
    assert compiled.module.STATE_UNITS[compiled.states.index(names["x"])] == "m" + BREAKS[
        index]

    # x'' = -4 x, x(0) = 1: x = cos(2 t); w = 2 x.
    result = springc.simulate(compiled, stop=1.0, interval=0.25, rtol=1e-10, atol=1e-12)
    assert not marker.exists()
    assert np.max(np.abs(result[names["x"]] - np.cos(2 * result.time))) < 1e-7
    assert np.max(np.abs(result[names["w"]] - 2 * np.cos(2 * result.time))) < 1e-7

    # The CLI's compile (fresh, not from the cache) writes the same safe module.
    out = tmp_path / "out.py"
    run = CliRunner().invoke(main, ["compile", str(path), "--backend", backend,
                                    "--no-cache", "-o", str(out)])
    assert run.exit_code == 0, run.output
    assert_only_generated_code(out.read_text(encoding="utf-8"))
    assert not marker.exists()


@pytest.mark.parametrize("command", ["compile", "simulate"])
def test_model_name_cannot_close_the_docstring(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch,
                                               command: str) -> None:
    # With the name alone hostile, the old module text was valid Python that ran PAYLOAD.
    marker = tmp_path / "marker"
    monkeypatch.setenv("SPRINGC_TEST_MARKER", str(marker))
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    name = quoted('M"""\n' + PAYLOAD + '\n"""')
    path = tmp_path / "m.mdl"
    path.write_text(f"model {name}\n  Real x(start = 1, fixed = true);\nequation\n"
                    f"  der(x) = -x;\nend {name};\n", encoding="utf-8")
    out = tmp_path / ("out.csv" if command == "simulate" else "out.py")
    run = CliRunner().invoke(main, [command, str(path), "-o", str(out)])
    assert run.exit_code == 0, run.output
    assert not marker.exists()
    if command == "compile":
        assert_only_generated_code(out.read_text(encoding="utf-8"))
    else:  # x = exp(-t)
        rows = [line.split(",") for line in out.read_text().splitlines()[1:]]
        assert max(abs(float(x) - np.exp(-float(t))) for t, x in rows) < 1e-4
