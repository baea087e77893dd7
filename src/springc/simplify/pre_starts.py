"""Initial equations ``pre(v) = e`` of discrete variables that no when-clause assigns.

Modelica 3.6, section 8.6: at the initialization ``pre(v)`` is an unknown that such an
equation determines. springc holds the value of ``pre(v)`` before the first event in
the start value of ``v`` (``ode_eval`` seeds ``pre(v)`` from it), so an equation
``pre(v) = e`` (or ``e = pre(v)``) whose ``e`` reads only parameters and constants
(the MSL's ``OnOffController``: ``pre(y) = pre_y_start``) becomes that start value and
leaves the initial problem of the states; ``fixed = true`` on such a variable likewise
sets ``pre(v)`` (its start), not ``v``. When-assigned variables get the same from
``events.discrete_starts``.
"""

from __future__ import annotations

from dataclasses import replace

from ..ir import expr as x
from ..ir import flat
from ..ir.when import assigned
from .events import at_time


def pre_starts(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` with its initial equations ``pre(v) = e`` moved into start values."""
    held = set(assigned(model.whens))
    discrete = {v.name: v for v in model.variables if v.is_unknown and v.name not in held
                and (v.variability == "discrete" or v.type in ("Boolean", "Integer"))}
    known = {v.name for v in model.variables if v.variability == "constant"
             or (v.variability == "parameter" and v.attributes.fixed is not False)}
    starts: dict[str, x.Expr] = {}
    kept = []
    for eq in model.initial_equations:
        name = _pre_of(eq, discrete, known, starts)
        if name is None:
            kept.append(eq)
            continue
        value = eq.rhs if isinstance(eq.lhs, x.Call) and eq.lhs.name == "pre" else eq.lhs
        starts[name] = at_time(value, x.Const(model.experiment.start or 0.0))
    # fixed = true on such a variable also gives pre(v) its start value (8.6), not a
    # condition on v itself (the MSL's IdealGTOThyristor: Boolean off(fixed = true))
    fixed = {name for name, v in discrete.items() if v.attributes.fixed is True}
    if not starts and not fixed:
        return model
    variables = tuple(replace(v, attributes=replace(
        v.attributes, start=starts.get(v.name, v.attributes.start),
        fixed=False if v.name in fixed else v.attributes.fixed))
        if v.name in starts or v.name in fixed else v for v in model.variables)
    return replace(model, variables=variables, initial_equations=tuple(kept))


def _pre_of(eq: flat.Equation, discrete: dict[str, flat.Variable], known: set[str],
            starts: dict[str, x.Expr]) -> str | None:
    """The name ``v`` of an equation ``pre(v) = e`` that gives ``pre(v)``'s value."""
    for side, value in ((eq.lhs, eq.rhs), (eq.rhs, eq.lhs)):
        if isinstance(side, x.Call) and side.name == "pre" and len(side.args) == 1 \
                and isinstance(side.args[0], x.Var) and side.args[0].name in discrete \
                and side.args[0].name not in starts and x.variables(value) <= known \
                and not any(isinstance(n, (x.Der, x.Call)) and not (
                    isinstance(n, x.Call) and n.name in x.MATH) for n in x.walk(value)):
            return side.args[0].name
    return None
