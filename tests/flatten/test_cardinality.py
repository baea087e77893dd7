"""``cardinality(c)`` (Modelica 3.6, 3.7.4.4): the number of connect equations naming
the connector ``c``, counted after the whole model is flat (the connects of the
enclosing model included); exact flat equations and the located error for a
non-connector argument."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import SpringcError
from springc.ir import expr as x
from springc.pipeline.files import flatten_files

MODEL = """model Card
  connector C
    Real e;
    flow Real f;
  end C;
  model M
    C c1, c2, c3, c4;
    Integer n1 = cardinality(c1);
    Integer n2 = cardinality(c2);
    Integer n4 = cardinality(c4);
  equation
    c1.e = 1.0;
    c1.f = 1.0;
    c2.f = 2.0;
    c4.e = 3.0;
    c4.f = 0.0;
    assert(cardinality(c3) == 1, "c3 is connected once");
  end M;
  M m;
equation
  connect(m.c1, m.c2);
  connect(m.c2, m.c3);
end Card;
"""


@pytest.fixture(autouse=True)
def _no_springc_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("SPRINGC_PATH", raising=False)


def test_cardinality_counts_the_connects_of_the_enclosing_model(tmp_path: Path) -> None:
    path = tmp_path / "Card.mo"
    path.write_text(MODEL)
    m = flatten_files([path], None)
    eqs = {x.to_text(e.lhs): x.to_text(e.rhs) for e in m.equations}
    assert (eqs["m.n1"], eqs["m.n2"], eqs["m.n4"]) == ("1", "2", "0")
    assert [x.to_text(a.condition) for a in m.assertions] == ["1 == 1"]


def test_cardinality_of_a_real_variable_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "Bad.mo"
    path.write_text("model Bad\n  Real x = 1.0;\n  Integer n = cardinality(x);\nend Bad;\n")
    with pytest.raises(SpringcError) as info:
        flatten_files([path], None)
    assert str(info.value) == (
        f"{path}:3:27: error: the argument of cardinality must be a connector\n"
        "    3 |   Integer n = cardinality(x);\n"
        "      |                           ^\n"
        "help: cardinality(c) counts the connect equations that name the connector c, a "
        "scalar connector (Modelica 3.6, section 3.7.4.4)")
