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
    assert len(EXAMPLE.findall(DOC)) == 6


@pytest.mark.parametrize("options, source, flat", EXAMPLE.findall(DOC))
def test_each_example_flattens_to_the_text_shown(tmp_path: Path, options: str, source: str,
                                                 flat: str) -> None:
    assert run(tmp_path, source, "flatten", *shlex.split(options.lstrip(":"))) == (0, flat, "")


REJECTED = {
    "model M\n  discrete String s;\n  Boolean b;\nequation\n  when sample(0, 1) then\n"
    "    s = \"a\";\n  end when;\n  b = s == \"a\";\nend M;\n":
        "8:7: error: reading the discrete String 's' (assigned in a when-clause) is not "
        "supported yet",
    "model M\n  Real x = 1;\n  Real y = if Connections.isRoot(x) then 1 else 0;\nend M;\n":
        "3:15: error: `Connections.isRoot` is supported only in the conditions of "
        "if-equations",
    "model M\n  function f\n    input Real x;\n    output Real y;\n  algorithm\n    y := x;\n"
    "  end f;\n  function f2 = f(x(start = 3));\n  Real y = f2(1);\nend M;\n":
        "8:19: error: only values of inputs may modify a function (`x`)",
    "model M\n  String s;\nequation\n  s = String(time);\nend M;\n":
        "4:14: error: 'String' of a value that changes during the simulation is not "
        "supported yet: it depends on time",
    "function f\n  input Real u;\n  output Real y;\nexternal \"C\";\nend f;\n"
    "model M\n  Real x = f(1);\nend M;\n":
        "7:12: error: the external function 'f' (C function 'f') is not supported: its "
        "library does not ship its C sources",
    "connector C\n  Real p;\n  flow Real f;\n  stream Real h;\nend C;\nmodel M\n  C c;\nend M;\n":
        "4:3: error: `stream` connectors are not supported yet",
    "function f\n  input Real u;\n  output Real y;\nalgorithm\n  y := u;\n"
    "  while noEvent(y > 1) loop\n    y := y / 2;\n  end while;\nend f;\nmodel M\n"
    "  Real x = f(time);\nend M;\n":
        "6:9: error: `while` loops whose condition is known only during the simulation are "
        "not supported yet",
    "operator record C\n  Real re;\nend C;\nmodel M\n  C c;\nend M;\n":
        "1:1: error: `operator` classes are not supported yet",
    "connector RO = output Real;\nexpandable connector C\n  Real y;\nend C;\nmodel M\n"
    "  RO s = time;\n  C bus;\nequation\n  connect(s, bus.x[2]);\nend M;\n":
        "9:18: error: adding 'x' to the expandable connector 'bus' (C) by a connection is "
        "not supported yet",
    "model M\n  Real x := 1;\nend M;\n": "2:10: error: `:=` in a declaration is not supported yet",
}


@pytest.mark.parametrize("source, message", REJECTED.items())
def test_each_rejected_construct_gives_the_message_quoted(tmp_path: Path, source: str,
                                                          message: str) -> None:
    code, out, err = run(tmp_path, source, "check")
    assert (code, out) == (1, "")
    assert err.splitlines()[0] == f"{tmp_path / 'example.mdl'}:{message}"
    assert message.split("error: ")[1].replace("|", "\\|") in DOC


def test_the_depth_limit_in_the_document_is_the_one_enforced() -> None:
    from springc.ir import expr

    assert f"Expression depth: {expr.MAX_DEPTH:,} levels" in DOC
    assert f"(depth N, limit {expr.MAX_DEPTH})" in DOC
