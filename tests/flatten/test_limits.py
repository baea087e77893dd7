"""The flat-size and loop caps (springc.flatten.scopes.limits): exact boundaries, and the two ways
to set the cap (the ``max_size`` keyword of ``flatten``, ``$SPRINGC_MAX_SIZE``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import ErrorGroup, FlattenError
from springc.flatten import flatten
from springc.ir.nodes import Const
from springc.parse import load

# 2 scalars in `a`, an array of 3 components, 1 scalar in each (8 elements in all), and a
# loop of 4 iterations.
SOURCE = """
model Cell
  Real y;
equation
  y = 1;
end Cell;
model M
  Real a[2];
  Cell c[3];
equation
  for i in 1:4 loop
    a[1] = i;
  end for;
  a[2] = 0;
end M;
"""


@pytest.fixture
def tree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):  # type: ignore[no-untyped-def]
    monkeypatch.delenv("SPRINGC_PATH", raising=False)
    monkeypatch.delenv("SPRINGC_MAX_SIZE", raising=False)
    path = tmp_path / "m.mdl"
    path.write_text(SOURCE)
    return load([path])


def test_a_model_at_the_cap_flattens(tree) -> None:  # type: ignore[no-untyped-def]
    model = flatten(tree, "M", max_size=8)
    assert [v.name for v in model.variables] == ["a[1]", "a[2]", "c[1].y", "c[2].y",
                                                 "c[3].y"]


def test_one_element_past_the_cap_is_refused_at_the_declaration(tree) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(FlattenError) as err:
        flatten(tree, "M", max_size=7)
    assert err.value.message == ("the flat model has more than 7 scalar variables and "
                                 "components (this declaration crosses the limit)")
    assert err.value.span is not None and (err.value.span.line, err.value.span.column) \
        == (9, 8)  # Cell c[3]: c[3] crosses it


def test_the_environment_variable_sets_the_cap(tree, monkeypatch: pytest.MonkeyPatch  # type: ignore[no-untyped-def]
                                               ) -> None:
    monkeypatch.setenv("SPRINGC_MAX_SIZE", "3")
    with pytest.raises(ErrorGroup) as group:
        flatten(tree, "M")
    assert [e.message for e in group.value.errors] == [
        "the flat model has more than 3 scalar variables and components (this declaration "
        "crosses the limit)", "this range has 4 elements, more than the limit of 3"]
    monkeypatch.setenv("SPRINGC_MAX_SIZE", "8")
    assert len(flatten(tree, "M").variables) == 5


def test_a_bad_environment_value_is_named(tree, monkeypatch: pytest.MonkeyPatch  # type: ignore[no-untyped-def]
                                          ) -> None:
    monkeypatch.setenv("SPRINGC_MAX_SIZE", "lots")
    with pytest.raises(FlattenError) as err:
        flatten(tree, "M")
    assert err.value.message == "SPRINGC_MAX_SIZE must be a positive integer, found 'lots'"


def test_loop_iterations_count_against_the_cap(tmp_path: Path) -> None:
    path = tmp_path / "loops.mdl"
    path.write_text("model L\n  Real a;\nequation\n  for i in 1:4 loop\n    a = i;\n"
                    "  end for;\nend L;\n")
    tree = load([path])
    assert len(flatten(tree, "L", max_size=4).equations) == 4
    with pytest.raises(FlattenError) as err:
        flatten(tree, "L", max_size=3)
    assert err.value.message == "this range has 4 elements, more than the limit of 3"


def test_loops_below_the_cap_one_by_one_are_counted_together(tmp_path: Path) -> None:
    path = tmp_path / "two.mdl"
    path.write_text("model T\n  Real a;\n  Real b;\nequation\n  for i in 1:3 loop\n    a = i;\n"
                    "  end for;\n  for j in 1:3 loop\n    b = j;\n  end for;\nend T;\n")
    tree = load([path])
    assert len(flatten(tree, "T", max_size=6).equations) == 6
    with pytest.raises(FlattenError) as err:
        flatten(tree, "T", max_size=5)
    assert err.value.message == ("the loops of this model run more than 5 iterations in all "
                                 "(this loop crosses the limit)")
    assert err.value.span is not None and err.value.span.line == 8


def test_a_nest_is_refused_before_it_runs(tmp_path: Path) -> None:
    path = tmp_path / "nest.mdl"
    path.write_text("model N\n  Real a;\nequation\n  for i in 1:3 loop\n    for j in 1:2 loop\n"
                    "      a = i + j;\n    end for;\n  end for;\nend N;\n")
    tree = load([path])
    with pytest.raises(FlattenError) as err:
        flatten(tree, "N", max_size=5)
    assert err.value.message == "this loop nest has 6 iterations, more than the limit of 5"
    assert err.value.span is not None and err.value.span.line == 4


def test_the_command_line_flag_sets_the_cap(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    from click.testing import CliRunner

    from springc.cli import main

    # the flag sets the variable for the process: record it so that teardown restores it
    monkeypatch.setenv("SPRINGC_MAX_SIZE", "2000000")
    path = tmp_path / "big.mdl"
    path.write_text("model Big\n  Real x[10](each start = 1, each fixed = true);\n"
                    "equation\n  der(x) = -x;\nend Big;\n")
    runner = CliRunner()
    refused = runner.invoke(main, ["--max-size", "9", "check", str(path)])
    assert refused.exit_code == 1
    assert f"{path}:2:8: error: a dimension of 'x' has 10 elements, more than the limit " \
           "of 9" in refused.output
    monkeypatch.setenv("SPRINGC_MAX_SIZE", "2000000")
    accepted = runner.invoke(main, ["--max-size", "10", "check", str(path)])
    assert accepted.exit_code == 0
    assert accepted.output == "Big: 10 unknowns, 10 equations, 0 parameters: balanced\n"
    bad = runner.invoke(main, ["--max-size", "0", "check", str(path)])
    assert bad.exit_code == 2 and "'--max-size'" in bad.output


DOUBLING = """
model D
  function grow
    input Integer n;
    output String s;
  algorithm
    s := "ab";
    for i in 1:n loop
      s := s + s;
    end for;
  end grow;
  parameter String t = grow({n});
  Real x = 1;
