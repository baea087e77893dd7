"""A subscript known only during the simulation (section 10.5: ``expr[i]`` with ``i``
a discrete Integer, the MSL's MultiSwitch): an if-expression on the index."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import SpringcError, errors_of
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


def test_assigning_with_a_run_time_subscript_is_a_located_error(tmp_path: Path) -> None:
    # the MSL's RealFFT: buf[iTick] := u in a when statement
    path = tmp_path / "m.mo"
    path.write_text("""model M
  Real buf[3](each start = 0, each fixed = true);
  Integer k(start = 0, fixed = true);
algorithm
  when sample(0, 0.1) then
    k := pre(k) + 1;
    buf[k] := time;
  end when;
end M;
""")
    with pytest.raises(SpringcError) as info:
        flatten_files([path], None)
    (err,) = errors_of(info.value)
    assert err.span is not None and (err.span.line, err.span.column) == (7, 5)
    assert err.message == ("assigning to 'buf' with a subscript known only during the "
                           "simulation is not supported yet")
