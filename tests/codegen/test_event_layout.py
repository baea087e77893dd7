"""codegen/event_layout: ``hold`` replaces each event relation by its slot, visiting a
node shared by several parents once (index reduction's expressions are DAGs whose
trees are exponentially larger: MultiBody's InitSpringConstant)."""

from __future__ import annotations

from springc.codegen.event_layout import EventLayout
from springc.ir import expr as x
from springc.ir.hybrid import EventSystem


def _shared(depth: int, leaf: x.Expr) -> x.Expr:
    """``leaf`` doubled ``depth`` times, each level one node read twice: 2**depth
    leaves as a tree."""
    e = leaf
    for _ in range(depth):
        e = x.BinOp("+", e, e)
    return e


def test_hold_visits_a_shared_node_once() -> None:
    relation = x.BinOp(">", x.Var("s"), x.Const(0.0))
    layout = EventLayout(EventSystem((), (relation,), (), (), (), ()), 0)
    leaf = x.If(relation, x.Var("a"), x.Var("b"))
    held = layout.hold(_shared(80, leaf))
    # the result shares its nodes the same way, one node per level (compared level by
    # level: == would compare the 2**80 leaves of the tree)
    node, levels = held, 0
    while isinstance(node, x.BinOp):
        assert node.op == "+" and node.left is node.right
        node, levels = node.left, levels + 1
    assert (levels, node) == (80, x.If(x.Var("_zr0"), x.Var("a"), x.Var("b")))


def test_a_relation_inside_a_quiet_call_is_not_held() -> None:
    # noEvent(s > 0) reads the relation itself, not its held value
    relation = x.BinOp(">", x.Var("s"), x.Const(0.0))
    layout = EventLayout(EventSystem((), (relation,), (), (), (), ()), 0)
    quiet = x.Call("noEvent", (relation,))
    assert layout.hold(x.BinOp("and", relation, quiet)) == \
        x.BinOp("and", x.Var("_zr0"), quiet)
