"""Relations in a function body generate no events unless the function has
``annotation(GenerateEvents = true)`` (Modelica 3.6, section 12.8 "Function Inlining and
Event Generation": by default "expressions in the function body that would normally be
event generating shall not generate events, similar to inlining the function body while
wrapping all expressions in noEvent"; 8.5). springc inlines function bodies, so their
relations and switching built-ins come out inside ``noEvent``; the caller's own
relations, in the arguments, still generate events."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.ir import expr as x
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def flat_of(tmp_path: Path, text: str) -> FlatModel:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return flatten_files([path], None)


def equations(m: FlatModel) -> list[str]:
    return [f"{x.to_text(e.lhs)} = {x.to_text(e.rhs)}" for e in m.equations]


def model(annotation: str) -> str:
    return f"""model M
  function larger
    input Real u1;
    input Real u2;
    output Real y;
  algorithm
    if u1 > u2 then
      y := u1;
    else
      y := u2;
    end if;
    y := y + abs(u1) + div(u1, u2) + integer(u1) + min(u1, u2);
    {annotation}
  end larger;
  Real v = larger(time, 0.5);
  Real w = larger(if time < 1 then time else 1, 2);
end M;
"""


def test_function_body_relations_are_literal_by_default(tmp_path: Path) -> None:
    m = flat_of(tmp_path, model("annotation(Inline = true, smoothOrder = 1);"))
    assert equations(m) == [
        "v = (if noEvent(time > 0.5) then time else 0.5) + noEvent(abs(time))"
        " + noEvent(div(time, 0.5)) + noEvent(integer(time)) + noEvent(min(time, 0.5))",
        # the argument's relation is the caller's: where it stands outside the body's
        # relations (the branch y := u1) it still generates events
        "w = (if noEvent((if time < 1 then time else 1) > 2) then if time < 1 then time"
        " else 1 else 2) + noEvent(abs(if time < 1 then time else 1))"
        " + noEvent(div(if time < 1 then time else 1, 2))"
        " + noEvent(integer(if time < 1 then time else 1))"
        " + noEvent(min(if time < 1 then time else 1, 2))"]


def test_generate_events_true_keeps_the_events(tmp_path: Path) -> None:
    m = flat_of(tmp_path, model("annotation(GenerateEvents = true);"))
    assert equations(m)[0] == (
        "v = (if time > 0.5 then time else 0.5) + abs(time) + div(time, 0.5)"
        " + integer(time) + min(time, 0.5)")


def test_a_generating_function_inside_a_quiet_one_is_literal(tmp_path: Path) -> None:
    m = flat_of(tmp_path, """model M
  function step
    input Real u;
    output Real y = if u > 0 then 1 else 0;
    annotation(GenerateEvents = true);
  end step;
  function twice
    input Real u;
    output Real y = 2*step(u);
  end twice;
  Real a = step(time - 1);
  Real b = twice(time - 1);
end M;
""")
    assert equations(m) == ["a = if time - 1 > 0 then 1 else 0",
                            "b = 2 * (if noEvent(time - 1 > 0) then 1 else 0)"]


def test_functions_in_a_when_condition_keep_their_events(tmp_path: Path) -> None:
    # above(x, 0.5) is no discrete-time expression (3.8.3) without GenerateEvents; a
    # literal condition would be read at events only and never fire: its relations stay
    # events, as in the clause's own relations
    m = flat_of(tmp_path, """model M
  function above
    input Real u;
    input Real k;
    output Boolean y;
  algorithm
    y := u > k;
  end above;
  Real x(start = 0, fixed = true);
  discrete Real tHit(start = -1, fixed = true);
  discrete Real y(start = 0, fixed = true);
equation
  der(x) = 1;
  when above(x, 0.5) then
    tHit = time;
  end when;
algorithm
  when above(x, 0.75) then
    y := if above(x, 2) then 1 else 2;
  end when;
end M;
""")
    assert [x.to_text(c) for clause in m.whens for b in clause.branches
            for c in b.conditions] == ["x > 0.5", "x > 0.75"]
    # the body's values are literal anyway (8.5: the clause wraps them in noEvent too)
    assert [x.to_text(a.value) for clause in m.whens for b in clause.branches
            for a in b.assignments] == ["time", "noEvent(if noEvent(x > 2) then 1 else 2)"]
