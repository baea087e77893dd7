"""``when`` statements in algorithm sections (11.2.7) while flattening: each becomes a
when-clause of the flat model whose assignments are the values its branch leaves
(reading the section's values assigned before it), exact flat models."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_when_statements_become_when_clauses(tmp_path: Path) -> None:
    path = tmp_path / "W.mo"
    path.write_text("""model W
  Real x(start = 1, fixed = true);
  discrete Real y(start = 0, fixed = true);
  Integer n(start = 0, fixed = true);
  Real z;
equation
  der(x) = -x;
algorithm
  z := 2 * x;
  when {x < 0.5, x < 0.25} then
    n := pre(n) + 1;
    y := z + n;
    if n > 1 then
      y := -y;
    end if;
  elsewhen time >= 2 then
    y := -1;
    terminate("late");
  end when;
  z := z + n;
end W;
""")
    assert format_flat(flatten_files([path], None)) == """model W
  Real x(start = 1, fixed = true);
  discrete Real y(start = 0, fixed = true);
  discrete Integer n(start = 0, fixed = true);
  Real z;
equation
  der(x) = -x;
  z = 2 * x + n;
  when {x < 0.5, x < 0.25} then
    n = pre(n) + 1;
    y = noEvent(if pre(n) + 1 > 1 then -(2 * x + (pre(n) + 1)) else 2 * x + (pre(n) + 1));
  elsewhen time >= 2 then
    y = -1;
    terminate("late");
  end when;
end W;
"""


SHIFT = """model S
  Real buf[3](each start = 0, each fixed = true);
  Real total(start = 0, fixed = true);
  discrete Real later(start = 0, fixed = true);
  discrete Real seen(start = 0, fixed = true);
algorithm
  when sample(0.1, 0.1) then
    buf := {buf[2], buf[3], time};
    total := buf[1] + buf[2] + buf[3];
    seen := later;
  end when;
  when sample(0.1, 0.1) then
    later := time;
  end when;
  annotation(experiment(StopTime = 0.45, Interval = 0.05));
end S;
"""


def test_reads_of_variables_a_when_statement_assigns_later_are_their_pre_values(
        tmp_path: Path) -> None:
    # 11.1.2: the algorithm runs in order, so `buf[2]` on the right of the first
    # assignment is still the value before the event; a when-equation 'buf[1]' =
    # 'buf[2]' would read the new one (the shifted buffer read one element ahead)
    path = tmp_path / "S.mo"
    path.write_text(SHIFT)
    text = format_flat(flatten_files([path], None))
    assert text.split("equation\n")[1] == """  when sample(0.1, 0.1) then
    'buf[1]' = pre('buf[2]');
    'buf[2]' = pre('buf[3]');
    'buf[3]' = time;
    total = pre('buf[2]') + pre('buf[3]') + time;
    seen = pre(later);
  end when;
  when sample(0.1, 0.1) then
    later = time;
  end when;
  annotation(experiment(StopTime = 0.45, Interval = 0.05));
end S;
"""


def test_a_shift_register_in_a_when_statement_simulates_in_order(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import springc  # the run: the buffer holds the last three sample times

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "S.mo"
    path.write_text(SHIFT)
    result = springc.simulate(str(path), backend="python", engine="scipy")
    for t, total, seen in zip(result.time, result["total"], result["seen"]):
        k = round(float(t) / 0.05) // 2  # samples at 0.1, 0.2, ... up to t
        samples = [0.1 * i for i in range(1, k + 1)]
        assert total == pytest.approx(sum(samples[-3:]), abs=1e-12)
        assert seen == pytest.approx(samples[-2] if k >= 2 else 0.0, abs=1e-12)


PRE_AFTER = """model P
  discrete Real a(start = 1, fixed = true);
  discrete Real c(start = 0, fixed = true);
  Boolean b(start = false, fixed = true);
  Boolean rose(start = false, fixed = true);
  Boolean moved(start = false, fixed = true);
algorithm
  when sample(0, 0.1) then
    a := pre(a) + 1;
    c := pre(a) + 10 * a;
    b := not pre(b);
    rose := edge(b);
    moved := change(a);
  end when;
  annotation(experiment(StopTime = 0.35, Interval = 0.05));
end P;
"""


def test_pre_after_an_assignment_reads_the_value_before_the_event(tmp_path: Path) -> None:
    path = tmp_path / "P.mo"
    path.write_text(PRE_AFTER)
    text = format_flat(flatten_files((str(path),), "P"))
    assert """  when sample(0, 0.1) then
    a = pre(a) + 1;
    c = pre(a) + 10 * (pre(a) + 1);
    b = not pre(b);
    rose = not pre(b) and not pre(b);
    moved = noEvent(pre(a) + 1 <> pre(a));
  end when;""" in text, text


def test_pre_edge_and_change_after_an_assignment_simulate(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import springc  # a steps 2, 3, 4, 5 at t = 0, 0.1, 0.2, 0.3; c = pre(a) + 10 a

    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    path = tmp_path / "P.mo"
    path.write_text(PRE_AFTER)
    result = springc.simulate(str(path), backend="python", engine="scipy")
    for t, a, c, b, rose, moved in zip(result.time, result["a"], result["c"], result["b"],
                                       result["rose"], result["moved"]):
        k = round(float(t) / 0.05) // 2 + 1  # samples up to t, the one at 0 included
        assert (a, c) == (1 + k, k + 10 * (1 + k))
        assert (b, rose, moved) == (k % 2, k % 2, 1)
