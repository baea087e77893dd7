"""Bad ``when`` statements in algorithm sections (11.2.7, 12.2): each gives
file:line:col, the source line, a caret and help."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main

CASES = {
    "nested": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  discrete Real y;\n"
        "equation\n"
        "  der(x) = -x;\n"
        "algorithm\n"
        "  when x < 0.5 then\n"
        "    when x < 0.2 then\n"
        "      y := 1;\n"
        "    end when;\n"
        "  end when;\n"
        "end M;\n",
        "M.mo:8:5: error: a when statement is not allowed inside another when statement\n"
        "    8 |     when x < 0.2 then\n"
        "      |     ^^^^^^^^^^^^^^^^^\n"
        "help: combine the conditions ('when a and b then') or use elsewhen "
        "(Modelica 3.6, section 11.2.7)\n"),
    "in a for loop": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  discrete Real y[2];\n"
        "equation\n"
        "  der(x) = -x;\n"
        "algorithm\n"
        "  for i in 1:2 loop\n"
        "    when x < 0.5 then\n"
        "      y[i] := i;\n"
        "    end when;\n"
        "  end for;\n"
        "end M;\n",
        "M.mo:8:5: error: a when statement is not allowed inside a for loop\n"
        "    8 |     when x < 0.5 then\n"
        "      |     ^^^^^^^^^^^^^^^^^\n"
        "help: put the loop inside the when statement (Modelica 3.6, section 11.2.7)\n"),
    "in a variable if": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  discrete Real y;\n"
        "equation\n"
        "  der(x) = -x;\n"
        "algorithm\n"
        "  if x > 0.1 then\n"
        "    when x < 0.5 then\n"
        "      y := 1;\n"
        "    end when;\n"
        "  end if;\n"
        "end M;\n",
        "M.mo:8:5: error: a when statement is not allowed inside an if statement "
        "whose condition is known only during the simulation\n"
        "    8 |     when x < 0.5 then\n"
        "      |     ^^^^^^^^^^^^^^^^^\n"
        "help: put the if statement inside the when statement (Modelica 3.6, "
        "section 11.2.7)\n"),
    "in a function": (
        "model M\n"
        "  function f\n"
        "    input Real u;\n"
        "    output Real v;\n"
        "  algorithm\n"
        "    v := u;\n"
        "    when u > 1 then\n"
        "      v := 2;\n"
        "    end when;\n"
        "  end f;\n"
        "  Real x = f(time);\n"
        "end M;\n",
        "M.mo:7:5: error: a when statement is not allowed in a function\n"
        "    7 |     when u > 1 then\n"
        "      |     ^^^^^^^^^^^^^^^\n"
        "help: functions have no events: move the when statement to an algorithm "
        "section of a model (Modelica 3.6, section 12.2)\n"),
    "assigned outside too": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  Real y;\n"
        "equation\n"
        "  der(x) = -x;\n"
        "algorithm\n"
        "  y := x;\n"
        "  when x < 0.5 then\n"
        "    y := 1;\n"
        "  end when;\n"
        "end M;\n",
        "M.mo:9:5: error: 'y' is assigned both in a when statement and outside "
        "of it in this algorithm section\n"
        "    9 |     y := 1;\n"
        "      |     ^^^^^^\n"
        "help: a variable a when statement assigns is discrete: assign it only "
        "in when statements\n"),
    "assert on another condition": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  discrete Real y;\n"
        "equation\n"
        "  der(x) = -x;\n"
        "algorithm\n"
        "  when x < 0.5 then\n"
        "    assert(x > 0, \"positive\");\n"
        "    y := 1;\n"
        "  end when;\n"
        "end M;\n",
        "M.mo:8:5: error: `assert` inside a when statement is not supported yet, "
        "unless the condition is initial() or terminal()\n"
        "    8 |     assert(x > 0, \"positive\");\n"
        "      |     ^^^^^^^^^^^^^^^^^^^^^^^^^\n"
        "help: springc supports a subset of Modelica; see \"Not supported yet\" in "
        "docs/language.md\n"),
    "in an initial algorithm": (
        "model M\n"
        "  Real x(start = 1, fixed = true);\n"
        "  discrete Real y(start = 0, fixed = true);\n"
        "equation\n"
        "  der(x) = -x;\n"
        "initial algorithm\n"
        "  when x < 0.5 then\n"
        "    y := 1;\n"
        "  end when;\n"
        "end M;\n",
        "M.mo:7:3: error: a when statement is not allowed in an initial algorithm section\n"
        "    7 |   when x < 0.5 then\n"
        "      |   ^^^^^^^^^^^^^^^^^\n"
        "help: move it to the algorithm section (Modelica 3.6, section 11.2.7)\n"),
}


@pytest.mark.parametrize("name", CASES)
def test_bad_when_statement_is_located(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                       name: str) -> None:
    source, expected = CASES[name]
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    Path("M.mo").write_text(source)
    result = CliRunner().invoke(main, ["check", "M.mo"], prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    assert (result.exit_code, result.stderr) == (1, expected)