end D;
"""


def test_a_string_doubled_in_a_function_is_capped_where_it_grows(tmp_path: Path) -> None:
    """2 * 2^n characters: n = 40 would need 2 TB; the cap stops it at the first
    concatenation past the limit (2^10 + 2^10 > 2000 characters)."""
    path = tmp_path / "d.mdl"
    path.write_text(DOUBLING.format(n=40))
    tree = load([path])
    with pytest.raises(FlattenError) as caught:
        flatten(tree, "D", max_size=2000)
    err = caught.value
    assert err.message == "this String has 2048 characters, more than the limit of 2000"
    assert err.span is not None and (err.span.line, err.span.column) == (9, 12)
    path.write_text(DOUBLING.format(n=9))  # 1024 characters: within the cap
    assert len(flatten(load([path]), "D", max_size=2000).equations) == 1


@pytest.mark.parametrize(("call", "message"), [
    ("String(1, minimumLength = 2001)",
     "the 'minimumLength' of String(...) has 2001 characters, more than the limit of 2000"),
    ("String(1.5, format = \"3000.3f\")",
     "the 'format' of String(...) has 3000 characters, more than the limit of 2000"),
    ("String(1.5, significantDigits = 100000)",
     "the 'significantDigits' of String(...) has 100000 characters, more than the limit "
     "of 2000"),
])
def test_string_widths_past_the_cap_are_refused(tmp_path: Path, call: str,
                                                message: str) -> None:
    path = tmp_path / "w.mdl"
    path.write_text(f"model W\n  parameter String t = {call};\n  Real x = 1;\nend W;\n")
    with pytest.raises((FlattenError, ErrorGroup)) as caught:
        flatten(load([path]), "W", max_size=2000)
    err = caught.value.errors[0] if isinstance(caught.value, ErrorGroup) else caught.value
    assert isinstance(err, FlattenError) and err.message == message


COUNTING = """
model W
  function count
    input Integer n;
    output Integer i = 0;
  algorithm
    while i < n loop
      i := i + 1;
    end while;
  end count;
  parameter Integer k = count({n});
  Real x = k;
end W;
"""


def test_one_while_loop_runs_a_hundredth_of_the_cap(tmp_path: Path) -> None:
    """A while loop whose condition never becomes false fails after max_size / 100
    iterations (1000 here), at the loop, long before the cap of all loops (100 s at the
    default cap of 2 million)."""
    path = tmp_path / "w.mdl"
    path.write_text(COUNTING.format(n=1000))
    flat = flatten(load([path]), "W", max_size=100_000)
    assert [p.binding for p in flat.parameters] == [Const(1000)]
    path.write_text(COUNTING.format(n=1001))
    with pytest.raises(FlattenError) as caught:
        flatten(load([path]), "W", max_size=100_000)
    err = caught.value
    assert err.message == "this while loop did not end within 1000 iterations"
    assert err.span is not None and (err.span.line, err.span.column) == (7, 5)
    assert err.hint is not None and err.hint.endswith(
        "raise the cap with springc --max-size N, SPRINGC_MAX_SIZE=N or "
        "flatten(..., max_size=N)")
