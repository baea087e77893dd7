"""A subscript known only during the simulation (section 10.5: ``expr[i]`` with ``i``
a discrete Integer, the MSL's MultiSwitch): an if-expression on the index."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.ir import expr as x
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_an_integer_variable_selects_an_element(tmp_path: Path) -> None:
    path = tmp_path / "m.mo"
    path.write_text("""model M
  Real e[3] = {10*time, 20, 30};
  Integer i = if time < 0.5 then 1 else if time < 1 then 2 else 3;
  Real y = e[i];
  Real m[2, 2] = [1, 2; 3, 4*time];
  Real r[2] = m[4 - i, :];
end M;
""")
    m = flatten_files([path], None)
    equations = {x.to_text(e.lhs): x.to_text(e.rhs) for e in m.equations}
    assert equations["y"] == "if i == 1 then e[1] else if i == 2 then e[2] else e[3]"
    assert (equations["r[1]"], equations["r[2]"]) == (
        "if 4 - i == 1 then m[1,1] else m[2,1]",
        "if 4 - i == 1 then m[1,2] else m[2,2]")


def test_assigning_with_a_run_time_subscript_chooses_each_element(tmp_path: Path) -> None:
    # the MSL's RealFFT: buf[iTick] := u in a when statement; the subscript is read
    # as it stands at the assignment, and the last element is chosen by k == 3 (an
    # index out of range assigns none); a when statement's relations are literal; an
    # element not chosen keeps its value from before the event, pre (11.1.2)
    path = tmp_path / "m.mo"
    path.write_text("""model M
  Real buf[3](each start = 0, each fixed = true);
  Integer k(start = 0, fixed = true);
  Real m[2, 2](each start = 0, each fixed = true);
algorithm
  when sample(0, 0.1) then
    k := pre(k) + 1;
    buf[k] := time;
    m[2, k] := -time;
  end when;
end M;
""")
    m = flatten_files([path], None)
    (when,) = m.whens
    equations = {e.name: x.to_text(e.value) for e in when.branches[0].assignments}
    assert equations == {
        "k": "pre(k) + 1",
        "buf[1]": "noEvent(if pre(k) + 1 == 1 then time else pre(buf[1]))",
        "buf[2]": "noEvent(if pre(k) + 1 == 2 then time else pre(buf[2]))",
        "buf[3]": "noEvent(if pre(k) + 1 == 3 then time else pre(buf[3]))",
        "m[2,1]": "noEvent(if pre(k) + 1 == 1 then -time else pre(m[2,1]))",
        "m[2,2]": "noEvent(if pre(k) + 1 == 2 then -time else pre(m[2,2]))"}


def test_a_function_assigns_with_a_run_time_subscript(tmp_path: Path) -> None:
    path = tmp_path / "m.mo"
    path.write_text("""model M
  function put
    input Integer i;
    input Real v;
    output Real y[3];
  algorithm
    y := {1, 2, 3};
    y[i] := v;
  end put;
  Integer k = if time < 0.5 then 1 else 3;
  Real y[3] = put(k, 10*time);
end M;
""")
    m = flatten_files([path], None)
    equations = {x.to_text(e.lhs): x.to_text(e.rhs) for e in m.equations}
    assert [equations[f"y[{j}]"] for j in (1, 2, 3)] == [
        "if k == 1 then 10 * time else 1",
        "if k == 2 then 10 * time else 2",
        "if k == 3 then 10 * time else 3"]
