"""Expandable connectors (Modelica 3.6, section 9.1.3), as Modelica.Blocks.Examples.
BusUsage uses them: every component of an expandable connector is a connector, a
declared variable is only potentially present (one no connection reaches and nothing
reads is no variable), two buses of one class connect element by element, a name the
bus does not declare is added to it by a connection to a signal (its causality deduced),
and the other additions are a located "not supported yet"."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.errors import FlattenError
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files

BUS = """package P
  expandable connector Bus
    Real speed;
    Real unused;
    Integer count;
    SubBus sub;
  end Bus;
  expandable connector SubBus
    Real a;
    Real b;
  end SubBus;
  connector RealOutput = output Real;
  connector RealInput = input Real;
  block Gain
    RealInput u;
    RealOutput y;
  equation
    y = 2*u;
  end Gain;
  model Part
    SubBus sub;
    RealOutput y;
  equation
    y = 3*time;
    connect(y, sub.a);
  end Part;
  model M
    RealOutput s;
    Gain gain;
    Gain gain2;
    Part part;
  protected
    Bus bus;
  equation
    s = sin(time);
    connect(s, bus.speed);
    connect(bus.speed, gain.u);
    connect(part.sub, bus.sub);
    connect(bus.sub.a, gain2.u);
  end M;
  model Undeclared
    RealOutput s = time;
    Bus bus;
  equation
    connect(s, bus.missing[2]);
  end Undeclared;
  model Augmented
    Bus bus;
    Part part;
  equation
    connect(bus, part.sub);
  end Augmented;
end P;
"""


def test_a_bus_keeps_only_what_is_connected(tmp_path: Path) -> None:
    # bus.unused, bus.count and sub.b (connected only bus to bus) are not present
    path = tmp_path / "bus.mo"
    path.write_text(BUS)
    assert format_flat(flatten_files([path], "P.M")) == """model 'P.M'
  output Real s;
  input Real 'gain.u';
  output Real 'gain.y';
  input Real 'gain2.u';
  output Real 'gain2.y';
  Real 'part.sub.a';
  output Real 'part.y';
  Real 'bus.speed';
  Real 'bus.sub.a';
equation
  'gain.y' = 2 * 'gain.u';
  'gain2.y' = 2 * 'gain2.u';
  'part.y' = 3 * time;
  s = sin(time);
  'part.y' = 'part.sub.a';
  'part.y' = 'bus.sub.a';
  s = 'bus.speed';
  s = 'gain.u';
  'bus.sub.a' = 'gain2.u';
end 'P.M';
"""


def test_signals_pass_through_a_bus(tmp_path: Path) -> None:
    path = tmp_path / "bus.mo"
    path.write_text(BUS)
    result = springc.simulate([path], model_name="P.M", stop=1.0, interval=0.25,
                              engine="scipy", backend="python", error_control="off")
    t = np.asarray(result.time)
    assert np.allclose(result["gain.y"], 2 * np.sin(t), rtol=0, atol=1e-12)
    assert np.allclose(result["gain2.y"], 6 * t, rtol=0, atol=1e-12)


def test_a_name_the_bus_does_not_declare_is_not_supported_yet(tmp_path: Path) -> None:
    path = tmp_path / "bus.mo"
    path.write_text(BUS)
    with pytest.raises(FlattenError) as info:
        flatten_files([path], "P.Undeclared")
    error = info.value
    assert error.message == ("adding 'missing' to the expandable connector 'bus' (P.Bus) "
                             "by a connection is not supported yet")
    assert (error.span.line, error.span.column) == (45, 20)


def test_buses_declaring_different_variables_are_not_supported_yet(tmp_path: Path) -> None:
    path = tmp_path / "bus.mo"
    path.write_text(BUS)
    with pytest.raises(FlattenError) as info:
        flatten_files([path], "P.Augmented")
    assert info.value.message == (
        "connecting the expandable connectors 'bus' (P.Bus) and 'part.sub' (P.SubBus), "
        "which declare different variables, is not supported yet")
    assert (info.value.span.line, info.value.span.column) == (51, 5)


AUGMENT = """package A
  expandable connector Bus
  end Bus;
  connector RealOutput = output Real;
  connector RealInput = input Real;
  block Source
    RealOutput y = 3 * time;
  end Source;
  block Sink
    RealInput u;
    RealOutput y = 2 * u;
  end Sink;
  model Unit
    Bus bus;
    Sink sink;
  equation
    connect(bus.w, sink.u);
  end Unit;
  model M
    Bus bus;
    Source source;
    Sink sink;
  equation
    connect(source.y, bus.w);
    connect(bus.w, sink.u);
  end M;
  model Linked
    Bus bus;
    Source source;
    Unit unit;
  equation
    connect(source.y, bus.w);
    connect(bus, unit.bus);
  end Linked;
  model Lone
    Unit unit;
  end Lone;
  model Both
    Bus b1;
    Bus b2;
  equation
    connect(b1.v, b2.v);
  end Both;
  connector Pin
    Real v;
    flow Real i;
  end Pin;
  model Cell
    Pin p;
  equation
    p.v = 1.5;
  end Cell;
  model Structured
    Bus bus;
    Cell cell;
  equation
    connect(cell.p, bus.pin);
  end Structured;
  model Fed
    Bus bus;
    Source source;
    Sink sink;
  equation
    connect(source.y, bus.w);
    connect(bus.w, sink.u);
  end Fed;
  model Many
    Fed f[2];
    Fed g;
  end Many;
