"""Calls whose arguments are all parameters with known values, evaluated numerically
where the symbolic execution of :mod:`.functions` decides control flow by the
parameters' values.

A ``while`` loop (or a function it calls) whose condition reads parameters runs as
often as their values say (:func:`.control.run_while`), so its symbolic result holds for
those values only, while its branches, merged as ``if``-expressions, build graphs whose
trees grow exponentially with the iterations (the filter coefficient functions of
``Modelica.Blocks.Continuous.Filter``: a Brent and a bisection iteration). Such a call
is run again on the arguments' values: its outputs become constants, its assertions'
conditions true or false, and the parameters its arguments read are recorded as
evaluated (``FlatModel.evaluated``: structural, so a new value compiles the model
again, as ``Evaluate = true`` would), as the tools compute such parameters once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...ir import expr as x
from .. import arrays as a
from ..scopes import ExpressionEvaluator
from .control import folded

Run = Callable[[list[a.Value], dict[str, tuple[a.Value, Any]]], a.Value]


def parameter_call(ev: ExpressionEvaluator, args: list[a.Value],
                   named: dict[str, tuple[a.Value, Any]], run: Run) -> a.Value:
    """``run(args, named)`` (the symbolic execution), or, where every argument is a
    parameter expression with a known value and the run decided control flow by the
    parameters' values, ``run`` on the arguments' values with constant outputs."""
    values = [*args, *(v for v, _ in named.values())]
    fl = ev.flattener
    if not values or not all(_foldable(ev, v) for v in values):
        return run(args, named)
    marks = (len(fl.assertions), len(fl.statement_conditions), fl.parameter_decisions)
    symbolic = run(args, named)
    if fl.parameter_decisions == marks[2]:
        return symbolic
    del fl.assertions[marks[0]:]
    del fl.statement_conditions[marks[1]:]
    for v in values:
        fl.evaluated.update(n for e in a.scalars(v) for n in x.variables(e))
    numeric = run([_constant(ev, v) for v in args],
                  {k: (_constant(ev, v), span) for k, (v, span) in named.items()})
    if isinstance(numeric, list):  # several outputs
        return [_folded(v) for v in numeric]  # type: ignore[return-value]
    return _folded(numeric)


def _foldable(ev: ExpressionEvaluator, v: a.Value) -> bool:
    """A parameter expression (or an array of them) with a known value."""
    if isinstance(v, np.ndarray):
        return v.dtype == object and all(_foldable(ev, item) for item in v.flat)
    if not isinstance(v, x.Expr) or not ev.flattener.is_parameter_expression(v):
        return False
    try:
        ev.fold(v)
    except (KeyError, ArithmeticError, ValueError, TypeError):
        return False
    return True


def _constant(ev: ExpressionEvaluator, v: a.Value) -> a.Value:
    return a.elementwise(lambda item: x.Const(ev.fold(item)), v)


def _folded(v: a.Value) -> a.Value:
    if isinstance(v, np.ndarray) and v.dtype == object:
        out = np.empty(v.shape, dtype=object)
        for idx, item in np.ndenumerate(v):
            out[idx] = _folded(item)
        return out
    return folded(v) if isinstance(v, x.Expr) else v
