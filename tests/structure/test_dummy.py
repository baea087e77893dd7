"""Dummy derivatives after Pantelides: chosen states as sets, priorities, numeric vetting."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import pytest

from springc.structure.dummy import (
    AVOID,
    DEFAULT,
    NEVER,
    PREFER,
    NumericallySingular,
    StateSelection,
    dummy_derivatives,
    state_priority,
)
from springc.structure.index import IndexReduction, StructurallySingular, pantelides


@dataclass(frozen=True)
class Reduced:
    """A reduced structure with names for every variable (created ones: ``der_<v>``)."""

    reduction: IndexReduction
    names: tuple[str, ...]

    def select(self, prefer: Sequence[str] = (), **options) -> StateSelection:
        """Dummy derivatives with ``stateSelect = prefer`` on the named variables."""
        priority = [PREFER if name in prefer else DEFAULT for name in self.names]
        return dummy_derivatives(self.reduction, priority, **options)

    def states(self, selection: StateSelection) -> set[str]:
        return {self.names[v] for v in selection.states}

    def dummies(self, selection: StateSelection) -> set[str]:
        return {self.names[v] for v in selection.dummy_derivatives}


def reduce(states: str, algebraic: str, equations: Sequence[str]) -> Reduced:
    """Build a system (variables: states, algebraic, ``der_<state>``) and run Pantelides."""
    names = [*states.split(), *algebraic.split(), *(f"der_{s}" for s in states.split())]
    var_derivative = [names.index(f"der_{n}") if f"der_{n}" in names else -1 for n in names]
    incidence = [[names.index(w) for w in eq.split()] for eq in equations]
    reduction = pantelides(incidence, var_derivative, [-1] * len(incidence), len(names))
    antiderivative = {d: v for v, d in enumerate(reduction.var_derivative) if d != -1}
    for var in range(len(names), reduction.n_var):
        names.append(f"der_{names[antiderivative[var]]}")
    return Reduced(reduction, tuple(names))


def pendulum() -> Reduced:
    # der(x) = vx, der(y) = vy, der(vx) = -lam*x, der(vy) = -lam*y - g, x^2 + y^2 = L^2
    return reduce(
        "x y vx vy", "lam", ["der_x vx", "der_y vy", "der_vx lam x", "der_vy lam y", "x y"]
    )


def rod() -> Reduced:
    # Two masses in the plane joined by a rigid rod of length L.
    return reduce(
        "x1 y1 x2 y2 vx1 vy1 vx2 vy2",
        "lam",
        [
            "der_x1 vx1",
            "der_y1 vy1",
            "der_x2 vx2",
            "der_y2 vy2",
            "der_vx1 lam x1 x2",
            "der_vy1 lam y1 y2",
            "der_vx2 lam x1 x2",
            "der_vy2 lam y1 y2",
            "x1 y1 x2 y2",
        ],
    )


def assert_consistent(selection: StateSelection, reduction: IndexReduction) -> None:
    """States and dummies partition the derivatives; dummies are nested downwards."""
    derivatives = {d for d in reduction.var_derivative if d != -1}
    assert set(selection.state_derivatives) | set(selection.dummy_derivatives) == derivatives
    assert not set(selection.state_derivatives) & set(selection.dummy_derivatives)
    for state, derivative in zip(selection.states, selection.state_derivatives, strict=True):
        assert reduction.var_derivative[state] == derivative
    for dummy in selection.dummy_derivatives:
        higher = reduction.var_derivative[dummy]
        assert higher == -1 or higher in selection.dummy_derivatives
    for block in selection.blocks:
        assert len(block.equations) == len(block.dummies)


def test_plain_ode_keeps_its_state() -> None:
    system = reduce("x", "", ["der_x x"])
    selection = system.select()
    assert system.states(selection) == {"x"}
    assert selection.state_derivatives == (system.names.index("der_x"),)
    assert selection.dummy_derivatives == ()
    assert selection.blocks == ()


def test_index_two_constraint_removes_the_only_state() -> None:
    # der(x) = f(x, z), g(x) = 0: x is fixed by g, so der(x) becomes a dummy.
    system = reduce("x", "z", ["der_x x z", "x"])
    assert system.reduction.differentiation_counts() == {1: 1}
    selection = system.select()
    assert selection.states == ()
    assert system.dummies(selection) == {"der_x"}


def test_pendulum_keeps_two_states() -> None:
    system = pendulum()
    selection = system.select()
    assert system.states(selection) in ({"x", "vx"}, {"y", "vy"})
    assert len(system.dummies(selection)) == 4
    assert [block.level for block in selection.blocks] == [1, 2]
    assert_consistent(selection, system.reduction)


def test_pendulum_ties_keep_the_lower_index_family() -> None:
    system = pendulum()
    assert system.states(system.select()) == {"x", "vx"}


def test_pendulum_prefer_y_and_vy() -> None:
    system = pendulum()
    selection = system.select(prefer=("y", "vy"))
    assert system.states(selection) == {"y", "vy"}
    assert system.dummies(selection) == {"der_der_x", "der_vx", "der_der_y", "der_x"}
    assert_consistent(selection, system.reduction)


def test_pendulum_prefer_x_and_vx() -> None:
    system = pendulum()
    assert system.states(system.select(prefer=("x", "vx"))) == {"x", "vx"}


def test_pendulum_never_and_fixed_start() -> None:
    system = pendulum()
    priority = [DEFAULT] * system.reduction.n_var
    priority[system.names.index("x")] = NEVER
    states = system.states(dummy_derivatives(system.reduction, priority))
    assert len(states) == 2 and "x" not in states
    priority[system.names.index("vy")] = PREFER
    assert system.states(dummy_derivatives(system.reduction, priority)) == {"y", "vy"}
    priority[system.names.index("vy")] = DEFAULT
    priority[system.names.index("x")] = state_priority("default", fixed_start=True)
    assert system.states(dummy_derivatives(system.reduction, priority)) == {"x", "vx"}


def test_rigid_rod_keeps_three_degrees_of_freedom() -> None:
    system = rod()
    selection = system.select()
    assert len(selection.states) == 6
    assert_consistent(selection, system.reduction)
    steered = system.select(prefer=("x1", "y1", "x2", "vx1", "vy1", "vx2"))
    assert system.states(steered) == {"x1", "y1", "x2", "vx1", "vy1", "vx2"}


def test_numeric_check_replaces_a_rejected_block() -> None:
    system = pendulum()
    der_vx = system.names.index("der_vx")
    calls: list[tuple[tuple[int, ...], tuple[int, ...]]] = []

    def without_der_vx(rows: tuple[int, ...], cols: tuple[int, ...]) -> bool:
        calls.append((rows, cols))
        return der_vx not in cols

    selection = system.select(prefer=("y", "vy"), is_nonsingular=without_der_vx)
    level_one = {system.names[v] for v in calls[0][1]}
    assert level_one == {"der_der_x", "der_vx", "der_der_y"}
    assert system.dummies(selection) == {"der_der_x", "der_der_y", "der_vy", "der_x"}
    assert system.states(selection) == {"y", "vx"}
    assert_consistent(selection, system.reduction)


def test_numeric_check_rejecting_everything_raises() -> None:
    system = pendulum()
    with pytest.raises(NumericallySingular) as info:
        system.select(is_nonsingular=lambda rows, cols: False)
    assert len(info.value.equations) == 3
    assert {system.names[v] for v in info.value.variables} == {
        "der_der_x",
        "der_der_y",
        "der_vx",
        "der_vy",
    }


def test_differentiated_equation_without_candidates_is_singular() -> None:
    # Equation 1 claims to be d/dt of equation 0 but holds no derivative at all.
    reduction = IndexReduction(
        incidence=((0,), (0,)),
        var_derivative=(-1,),
        eq_derivative=(1, -1),
        n_var=1,
        eq_to_var=(-1, 0),
        var_to_eq=(1,),
        differentiated=(0,),
        n_original_eq=1,
        n_original_var=1,
    )
    with pytest.raises(StructurallySingular) as info:
        dummy_derivatives(reduction)
    assert info.value.equations == (0,)
    assert info.value.variables == (0,)


def test_state_priority_scale() -> None:
    assert state_priority("always") == math.inf
    assert state_priority("never") == -math.inf
    ordered = [
        state_priority("avoid"),
        state_priority("avoid", fixed_start=True),
        state_priority("default"),
        state_priority("default", fixed_start=True),
        state_priority("prefer"),
    ]
    assert ordered == sorted(ordered) and len(set(ordered)) == 5
    assert state_priority("avoid") == AVOID
    with pytest.raises(ValueError, match="unknown stateSelect 'sometimes'"):
        state_priority("sometimes")


def test_too_many_priorities_are_rejected() -> None:
    system = pendulum()
    with pytest.raises(ValueError, match="priorities for 11 variables"):
        dummy_derivatives(system.reduction, [DEFAULT] * 12)


def test_large_index_one_chain_keeps_every_state() -> None:
    n = 5000
    var_derivative = [n + i for i in range(n)] + [-1] * (2 * n)
    incidence = [(n + i, 2 * n + i) for i in range(n)]
    incidence += [(2 * n + i, i, *((2 * n + i - 1,) if i else ())) for i in range(n)]
    reduction = pantelides(incidence, var_derivative, [-1] * (2 * n), 3 * n)
    selection = dummy_derivatives(reduction)
    assert selection.states == tuple(range(n))
    assert selection.state_derivatives == tuple(range(n, 2 * n))
    assert selection.dummy_derivatives == ()
