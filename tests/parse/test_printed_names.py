"""Names and source text in diagnostics are printed on one line each: a newline in a
quoted name cannot forge an ``error:`` line, and a U+2028 in a comment neither splits
the excerpt nor moves the caret off the text it marks."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from springc.cli import main
from springc.errors import Span, SpringcError, printable, render


def test_a_quoted_name_with_a_newline_cannot_forge_a_line(tmp_path: Path) -> None:
    path = tmp_path / "q.mo"
    path.write_text("package 'P\\nerror: forged line'\n  model M\n    Real x = 1;\n"
                    "  end M;\nend 'P\\nerror: forged line';\n")
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 1
    assert result.stderr == ("error: no model at the top level of the given files: their "
                             "models sit in packages (P\\nerror: forged line.M)\n"
                             "help: choose one by its dotted name, e.g. --model "
                             "P\\nerror: forged line.M\n")


def test_a_line_separator_is_escaped_and_the_caret_still_marks_the_name(
        tmp_path: Path) -> None:
    path = tmp_path / "w.mo"
    path.write_text("model W\n  Real x = 1; // a\u2028b\n  Real y = 2 /*\u2028\x07*/ + zz;\n"
                    "end W;\n", encoding="utf-8")
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 1
    assert result.stderr.splitlines()[:3] == [
        f"{path}:3:23: error: undefined name 'zz'",
        "    3 |   Real y = 2 /*\\u2028\\x07*/ + zz;",
        "      |                               ^^"]


def test_printable_escapes_every_line_breaking_character() -> None:
    assert printable("a\nb\rc\u2028d\u2029e\x85f\x1bg\th") == (
        "a\\nb\\rc\\u2028d\\u2029e\\x85f\\x1bg\\th")
    error = SpringcError("bad 'x\ny'", Span("f\nake.mo", 1, 1, 1, 2), hint="h\u2028i")
    assert render(error, lambda _: None) == "f\\nake.mo:1:1: error: bad 'x\\ny'\nhelp: h\\u2028i"


def test_the_summary_lines_escape_the_model_name(tmp_path: Path) -> None:
    path = tmp_path / "m.mo"
    path.write_text("model 'M\\nerror: forged'\n  Real x(start = 1);\nequation\n"
                    "  der(x) = -x;\nend 'M\\nerror: forged';\n")
    checked = CliRunner().invoke(main, ["check", str(path)])
    assert checked.stdout == ("'M\\nerror: forged': 1 unknown, 1 equation, 0 parameters: "
                              "balanced\n")
    run = CliRunner().invoke(main, ["simulate", str(path), "--stop", "0.1",
                                    "-o", str(tmp_path / "m.csv")])
    assert run.exit_code == 0, run.output
    assert run.stderr.startswith("M\\nerror: forged: ") and run.stderr.count("\n") == 1


def test_a_long_source_line_is_shown_around_the_caret() -> None:
    """A 1,000-column line shows 160 columns from 40 before the caret, cut with ..."""
    text = "x" * 500 + "BAD" + "y" * 497
    error = SpringcError("bad", Span("m.mo", 1, 501, 1, 504))
    assert render(error, lambda _: text).splitlines()[1:] == [
        "    1 | ..." + "x" * 40 + "BAD" + "y" * 117 + "...",
        "      | " + " " * 43 + "^^^"]
    short = SpringcError("bad", Span("m.mo", 1, 2, 1, 3))
    assert render(short, lambda _: "abc").splitlines()[1:] == ["    1 | abc", "      |  ^"]
