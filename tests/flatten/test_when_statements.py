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
