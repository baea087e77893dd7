"""The count of symbolic work (springc.simplify.isolate.counting): only inside a
``counting`` block, only of its own thread, nested blocks apart."""

from __future__ import annotations

import threading

from springc.ir import expr as x
from springc.simplify.isolate import SymbolicWork, counting, partial, solve_for

X, Y = x.Var("x"), x.Var("y")
RESIDUAL = x.sub(x.mul(x.Const(2), X), Y)  # 2*x - y


def test_the_work_of_a_block_is_counted() -> None:
    partial(RESIDUAL, "x")  # outside: counted nowhere
    with counting() as work:
        assert partial(RESIDUAL, "x") == x.Const(2)
        assert partial(RESIDUAL, "y") == x.Const(-1)
        solve_for(RESIDUAL, "x")
    solve_for(RESIDUAL, "x")
    assert work == SymbolicWork(solve=1, diff=2)


def test_nested_blocks_and_other_threads_count_apart() -> None:
    with counting() as outer:
        solve_for(RESIDUAL, "x")
        with counting() as inner:
            partial(RESIDUAL, "x")
        thread = threading.Thread(target=lambda: partial(RESIDUAL, "y"))
        thread.start()
        thread.join()
        partial(RESIDUAL, "y")
    assert (outer, inner) == (SymbolicWork(solve=1, diff=1), SymbolicWork(solve=0, diff=1))
