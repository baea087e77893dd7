"""Functional inputs (Modelica 3.6, section 12.4.2): a function passed by its name to
an input declared with a (partial) function type, called inside the function; a
function given anywhere else, or a functional input used as a value, is an error."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import FlattenError
from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files

SOURCE = """package H
  partial function PF
    input Real x;
    output Real y;
  end PF;
  function Sq
    extends PF;
  algorithm
    y := x * x;
  end Sq;
  function apply
    input PF f;
    input Real v;
    output Real y;
  algorithm
    y := f(v) + f(2 * v);
  end apply;
  function twice
    input PF g;
    input Real v;
    output Real y;
  algorithm
    y := 2 * apply(g, v);
  end twice;
  function asValue
    input PF f;
    output Real y;
  algorithm
    y := f + 1;
  end asValue;
  function plain
    input Real r;
    output Real y;
  algorithm
    y := r + 1;
  end plain;
  record R
    Real a;
  end R;
  model Good
    Real z = apply(Sq, time);
    Real w = twice(Sq, 3);
  end Good;
  model UsedAsValue
    Real z = asValue(Sq);
  end UsedAsValue;
  model ToRealInput
    Real z = plain(Sq);
  end ToRealInput;
  model ToRecord
    R r = R(Sq);
  end ToRecord;
end H;
"""


def _flat(tmp_path: Path, name: str) -> str:
    path = tmp_path / "h.mo"
    path.write_text(SOURCE)
    return format_flat(flatten_files([path], f"H.{name}"))


def test_a_function_passed_to_a_functional_input(tmp_path: Path) -> None:
    """apply(Sq, t) = t^2 + (2t)^2; twice passes its own functional input on:
    2 (3^2 + 6^2) = 90."""
    assert _flat(tmp_path, "Good") == """model 'H.Good'
  Real z;
  Real w;
equation
  z = time * time + 2 * time * (2 * time);
  w = 90;
end 'H.Good';
"""


@pytest.mark.parametrize(("name", "message", "where"), [
    ("UsedAsValue", "'f' is a function (a functional input), not a value", (29, 10)),
    ("ToRealInput", "the input 'r' of 'H.plain' is given the function 'H.Sq', but it is "
     "not a functional input", (48, 14)),
    ("ToRecord", "'Sq' is a component or class, not a value", (51, 13)),
])
def test_a_function_elsewhere_is_an_error(tmp_path: Path, name: str, message: str,
                                          where: tuple[int, int]) -> None:
    with pytest.raises(FlattenError) as info:
        _flat(tmp_path, name)
    assert info.value.message == message
    assert info.value.span is not None
    assert (info.value.span.line, info.value.span.column) == where
