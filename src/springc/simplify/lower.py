"""Lower the flat model to a DAE: flat.FlatModel -> dae.DAE.

Equations become residuals ``lhs - rhs``; ``der`` of an expression is expanded by
the chain rule, and ``der(x)`` becomes the derivative variable ``der(x)``.
"""

from __future__ import annotations

from collections.abc import Callable

from ..ir import dae, flat
from ..ir import expr as x
from .events import continuous_part
from .isolate import count_diff, free_variables, pre_only


def lower_derivatives(e: x.Expr, varying: Callable[[str], bool]) -> x.Expr:
    """Replace ``der(expr)`` by derivative variables (``der(x)`` for ``der(x)``);
    ``varying(name)`` is false for parameters, whose derivative is zero. A node shared
    by several parents is lowered once (the assertions of functions that loop
    symbolically, Blocks.Continuous.Filter's, are graphs whose trees are exponential)."""
    return _lower(e, varying, {})


def _lower(e: x.Expr, varying: Callable[[str], bool],
           memo: dict[int, tuple[x.Expr, x.Expr]]) -> x.Expr:
    if isinstance(e, (x.Const, x.Var, x.Time)):
        return e
    found = memo.get(id(e))
    if found is not None and found[0] is e:
        return found[1]
    out = _lower_node(e, varying, memo)
    memo[id(e)] = (e, out)
    return out


def _lower_node(e: x.Expr, varying: Callable[[str], bool],
                memo: dict[int, tuple[x.Expr, x.Expr]]) -> x.Expr:
    if isinstance(e, x.Der):
        arg = e.arg
        if isinstance(arg, x.Var):
            return x.Var(dae.derivative_name(arg.name)) if varying(arg.name) else x.ZERO
        inner = _lower(arg, varying, memo)
        return _lower(x.time_derivative(inner, varying), varying, memo)
    if isinstance(e, x.BinOp):
        left, right = _lower(e.left, varying, memo), _lower(e.right, varying, memo)
        return e if left is e.left and right is e.right else x.BinOp(e.op, left, right)
    if isinstance(e, (x.Neg, x.Not)):
        arg = _lower(e.arg, varying, memo)
        return e if arg is e.arg else type(e)(arg)
    if isinstance(e, x.Call):
        return x.Call(e.name, tuple(_lower(a, varying, memo) for a in e.args))
    if isinstance(e, x.If):
        return x.If(_lower(e.cond, varying, memo), _lower(e.then, varying, memo),
                    _lower(e.otherwise, varying, memo))
    raise TypeError(f"not an expression: {e!r}")


def differentiate(e: x.Expr, varying: Callable[[str], bool]) -> x.Expr:
    """d/dt of a lowered expression, again in terms of derivative variables."""
    count_diff()
    return lower_derivatives(x.time_derivative(e, varying), varying)


def _residual(eq: flat.Equation, varying: Callable[[str], bool]) -> dae.Residual:
    lhs = lower_derivatives(eq.lhs, varying) if _has_der(eq.lhs) else eq.lhs
    rhs = lower_derivatives(eq.rhs, varying) if _has_der(eq.rhs) else eq.rhs
    residual = x.sub(lhs, rhs)
    names = free_variables(residual)
    return dae.Residual(residual, eq.span, eq.origin, eq, frozenset(names),
                        pre_only(residual) if _reads_pre(eq) else frozenset())


def _reads_pre(eq: flat.Equation) -> bool:
    """Whether ``eq`` calls ``pre``."""
    return x.calls_named([eq.lhs, eq.rhs], "pre")


def _has_der(e: x.Expr) -> bool:
    stack = [e]
    while stack:
        node = stack.pop()
        kind = type(node)
        if kind is x.Der:
            return True
        if kind is x.BinOp:
            stack += (node.left, node.right)  # type: ignore[union-attr]
        elif kind is not x.Var and kind is not x.Const:
            stack.extend(x.children(node))
    return False


def lower(model: flat.FlatModel) -> dae.DAE:
    """Build the DAE of a flat model; the variables its when-clauses assign are held
    between events (simplify/events.py), not unknowns of the DAE."""
    model = continuous_part(model)
    unknowns = tuple(
        dae.Unknown(v.name, v.attributes.start, bool(v.attributes.fixed),
                    v.attributes.nominal, v.attributes.state_select or "default",
                    v.attributes.unit, v.component, v.span)
        for v in model.unknowns)
    parameters = tuple(dae.Parameter(v.name, v.binding, v.attributes.start, v.span)
                       for v in model.parameters)
    names = {u.name for u in unknowns}

    def varying(name: str) -> bool:
        return name in names or dae.is_derivative(name)

    equations = tuple(_residual(eq, varying) for eq in model.equations)
    initial = tuple(_residual(eq, varying) for eq in model.initial_equations)
    bases = (dae.derivative_base(n) for r in equations + initial for n in r.variables)
    differentiated = frozenset(b for b in bases if b is not None and b in names)
    return dae.DAE(model.name, unknowns, parameters, equations, initial, model.experiment,
                   model.span, differentiated)
