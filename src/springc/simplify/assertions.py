"""Assertions of the simplified model: the flat conditions in terms of what the ODE
computes (states, step variables, parameters, time).

Derivatives become derivative variables as in :mod:`.lower`, and every eliminated
alias is replaced by its value (``a = ±kept`` or a parameter expression), so that a
condition reads only names the generated code has at hand.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir import dae, flat
from ..ir import expr as x
from .alias import Alias
from .lower import lower_derivatives


def simplified_assertions(assertions: Sequence[flat.Assertion], system: dae.DAE,
                          aliases: Sequence[Alias]) -> tuple[flat.Assertion, ...]:
    names = {u.name for u in system.unknowns}

    def varying(name: str) -> bool:
        return name in names or dae.is_derivative(name)

    mapping = {a.name: a.value for a in aliases}
    out = []
    for item in assertions:
        condition = x.substitute(lower_derivatives(item.condition, varying), mapping)
        out.append(flat.Assertion(condition, item.message, item.level, item.span,
                                  item.origin))
    return tuple(out)
