"""``delay(expr, delayTime[, delayMax])`` in the generated module (Modelica 3.6, 3.7.4.1).

The generated functions are pure functions of ``(t, x, p, z)``, so the history of a
delayed expression lives with the simulation (:mod:`springc.simulation.delays`): the
k-th distinct ``delay`` call of the system reads its value from the slot
``z[Z_DELAYS + k]`` (local ``_zdl<k>``), which the simulation fills before each
evaluation from the history of ``expr`` at ``t - delayTime`` (``Z_DELAYS``).
``delay_inputs(t, x, p, z)`` returns ``[expr_0, ..., expr_n-1, delayTime_0, ...,
delayTime_n-1]`` at ``(t, x)``: what the simulation records after each step and the
delay times it looks back by. ``DELAYS`` is the number of delay calls (0: none).
"""

from __future__ import annotations

import dataclasses

from ..ir import expr as x
from ..ir import ode
from .encoding import encode_strings
from .statements import Load, Raw, Stmt, Store

NAME = "delay"


def _calls(e: x.Expr, out: dict[x.Call, None]) -> None:
    """The delay calls of ``e`` into ``out``, in :func:`ir.expr.walk`'s order (their
    slots' order)."""
    x.calls_named([e], NAME, out)


def _replace(e: x.Expr, names: dict[x.Call, x.Var]) -> x.Expr:
    if isinstance(e, x.Call) and e in names:
        return names[e]
    return x.map_children(e, lambda c: _replace(c, names))


class DelayLayout:
    """The delay calls of ``system`` and the system reading their slots instead."""

    def __init__(self, system: ode.ODE) -> None:
        found: dict[x.Call, None] = {}
        for step in system.steps:
            for e in ode.step_expressions(step):
                _calls(e, found)
        for a in system.observed:
            _calls(a.expr, found)
        for item in system.assertions:
            _calls(item.condition, found)
        self.calls = list(found)
        self.names = [f"_zdl{k}" for k in range(len(self.calls))]
        self.base = 0  # set by the context: the first slot after the event slots
        self.system = system
        if self.calls:
            mapping = {c: x.Var(n) for c, n in zip(self.calls, self.names)}

            def f(e: x.Expr) -> x.Expr:
                return _replace(e, mapping)

            self.system = dataclasses.replace(
                system, steps=tuple(ode.map_step(s, f) for s in system.steps),
                observed=tuple(ode.Assign(a.name, f(a.expr), a.span)
                               for a in system.observed),
                assertions=tuple(dataclasses.replace(item, condition=f(item.condition))
                                 for item in system.assertions))

    def __len__(self) -> int:
        return len(self.calls)

    def loads(self) -> list[Stmt]:
        return [Load(n, f"z[{self.base + k}]", n) for k, n in enumerate(self.names)]

    def inputs_body(self, base: list[Stmt]) -> list[Stmt]:
        """``delay_inputs``: ``base`` (loads, steps, aliases), then the values."""
        n = len(self.calls)
        out = [*base, Raw(f"di = np.empty({2 * n})")]
        for k, call in enumerate(self.calls):
            out.append(Store(f"di[{k}]", call.args[0], x.to_text(call)))
            out.append(Store(f"di[{n + k}]", call.args[1], "delay time"))
        return out

    def constants(self) -> list[str]:
        """The module constants (none without delay calls: ``DELAYS`` then reads 0
        through ``getattr``, as the generated-module contract has no delay names)."""
        if not self.calls:
            return []
        return [f"DELAYS = {len(self.calls)}",
                f"Z_DELAYS = {self.base}",
                f"DELAY_CALLS = {encode_strings([x.to_text(c) for c in self.calls])}"]


def used_names(layout: DelayLayout) -> set[str]:
    """The model names the arguments of the delay calls read."""
    out: set[str] = set()
    for call in layout.calls:
        for arg in call.args[:2]:
            out |= x.variables(arg)
    return out
