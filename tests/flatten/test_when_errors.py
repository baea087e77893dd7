"""Bad hybrid input: each gives file:line:col, the source line, a caret and help."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main

CASES = {
    "reinit outside when": (
        "model M\n  Real x(start = 1);\nequation\n  der(x) = -x;\n  reinit(x, 0);\nend M;\n",
        "check",
        "M.mo:5:3: error: reinit(...) is only allowed inside a when-clause\n"
        "    5 |   reinit(x, 0);\n"
        "      |   ^^^^^^^^^^^^\n"
        "help: write 'when condition then reinit(...); end when;'\n"),
    "when inside a variable if": (
        "model M\n  Real x(start = 1);\nequation\n  if x > 0 then\n    der(x) = -1;\n"
        "    when x < 0.5 then\n      reinit(x, 1);\n    end when;\n  else\n"
        "    der(x) = 1;\n  end if;\nend M;\n",
        "check",
        "M.mo:6:5: error: a when-equation cannot be inside an if-equation with a variable "
        "condition\n"
        "    6 |     when x < 0.5 then\n"
        "      |     ^^^^^^^^^^^^^^^^^\n"
        "help: put the when-equation outside the if-equation and its condition into the "
        "when's condition\n"),
    "pre of a continuous variable": (
        "model M\n  Real x(start = 1);\n  Real y;\nequation\n  der(x) = -x;\n  y = pre(x);\n"
        "end M;\n",
        "check",
        "M.mo:6:7: error: pre(x) of a continuous variable outside a when-clause\n"
        "    6 |   y = pre(x);\n"
        "      |       ^^^^^^\n"
        "M.mo:2:8: note: 'x' is declared here\n"
        "    2 |   Real x(start = 1);\n"
        "      |        ^^^^^^^^^^^^\n"
        "help: pre() gives the value before an event: use it inside a when-clause "
        "(reinit(v, -e*pre(v))), or make the variable discrete (assign it in a when-clause "
        "or declare it Integer, Boolean or discrete)\n"),
    "non-Boolean condition": (
        "model M\n  Real x(start = 1);\nequation\n  der(x) = -x;\n  when x - 0.5 then\n"
        "    reinit(x, 1);\n  end when;\nend M;\n",
        "check",
        "M.mo:5:8: error: the condition of a when-clause must be a Boolean expression\n"
        "    5 |   when x - 0.5 then\n"
        "      |        ^^^^^^^\n"
        "help: write a relation such as 'h <= 0', a Boolean variable, sample(start, "
        "interval) or initial()\n"),
    "Integer condition": (
        "model M\n  Real x(start = 1);\n  Integer n(start = 0);\nequation\n  der(x) = -x;\n"
        "  when n then\n    reinit(x, 1);\n  end when;\nend M;\n",
        "check",
        "M.mo:6:8: error: the condition of a when-clause must be Boolean, but 'n' is "
        "Integer\n"
        "    6 |   when n then\n"
        "      |        ^\n"
        "help: compare it, e.g. 'when x > 0 then'\n"),
    "nested when": (
        "model M\n  Real x(start = 1);\nequation\n  der(x) = -x;\n  when x < 0.5 then\n"
        "    when x < 0.2 then\n      reinit(x, 1);\n    end when;\n  end when;\nend M;\n",
        "check",
        "M.mo:6:5: error: when-equations cannot be nested\n"
        "    6 |     when x < 0.2 then\n"
        "      |     ^^^^^^^^^^^^^^^^^\n"
        "help: combine the conditions: 'when a and b then' or use elsewhen\n"),
    "reinit of a variable that is not a state": (
        "model M\n  Real x(start = 1);\n  Real y;\nequation\n  der(x) = -x;\n  y = 2 * x;\n"
        "  when x < 0.5 then\n    reinit(y, 1);\n  end when;\nend M;\n",
        "simulate",
        "M.mo:8:5: error: reinit(y, ...): 'y' is not a state of the simplified system\n"
        "    8 |     reinit(y, 1);\n"
        "      |     ^^^^^^^^^^^^\n"
        "note: the states are: x\n"
        "help: reinit a variable whose derivative appears in the equations (der(y)), or "
        "give it stateSelect = StateSelect.always\n"),
    "unbalanced branches of a variable if": (
        "model M\n  Real x(start = 1);\n  Real y;\nequation\n  der(x) = -x;\n"
        "  if x > 0.5 then\n    y = 1;\n  else\n  end if;\nend M;\n",
        "check",
        "M.mo:6:3: error: the branches of an if-equation with a variable condition must "
        "have the same number of equations (found 1, 0)\n"
        "    6 |   if x > 0.5 then\n"
        "      |   ^^^^^^^^^^^^^^^\n"
        "note: the condition depends on variables, so the branch switches during the "
        "simulation\n"
        "help: give every branch, including 'else', one equation for each variable the "
        "if-equation determines\n"),
    "assert inside when": (
        "model M\n  Real x(start = 1);\nequation\n  der(x) = -x;\n"
        "  when x < 0.5 then\n    assert(x > 0, \"x stays positive\");\n  end when;\n"
        "end M;\n",
        "check",
        "M.mo:6:5: error: `assert` inside a when-clause is not supported yet, unless the "
        "condition is initial() or terminal()\n"
        "    6 |     assert(x > 0, \"x stays positive\");\n"
        "      |     ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^\n"
        "help: springc supports a subset of Modelica; see \"Not supported yet\" in "
        "docs/language.md\n"),    "sample with a negative interval": (
        "model M\n  parameter Real T = -0.5;\n  discrete Real y(start = 0);\nequation\n"
        "  when sample(0, 2*T) then\n    y = pre(y) + 1;\n  end when;\nend M;\n",
        "check",
        "M.mo:5:18: error: the interval of sample(start, interval) must be positive, "
        "found -1\n"
        "    5 |   when sample(0, 2*T) then\n"
        "      |                  ^^^\n"
        "help: sample(start, interval) is true at start, start + interval, start + "
        "2*interval... (Modelica 3.6, section 3.7.5)\n"),
    "sample with a zero interval": (
        "model M\n  discrete Real y(start = 0);\nequation\n"
        "  when sample(0, 0) then\n    y = pre(y) + 1;\n  end when;\nend M;\n",
        "check",
        "M.mo:4:18: error: the interval of sample(start, interval) must be positive, "
        "found 0\n"
        "    4 |   when sample(0, 0) then\n"
        "      |                  ^\n"
        "help: sample(start, interval) is true at start, start + interval, start + "
        "2*interval... (Modelica 3.6, section 3.7.5)\n"),
    "sample interval 0/0": (
        "model M\n  discrete Real y(start = 0);\nequation\n"
        "  when sample(1, 0/0) then\n    y = pre(y) + 1;\n  end when;\nend M;\n",
        "check",
        "M.mo:4:18: error: cannot evaluate the interval of sample(start, interval): "
        "division by zero\n"
        "    4 |   when sample(1, 0/0) then\n"
        "      |                  ^^^\n"),
}


@pytest.mark.parametrize("name", CASES)
def test_bad_hybrid_input_is_located(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                     name: str) -> None:
    source, command, expected = CASES[name]
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    Path("M.mo").write_text(source)
    result = CliRunner().invoke(main, [command, "M.mo"], prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    assert (result.exit_code, result.stderr) == (1, expected)


def test_a_sample_interval_set_to_zero_for_a_run_is_located(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A parameter interval is checked when the model is flattened with its own value,
    and by an assertion in the flat model when a run sets another (``--set T=0``)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    Path("M.mo").write_text("model M\n  parameter Real T = 0.5;\n  discrete Real y(start = 0);"
                            "\nequation\n  when sample(0, 2*T) then\n    y = pre(y) + 1;\n"
                            "  end when;\nend M;\n")
    result = CliRunner().invoke(main, ["simulate", "M.mo", "--set", "T=0"],
                                prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    assert (result.exit_code, result.stderr) == (1, (
        "M.mo:5:18: error: assertion failed before the simulation started: the interval "
        "of sample(start, interval) must be positive: 2 * T <= 0\n"
        "    5 |   when sample(0, 2*T) then\n"
        "      |                  ^^^\n"
        "help: the model left the range its author allowed; check the parameters (--set) "
        "and start values\n"))
