"""The start values of the variables an algorithm section assigns, while it runs
(section 11.1.2), for :mod:`.algorithms`.

A variable read before the section assigns it has its start value; the section
usually gets those values at the end of flattening (:func:`.algorithms.apply_starts`),
once every variable is known. A ``while`` loop whose condition reads such a variable
needs the value at once to be decided while flattening: :func:`known_starts` gives
the start values that are known constants of the variables the section's
assignments name directly (``y := ...``, ``v[2] := ...`` counts for ``v``).
"""

from __future__ import annotations

from ...errors import FlattenError
from ...ir import expr as x
from ...ir import syntax as s
from ..calls import folded
from ..checks import declared
from ..scopes import ClassScope, FlattenContext, Scope, attributes_of, statements


def known_starts(fl: FlattenContext, body: tuple[s.Statement, ...], where: Scope,
                 owner: ClassScope) -> dict[str, x.Const]:
    """Flat name -> constant start value, for the variables ``body`` assigns."""
    out: dict[str, x.Const] = {}
    for stmt in statements(body):
        if not isinstance(stmt, s.Assign):
            continue
        for target in stmt.targets:
            if target is None or len(target.parts) != 1:
                continue
            ref = s.Ref((s.RefPart(target.parts[0].name, (), target.parts[0].span),),
                        target.span)
            prim = declared(ref, where)
            if prim is None or prim.variability in ("parameter", "constant") \
                    or prim.type == "String":
                continue
            try:
                found = list(attributes_of(fl, owner, prim))
            except FlattenError:  # reported where the declaration is flattened
                continue
            for v in found:
                start = v.attributes.start
                default = x.Const(False) if v.type == "Boolean" else x.ZERO
                value = default if start is None else folded(start)
                if isinstance(value, x.Const):
                    out[v.name] = value
    return out
