"""ir.records.quick_init: the same construction as the dataclass's own __init__."""

from __future__ import annotations

import dataclasses
import inspect

import pytest

from springc.ir import dae, flat, nodes, ode
from springc.ir.records import quick_init


@dataclasses.dataclass(frozen=True, slots=True)
class _Plain:
    op: str
    left: object
    right: object = None


@quick_init
@dataclasses.dataclass(frozen=True, slots=True)
class _Quick:
    op: str
    left: object
    right: object = None


def test_a_quick_class_takes_the_same_arguments_and_keeps_the_same_values() -> None:
    assert list(inspect.signature(_Quick.__init__).parameters) == \
        list(inspect.signature(_Plain.__init__).parameters) == ["self", "op", "left", "right"]
    assert inspect.signature(_Quick.__init__).parameters["right"].default is None
    for args, kwargs in [(("+", 1, 2), {}), (("-",), {"left": 3}), ((), {"op": "*", "left": 4,
                                                                          "right": 5})]:
        q, p = _Quick(*args, **kwargs), _Plain(*args, **kwargs)
        assert (q.op, q.left, q.right) == (p.op, p.left, p.right)
    assert _Quick("+", 1) == _Quick("+", 1, None) and hash(_Quick("+", 1)) == hash(
        _Quick("+", 1, None))
    assert dataclasses.replace(_Quick("+", 1), left=7) == _Quick("+", 7)
    assert repr(_Quick("+", 1)) == "_Quick(op='+', left=1, right=None)"
    with pytest.raises(TypeError, match="missing 1 required positional argument: 'left'"):
        _Quick("+")  # type: ignore[call-arg]


def test_a_quick_class_stays_frozen() -> None:
    with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field 'op'"):
        _Quick("+", 1).op = "-"  # type: ignore[misc]


def test_a_class_with_a_default_factory_keeps_its_own_init() -> None:
    @dataclasses.dataclass(frozen=True, slots=True)
    class Listed:
        items: list[int] = dataclasses.field(default_factory=list)

    init = Listed.__init__
    assert quick_init(Listed).__init__ is init
    assert Listed().items == []


def test_the_ir_classes_construct_through_quick_init() -> None:
    for cls in (nodes.BinOp, nodes.Var, flat.Variable, flat.Attributes, dae.Residual,
                ode.Assign):
        assert cls.__init__.__qualname__ == f"{cls.__qualname__}.__init__"
        assert "_set0" in cls.__init__.__globals__  # the slot stores, bound once
    r = dae.Residual(nodes.Var("x"), None, None)  # type: ignore[arg-type]
    assert (r.source, r.variables, r.pre_only) == (None, frozenset(), frozenset())
