"""If-expressions chosen by Boolean or Integer parameters whose branches differ in
``der``: ``FlatModel`` -> ``FlatModel`` with the chosen branch.

The MSL's signal adaptors (``Blocks.Interfaces.Adaptors.PotentialToFlowAdaptor``)
write ``y1 = if use_fder then -der(y) else 0``; with ``use_fder = false`` the
derivative must not make ``y`` a differentiated variable (``Translational.Examples.
GenerationOfFMUs`` stopped at "nothing computes der(spring.positionToForce1.y)").
Boolean and Integer parameters are structural (generated code cannot change them,
``codegen.structural_parameters``), so the branch their value chooses is the
equation: only where a branch reads ``der`` is it taken here, before the structure
is analysed; any other if-expression stays as it is.
"""

from __future__ import annotations

from dataclasses import replace

from ..ir import expr as x
from ..ir import flat
from ..ir.nodes import map_children


def parameter_branches(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` with the if-expressions the module docstring describes replaced by
    the branch chosen; the model itself when it has none."""
    values = _structural_values(model)
    if not values:
        return model
    changed = False
    equations = []
    for eq in model.equations:
        if not (_has_if(eq.lhs) or _has_if(eq.rhs)):  # one walk, for most equations
            equations.append(eq)
            continue
        lhs, rhs = _choose(eq.lhs, values), _choose(eq.rhs, values)
        if lhs is not eq.lhs or rhs is not eq.rhs:
            changed = True
            eq = replace(eq, lhs=lhs, rhs=rhs)
        equations.append(eq)
    return replace(model, equations=tuple(equations)) if changed else model


def _structural_values(model: flat.FlatModel) -> dict[str, object]:
    """The values of the Boolean and Integer parameters and constants whose bindings
    evaluate from each other (in declaration order, repeated until none is added)."""
    pending = [v for v in model.variables if v.variability in ("parameter", "constant")
               and v.type in ("Boolean", "Integer") and v.binding is not None]
    values: dict[str, object] = {}
    added = True
    while added and pending:
        added = False
        for v in list(pending):
            assert v.binding is not None
            try:
                values[v.name] = x.evaluate(v.binding, values)
            except (KeyError, ArithmeticError, TypeError, ValueError):
                continue
            pending.remove(v)
            added = True
    return values


def _has_if(e: x.Expr) -> bool:
    return any(isinstance(n, x.If) for n in x.walk(e))


def _reads_der(e: x.Expr) -> bool:
    return any(isinstance(n, x.Der) for n in x.walk(e))


def _choose(e: x.Expr, values: dict[str, object]) -> x.Expr:
    """``e`` with each if-expression whose condition ``values`` decide and one of
    whose branches reads ``der`` replaced by the branch chosen."""
    if not _reads_der(e):
        return e
    if isinstance(e, x.If) and x.variables(e.cond) <= values.keys() and \
            (_reads_der(e.then) or _reads_der(e.otherwise)):
        try:
            chosen = e.then if x.evaluate(e.cond, values) else e.otherwise
        except (KeyError, ArithmeticError, TypeError, ValueError):
            chosen = None
        if chosen is not None:
            return _choose(chosen, values)
    return map_children(e, lambda c: _choose(c, values))
