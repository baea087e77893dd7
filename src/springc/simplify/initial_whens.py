"""Initial equations ``v = e`` of when-assigned variables whose ``e`` reads variables.

Modelica 3.6, section 8.6: during the initialization a when-clause that is not active
holds its variables (``v = pre(v)``), and the initial equations determine them. An
initial equation ``v = e`` whose ``e`` reads only parameters and ``time`` is ``v``'s
start value (``events.discrete_starts``); one whose ``e`` reads continuous variables
(Blocks.Math.SignalExtrema: ``y_min = u``) is known only once the continuous
initialization is solved. Such equations become a first branch ``when initial()`` of
the when-clause that assigns ``v``: at the initial event ``v = e``, later the clause's
own branches. The states' initial problem no longer counts them.

A when-clause whose conditions already read ``initial()`` is active at the
initialization (its equations hold then): its variables' initial equations stay where
they are.
"""

from __future__ import annotations

from dataclasses import replace

from ..ir import expr as x
from ..ir import flat
from ..ir import when as w
from .events import discrete_starts

_INITIAL = x.Call("initial", ())


def initial_whens(model: flat.FlatModel) -> flat.FlatModel:
    """``model`` with the initial equations ``v = e`` of when-assigned ``v`` whose ``e``
    is no start value moved into a ``when initial()`` branch of ``v``'s clause."""
    if not model.whens or not model.initial_equations:
        return model
    owner = {a.name: k for k, clause in enumerate(model.whens)
             for b in clause.branches for a in b.assignments
             if not any(_reads_initial(c) for branch in clause.branches
                        for c in branch.conditions)}
    taken = discrete_starts(model).equations
    moved: dict[int, list[w.Assignment]] = {}
    kept: list[flat.Equation] = []
    done: set[str] = set()
    for eq in model.initial_equations:
        if id(eq) not in taken and isinstance(eq.lhs, x.Var) and eq.lhs.name in owner \
                and eq.lhs.name not in done:
            done.add(eq.lhs.name)
            moved.setdefault(owner[eq.lhs.name], []).append(
                w.Assignment(eq.lhs.name, eq.rhs, eq.span))
        else:
            kept.append(eq)
    if not moved:
        return model
    whens = tuple(replace(clause, branches=(
        w.WhenBranch((_INITIAL,), tuple(moved[k]), (), (), clause.span),
        *clause.branches)) if k in moved else clause for k, clause in enumerate(model.whens))
    return replace(model, whens=whens, initial_equations=tuple(kept))


def _reads_initial(e: x.Expr) -> bool:
    return any(isinstance(n, x.Call) and n.name == "initial" for n in x.walk(e))
