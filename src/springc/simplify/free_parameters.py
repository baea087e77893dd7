"""Parameters computed during initialization: ``parameter Real p(fixed = false)``.

Modelica 3.6, section 8.6: a parameter with ``fixed = false`` is an unknown of the
initialization problem, determined by the initial equations, and constant afterwards.
The Modelica Standard Library uses them for filter coefficients computed by functions
of other parameters (``Blocks.Continuous.Filter``) and for values fixed by the initial
state (``Thermal.HeatTransfer.Examples.TwoMasses``: the final temperature).

This pass runs first on the flat model, taking each such parameter (without a binding)
out of the initialization's unknowns:

1. an initial equation ``p = e`` (or ``e = p``) whose ``e`` reads only parameters,
   constants and parameters already given this way becomes ``p``'s binding, and the
   equation leaves the initial problem (repeated until none is found: a chain of
   coefficients, each computed from the ones before);
2. any other becomes a continuous variable that keeps its start value as a guess, with
   ``der(p) = 0``: a state the initial equations determine, constant during the run;
3. a parameter whose binding reads such a state (directly or through another parameter
   of this rule: ``Forces.Spring``'s ``c`` passed on to its inner line force) is no
   longer known before the initialization either: it becomes a continuous variable with
   its binding as an equation ``q = e``, constant as the states it reads.
"""

from __future__ import annotations

from dataclasses import replace

from ..ir import expr as x
from ..ir import flat


def free_parameters(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` with its ``fixed = false`` parameters bound or turned into states
    (module docstring); the model itself when it has none."""
    free = {v.name for v in model.variables if v.variability == "parameter"
            and v.binding is None and v.attributes.fixed is False}
    if not free:
        return model
    known = {v.name for v in model.variables
             if v.variability in ("parameter", "constant") and v.name not in free}
    bindings: dict[str, x.Expr] = {}
    initial = list(model.initial_equations)
    found = True
    while found:
        found = False
        for eq in list(initial):
            target, value = _definition(eq, free - bindings.keys())
            if target is not None and value is not None and \
                    _reads_only(value, known | bindings.keys()):
                bindings[target] = value
                initial.remove(eq)
                found = True
    stateful = {v.name for v in model.variables if v.name in free - bindings.keys()
                and v.type == "Real"}  # (a Boolean or Integer: rule 1 only)
    dependent = _dependents(model, stateful)
    variables, equations = [], list(model.equations)
    for v in model.variables:
        if v.name in bindings:
            v = replace(v, binding=bindings[v.name])
        elif v.name in stateful:
            v = replace(v, variability="continuous")
            equations.append(flat.Equation(
                x.Der(x.Var(v.name)), x.ZERO, v.span,
                flat.Origin("equation", v.component, f"'{v.name}' is a parameter with "
                            "fixed = false: constant after the initialization")))
        elif v.name in dependent and v.binding is not None:
            equations.append(flat.Equation(
                x.Var(v.name), v.binding, v.span,
                flat.Origin("equation", v.component, f"'{v.name}' is a parameter whose "
                            "binding reads a parameter with fixed = false")))
            v = replace(v, variability="continuous", binding=None)
        variables.append(v)
    return replace(model, variables=tuple(variables), equations=tuple(equations),
                   initial_equations=tuple(initial))


def _dependents(model: flat.FlatModel, stateful: set[str]) -> set[str]:
    """The parameters whose bindings read a name of ``stateful`` or, in turn, one of
    them (rule 3)."""
    reads = {v.name: x.variables(v.binding) for v in model.variables
             if v.variability == "parameter" and v.binding is not None}
    dependent: set[str] = set()
    found = bool(stateful)
    while found:
        found = False
        for name, names in reads.items():
            if name not in dependent and not names.isdisjoint(stateful | dependent):
                dependent.add(name)
                found = True
    return dependent


def _definition(eq: flat.Equation, free: set[str]) -> tuple[str | None, x.Expr | None]:
    """``(p, e)`` for an equation ``p = e`` or ``e = p`` with ``p`` in ``free``."""
    for side, other in ((eq.lhs, eq.rhs), (eq.rhs, eq.lhs)):
        if isinstance(side, x.Var) and side.name in free and side.name not in \
                x.variables(other):
            return side.name, other
    return None, None


def _reads_only(e: x.Expr, names: set[str]) -> bool:
    """Whether ``e`` is an expression of ``names`` alone (no time, derivative or
    event operator)."""
    for node in x.walk(e):
        if isinstance(node, (x.Time, x.Der)):
            return False
        if isinstance(node, x.Call) and node.name in ("pre", "initial", "sample", "edge",
                                                      "change", "terminal", "delay"):
            return False
    return x.variables(e) <= names