end A;
"""


def test_a_connection_adds_a_variable_to_a_bus(tmp_path: Path) -> None:
    """bus.w takes the type and causality of source.y (an inside output): the signal
    reaches sink.u through it, sink.y = 2 * 3 t."""
    path = tmp_path / "augment.mo"
    path.write_text(AUGMENT)
    result = springc.simulate([path], model_name="A.M", stop=1.0, interval=0.25,
                              engine="scipy", backend="python", error_control="off")
    t = np.asarray(result.time)
    assert np.allclose(result["sink.y"], 6 * t, rtol=0, atol=1e-12)
    assert np.allclose(result["bus.w"], 3 * t, rtol=0, atol=1e-12)


def test_an_added_input_needs_another_bus(tmp_path: Path) -> None:
    """unit.bus.w is an input (copied from sink.u): valid where unit.bus is connected
    to another bus (Linked), an error where it is not (Lone, section 9.1.3)."""
    path = tmp_path / "augment.mo"
    path.write_text(AUGMENT)
    result = springc.simulate([path], model_name="A.Linked", stop=1.0, interval=0.25,
                              engine="scipy", backend="python", error_control="off")
    t = np.asarray(result.time)
    assert np.allclose(result["unit.sink.y"], 6 * t, rtol=0, atol=1e-12)
    with pytest.raises(FlattenError) as info:
        flatten_files([path], "A.Lone")
    assert info.value.message == (
        "'unit.bus.w' is added to an expandable connector as an input, and no other "
        "expandable connector of its augmentation set has it as a non-input")
    assert info.value.hint == (
        "a variable that is an input in one expandable connector must be a non-input in "
        "another of its augmentation set (Modelica 3.6, section 9.1.3)")


def test_both_sides_undeclared(tmp_path: Path) -> None:
    path = tmp_path / "augment.mo"
    path.write_text(AUGMENT)
    with pytest.raises(FlattenError) as info:
        flatten_files([path], "A.Both")
    error = info.value
    assert error.message == ("'b1.v' and the other side of the connection are both "
                             "undeclared variables of expandable connectors")
    assert (error.span.line, error.span.column) == (42, 5)


def test_a_connection_adds_a_connector_to_a_bus(tmp_path: Path) -> None:
    """bus.pin is a Pin like cell.p; bus is an outside connector of the model, so its
    flow enters the set with a minus sign and, connected nowhere else, is zero."""
    path = tmp_path / "augment.mo"
    path.write_text(AUGMENT)
    assert format_flat(flatten_files([path], "A.Structured")) == """model 'A.Structured'
  Real 'bus.pin.v';
  flow Real 'bus.pin.i';
  Real 'cell.p.v';
  flow Real 'cell.p.i';
equation
  'cell.p.v' = 1.5;
  'cell.p.v' = 'bus.pin.v';
  'cell.p.i' - 'bus.pin.i' = 0;
  'bus.pin.i' = 0;
end 'A.Structured';
"""


def test_buses_of_instances_copied_from_a_template(tmp_path: Path) -> None:
    """f[2] and g are copies of f[1]'s instance: each bus still gets its variable w,
    and every sink.y = 2 * 3 t."""
    path = tmp_path / "augment.mo"
    path.write_text(AUGMENT)
    result = springc.simulate([path], model_name="A.Many", stop=1.0, interval=0.25,
                              engine="scipy", backend="python", error_control="off")
    t = np.asarray(result.time)
    for name in ("f[1]", "f[2]", "g"):
        assert np.allclose(result[f"{name}.sink.y"], 6 * t, rtol=0, atol=1e-12)
        assert np.allclose(result[f"{name}.bus.w"], 3 * t, rtol=0, atol=1e-12)
