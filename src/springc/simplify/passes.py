"""Structural simplification: flat.FlatModel -> ode.ODE.

The pipeline is a short list of passes, each in its own module:

0. ``check_balance`` (:mod:`springc.simplify.balance`): as ``springc check`` does, so
   that a missing or surplus equation is reported with its location, before the
   structural passes would find it less clearly;
1. ``free_parameters`` (:mod:`springc.simplify.free_parameters`): ``fixed = false``
   parameters bound by their initial equations, or kept constant as states;
   ``pre_starts`` (:mod:`springc.simplify.pre_starts`): ``pre(v) = e`` initial equations
   as start values; ``initial_whens`` (:mod:`springc.simplify.initial_whens`): initial
   equations ``v = e`` of when-assigned ``v`` reading variables as ``when initial()``
   branches; ``parameter_branches`` (:mod:`springc.simplify.parameter_branches`):
   if-expressions of Boolean or Integer parameters with a `der` in a branch chosen; then
   ``lower`` (:mod:`springc.simplify.lower`): residual equations and derivative variables;
2. ``eliminate_aliases`` (:mod:`springc.simplify.alias`): ``a = ±b`` and ``a = p`` removed;
3. ``index_reduce`` (:mod:`springc.simplify.index_reduction`): Pantelides and dummy derivatives;
4. ``causalize`` (:mod:`springc.simplify.causalize`): matching, BLT, solved blocks.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from ..collector import collector_paused
from ..errors import Note, Span
from ..ir import flat, ode
from .alias import eliminate_aliases
from .assertions import simplified_assertions
from .balance import check_balance, dae_incidence
from .causalize import causalize
from .events import with_events
from .free_parameters import free_parameters
from .hybrid_checks import check_reinits
from .index_reduction import DummyBlock, index_reduce
from .initial_whens import initial_whens
from .lower import lower
from .parameter_branches import parameter_branches
from .pre_starts import pre_starts
from .state_select import check_state_select
from .static_choice import pivot_checks


@dataclass(frozen=True)
class Simplified:
    """The ODE, warnings of the passes, and the blocks of the dummy-derivative choice
    (what :mod:`springc.simplify.state_choice` monitors; empty when no index reduction was done)."""

    ode: ode.ODE
    warnings: tuple[Note, ...]
    blocks: tuple[DummyBlock, ...] = field(default=())


def simplify(model: flat.FlatModel, at: Mapping[str, float] | None = None) -> Simplified:
    """Run the passes of the module docstring on ``model``.

    ``at``: values of variables (by name; derivatives as ``der(x)``) at which the
    states are chosen: each dummy-derivative block is then the best-conditioned
    choice there (:func:`springc.simplify.index_reduction.pivoted_choice`), instead of the default
    priority choice checked at the start values. Used to switch states during a
    simulation (:mod:`springc.simplify.state_choice`).

    The cyclic garbage collector is paused meanwhile: the passes allocate millions of
    small acyclic nodes, and its full collections, each scanning the whole (large)
    flat model, made the run superlinear in the model size.
    """
    with collector_paused():
        return _simplify(model, at)


def _pivot_checks(blocks: Sequence[DummyBlock], span: Span) -> tuple[flat.Assertion, ...]:
    """The run-time checks of the default choice's blocks that may turn singular
    (:func:`springc.simplify.static_choice.pivot_checks`; none where one cannot be
    checked)."""
    checks = pivot_checks([(b.equations, b.candidates, b.dummies, b.tiers, b.span or span)
                           for b in blocks if b.switchable])
    return checks or ()


def _simplify(model: flat.FlatModel, at: Mapping[str, float] | None) -> Simplified:
    model = parameter_branches(initial_whens(pre_starts(free_parameters(model))))
    system = lower(model)
    check_balance(model, dae_incidence(system))
    aliased = eliminate_aliases(system)
    reduced = index_reduce(aliased.dae, at)
    steps = causalize(reduced)
    unknowns = {u.name: u for u in aliased.dae.unknowns}
    check_state_select(unknowns.values(), {reduced.names[s] for s, _ in reduced.states})
    states = []
    for state, derivative in reduced.states:
        name = reduced.names[state]
        u = unknowns.get(name)
        states.append(ode.State(name, reduced.names[derivative],
                                u.start if u else None, bool(u and u.fixed),
                                u.nominal if u else None, u.unit if u else None,
                                u.span if u else model.span))
    observed = tuple(ode.Assign(a.name, a.value, a.equation.span) for a in aliased.aliases)
    assertions = simplified_assertions(model.assertions, system, aliased.aliases)
    if at is None:
        assertions += _pivot_checks(reduced.blocks, model.span)
    result = ode.ODE(model.name, tuple(states), tuple(steps), observed,
                     aliased.dae.parameters, aliased.dae, assertions=assertions)
    result = with_events(model, result)
    if result.events is not None:
        check_reinits(model, result)
    return Simplified(result, aliased.warnings, reduced.blocks)
