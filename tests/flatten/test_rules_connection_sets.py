"""Connection sets (Modelica 3.6 sections 8.3.3, 9.1.2, 9.2 and 9.3): connect only under
parameter conditions, one source per set of signals, and the zero flow of every flow
variable never connected as inside (the model's own connectors included): for each rule
a valid model (its balance summary) and an invalid one (the exact error and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome
from springc.errors import BalanceError
from springc.ir.flat import format_equation
from springc.pipeline.files import flatten_files
from springc.simplify import check_balance

PIN = """\
  connector C
    Real e;
    flow Real f;
  end C;
  model R
    C c1, c2;
  equation
    c1.e = c1.f;
    c2.e = c2.f;
  end R;
"""
SIGNALS = """\
  connector RealInput = input Real;
  connector RealOutput = output Real;
"""

CASES = {
    "connect_in_parameter_if": (f"""\
model M
{PIN}  parameter Boolean joined = true;
  R m;
equation
  if joined then
    connect(m.c1, m.c2);
  end if;
end M;
""", "M: 4 unknowns, 4 equations, 1 parameter: balanced"),
    "connect_in_variable_if": (f"""\
model M
{PIN}  R m;
equation
  if time < 1.0 then
    connect(m.c1, m.c2);
  end if;
end M;
""", "15:5: connect inside an if-equation whose condition is not a parameter expression\n"
         "help: connect-equations may be inside if-equations only when the conditions are "
         "parameter expressions (Modelica 3.6, section 8.3.3)"),
    "one_signal_source": (f"""\
model M
{SIGNALS}  block B
    RealInput u;
    RealOutput y = 2 * u;
  end B;
  model A
    RealInput u = 1.0;
    B b;
  equation
    connect(u, b.u);
  end A;
  A a;
end M;
""", "M: 3 unknowns, 3 equations, 0 parameters: balanced"),
    "two_signal_sources": (f"""\
model M
{SIGNALS}  block B
    RealOutput y = 2;
  end B;
  model A
    RealInput u = 1.0;
    B b;
  equation
    connect(u, b.y);
  end A;
  A a;
end M;
""", "11:5: a connection set has 2 sources of its signal: 'a.u' (outside input), 'a.b.y' "
         "(inside output)\nhelp: a set of connected inputs and outputs may contain at most "
         "one inside output or one public outside input (Modelica 3.6, section 9.3)"),
    "own_connector_flow_zero": ("""\
model M
  connector C
    Real e;
    flow Real f;
  end C;
  C c(e = 1.0);
end M;
""", "M: 2 unknowns, 2 equations, 0 parameters: balanced"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected


def test_own_connectors_connected_outside(tmp_path: Path) -> None:
    """Two connectors of the model connected to each other: the outside set gives
    -c1.f - c2.f = 0 and each flow, never connected as inside, is zero: with c1.f = 2
    the model is over-determined (the suite's Connections.Declarations.
    UnconnectedInsideFlow)."""
    path = tmp_path / "m.mo"
    path.write_text("""\
model M
  connector C
    Real e;
    flow Real f;
  end C;
  C c1, c2;
equation
  connect(c1, c2);
  c1.e = 1.0;
  c1.f = 2.0;
end M;
""")
    with pytest.raises(BalanceError) as info:
        check_balance(flatten_files([path]))
    assert info.value.message == "model 'M' is over-determined: 4 unknowns, 6 equations"


def test_element_of_own_connector_is_outside(tmp_path: Path) -> None:
    """`q.y` with `q` a connector of the model is an outside connector: its flow enters
    the set with a minus sign, and is zero as an inside element (9.1.2, 9.2)."""
    path = tmp_path / "m.mo"
    path.write_text("""\
model M
  connector C
    Real e;
    flow Real f;
  end C;
  connector Pair
    C x;
    C y;
  end Pair;
  model B
    C c;
  equation
    c.e = 2.0;
  end B;
  B b;
  Pair q;
equation
  connect(b.c, q.y);
  q.x.e = 4.0;
end M;
""")
    equations = {format_equation(eq) for eq in flatten_files([path]).equations}
    assert "'b.c.f' - 'q.y.f' = 0;" in equations
    assert {"'q.x.f' = 0;", "'q.y.f' = 0;"} <= equations
