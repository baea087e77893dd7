"""docs/language.md stays true: its examples flatten to exactly the text it shows, and
each construct it lists as not supported gives exactly the message it quotes."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from springc.cli import main

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "language.md").read_text()
EXAMPLE = re.compile(r"<!-- flatten(.*?) -->\n```modelica\n(.*?)```\n\n```text\n(.*?)```", re.S)


def run(tmp_path: Path, source: str, *args: str) -> tuple[int, str, str]:
    path = tmp_path / "example.mdl"
    path.write_text(source)
    result = CliRunner().invoke(main, [*args, str(path)], prog_name="springc",
                                env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    return result.exit_code, result.stdout, result.stderr


def test_the_document_has_its_examples() -> None:
    assert len(EXAMPLE.findall(DOC)) == 4


@pytest.mark.parametrize("options, source, flat", EXAMPLE.findall(DOC))
def test_each_example_flattens_to_the_text_shown(tmp_path: Path, options: str, source: str,
                                                 flat: str) -> None:
    assert run(tmp_path, source, "flatten", *shlex.split(options.lstrip(":"))) == (0, flat, "")


REJECTED = {
    "model M\n  Real x;\nequation\n  when time > 1 then\n    reinit(x, 0);\n  end when;\n"
    "  der(x) = 1;\nend M;\n": "4:3: error: `when` equations are not supported yet",
    "model M\n  Real x;\nequation\n  der(x) = pre(x);\nend M;\n":
        "4:12: error: `pre` is not supported yet",
    "model M\n  Real x;\nequation\n  der(x) = if x > 0 then -1 else 1;\nend M;\n":
        "4:15: error: relations on variables generate events, which are not supported yet",
    "model M\n  Real x;\nalgorithm\n  x := 1;\nend M;\n":
        "3:1: error: `algorithm` sections outside functions are not supported yet",
    "model M\n  String s = \"a\";\n  Real x = 1;\nend M;\n":
        "2:10: error: `String` variables are not supported yet",
    "model M\n  model W\n    Real g = 1;\n  end W;\n  inner outer W w;\nend M;\n":
        "5:9: error: `inner outer` elements are not supported yet",
    "model M\n  type E = enumeration(:);\n  Real x = 1;\nend M;\n":
        "2:12: error: unspecified enumerations `enumeration(:)` are not supported yet",
    "function f\n  input Real u;\n  output Real y;\nexternal \"C\";\nend f;\n"
    "model M\n  Real x = f(1);\nend M;\n":
        "4:1: error: `external` functions are not supported yet",
    "connector C\n  Real p;\n  flow Real f;\n  stream Real h;\nend C;\nmodel M\n  C c;\nend M;\n":
        "4:3: error: `stream` connectors are not supported yet",
    "function f\n  input Real u;\n  output Real y;\nalgorithm\n  y := u;\n  while y > 1 loop\n"
    "    y := y / 2;\n  end while;\nend f;\nmodel M\n  Real x = f(3);\nend M;\n":
        "6:3: error: `while` loops are not supported yet",
    "model M\n  Real x = .Modelica.Constants.pi;\nend M;\n":
        "2:12: error: global names (`.A.B`) are not supported yet",
    "model M\n  model extends N\n  end N;\nend M;\n": (
        "2:9: error: `class extends` definitions are not supported yet"),
    "operator record C\n  Real re;\nend C;\nmodel M\n  C c;\nend M;\n":
        "1:1: error: `operator` classes are not supported yet",
    "expandable connector C\n  Real x;\nend C;\nmodel M\n  C c;\nend M;\n":
        "1:1: error: `expandable` connectors are not supported yet",
    "model M\n  Real x := 1;\nend M;\n": "2:10: error: `:=` in a declaration is not supported yet",
    "model M\n  Real x;\nequation\n  terminate(\"stop\");\n  x = 1;\nend M;\n":
        "4:3: error: `terminate` is not supported yet as an equation",
}


@pytest.mark.parametrize("source, message", REJECTED.items())
def test_each_rejected_construct_gives_the_message_quoted(tmp_path: Path, source: str,
                                                          message: str) -> None:
    code, out, err = run(tmp_path, source, "check")
    assert (code, out) == (1, "")
    assert err.splitlines()[0] == f"{tmp_path / 'example.mdl'}:{message}"
    assert message.split("error: ")[1].replace("|", "\\|") in DOC


def test_discrete_unknowns_are_rejected_by_simulate(tmp_path: Path) -> None:
    source = "model M\n  discrete Real x;\nequation\n  x = 1;\nend M;\n"
    assert run(tmp_path, source, "check")[0] == 0
    code, _, err = run(tmp_path, source, "simulate")
    message = "discrete variables (Integer, Boolean or `discrete`) are not supported yet"
    assert (code, err.splitlines()[0]) == (1, f"{tmp_path / 'example.mdl'}:2:17: error: "
                                               + message)
    assert message in DOC


def test_the_depth_limit_in_the_document_is_the_one_enforced() -> None:
    from springc.ir import expr

    assert f"Expression depth: {expr.MAX_DEPTH:,} levels" in DOC
    assert f"(depth N, limit {expr.MAX_DEPTH})" in DOC
