"""``while`` loops of functions whose condition is known only during the simulation
(section 11.2.3), unrolled where they are counted searches (``flatten/calls/counted.py``,
the MSL's TimeTable): a counter raised by a constant, a condition comparing a subscript
of an array by it; every other such loop stays a located error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from rule_outcome import outcome
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

SEARCH = """model W
  function firstAbove "the first index from i0 on whose entry exceeds t (or the last)"
    input Real table[:];
    input Real t;
    input Integer i0;
    output Integer i;
  algorithm
    i := i0;
    while i < size(table, 1) and t >= table[i] loop
      i := i + 1;
    end while;
  end firstAbove;
  parameter Real tab[4] = {0, 1, 2, 3};
  Real k = firstAbove(tab, time, 1);
  Real m = firstAbove(tab, 2 * time, 2);
  annotation(experiment(StopTime = 4, Interval = 0.125));
end W;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_a_counted_search_unrolls_to_a_sum_of_its_conditions(tmp_path: Path) -> None:
    path = tmp_path / "W.mo"
    path.write_text(SEARCH)
    equations = {x.to_text(e.lhs): x.to_text(e.rhs)
                 for e in flatten_files([path], None).equations}
    # at most size(tab) = 4 checks let the loop go on; the fourth (i0 + 3 < 4) is
    # false from i0 = 1, the third from i0 = 2; each check reads the counter at
    # i0 + k, never the value of the iteration before; the conditions are f's own,
    # literal (a function body generates no events, 12.8)
    assert equations["k"] == (
        "1 + ((if noEvent(time >= tab[1]) then 1 else 0) + (if noEvent(time >= tab[1]) "
        "and noEvent(time >= tab[2]) then 1 else 0) + (if noEvent(time >= tab[1]) and "
        "noEvent(time >= tab[2]) and noEvent(time >= tab[3]) then 1 else 0))")
    assert equations["m"] == (
        "2 + ((if noEvent(2 * time >= tab[2]) then 1 else 0) + (if noEvent(2 * time >= "
        "tab[2]) and noEvent(2 * time >= tab[3]) then 1 else 0))")


def test_a_counted_search_simulates_to_its_closed_form(tmp_path: Path) -> None:
    path = tmp_path / "W.mo"
    path.write_text(SEARCH)
    result = springc.simulate(str(path), engine="scipy")
    t = result.time
    # the first index i >= i0 with t < tab[i] = i - 1, else 4: 1 + min(floor(t) + 1, 3)
    # from i0 = 1 (t >= 0), max(2, min(floor(2 t) + 2, 4)) from i0 = 2
    assert np.array_equal(result["k"], 1 + np.minimum(np.floor(t) + 1, 3))
    assert np.array_equal(result["m"], np.maximum(2, np.minimum(np.floor(2 * t) + 2, 4)))


def _loop(body: str, cond: str = "i < size(table, 1) and t >= table[i]") -> str:
    return f"""model W
  function f
    input Real table[:];
    input Real t;
    output Integer i;
  algorithm
    i := 1;
    while {cond} loop
{body}
    end while;
  end f;
  Real k = f({{0, 1, 2}}, time);
end W;
"""


WHILE = ("8:11: `while` loops whose condition is known only during the simulation are "
         "not supported yet")


@pytest.mark.parametrize(("text", "message"), [
    # no subscript by the counter in the condition: no bound
    (_loop("      i := i + 1;", "t >= i"), WHILE),
    # the counter also changes under a condition
    (_loop("      i := i + 1;\n      if t > 5 then\n        i := i + 1;\n      end if;"),
     WHILE),
    # the counter goes down
    (_loop("      i := i - 1;"), WHILE),
    # the subscript is not the counter itself
    (_loop("      i := i + 1;", "i < 3 and t >= table[i + 1]"), WHILE),
])
def test_other_run_time_while_loops_stay_located_errors(tmp_path: Path, text: str,
                                                        message: str) -> None:
    assert outcome(tmp_path, text).split("\nhelp")[0] == message
