"""Pantelides' algorithm on hand-built integer systems: differentiations and matchings."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pytest

from springc.structure.index import (
    IndexReduction,
    StructurallySingular,
    pantelides,
)


@dataclass(frozen=True)
class Named:
    """A structure with variable names; ``der_<s>`` is the derivative of state ``s``."""

    names: tuple[str, ...]
    incidence: tuple[tuple[int, ...], ...]
    var_derivative: tuple[int, ...]

    def __getitem__(self, name: str) -> int:
        return self.names.index(name)

    def reduce(self, **options) -> IndexReduction:
        n_eq = len(self.incidence)
        return pantelides(
            self.incidence, self.var_derivative, [-1] * n_eq, len(self.names), **options
        )


def named(states: str, algebraic: str, equations: Sequence[str]) -> Named:
    """Variables: states, algebraic, then ``der_<state>``; equations list variable names."""
    names = [*states.split(), *algebraic.split(), *(f"der_{s}" for s in states.split())]
    var_derivative = tuple(names.index(f"der_{n}") if f"der_{n}" in names else -1 for n in names)
    incidence = tuple(tuple(names.index(w) for w in eq.split()) for eq in equations)
    return Named(tuple(names), incidence, var_derivative)


def all_names(system: Named, reduction: IndexReduction) -> list[str]:
    """Names of every variable of ``reduction``; created ones are ``der_<antiderivative>``."""
    names = list(system.names)
    antiderivative = {d: v for v, d in enumerate(reduction.var_derivative) if d != -1}
    for var in range(len(names), reduction.n_var):
        names.append(f"der_{names[antiderivative[var]]}")
    return names


def assert_perfect(reduction: IndexReduction) -> None:
    """Highest-order equations and highest derivatives are perfectly matched."""
    active = [e for e in range(reduction.n_eq) if reduction.eq_derivative[e] == -1]
    highest = [v for v in range(reduction.n_var) if reduction.var_derivative[v] == -1]
    assert len(active) == len(highest)
    assert {reduction.eq_to_var[e] for e in active} == set(highest)
    for eq in active:
        assert reduction.eq_to_var[eq] in reduction.incidence[eq]
        assert reduction.var_to_eq[reduction.eq_to_var[eq]] == eq
    inactive = set(range(reduction.n_eq)) - set(active)
    assert all(reduction.eq_to_var[e] == -1 for e in inactive)
    lower = set(range(reduction.n_var)) - set(highest)
    assert all(reduction.var_to_eq[v] == -1 for v in lower)


ODE = named("x", "", ["der_x x"])

# der(x) = vx, der(y) = vy, der(vx) = -lam*x, der(vy) = -lam*y - g, x^2 + y^2 = L^2
PENDULUM = named(
    "x y vx vy", "lam", ["der_x vx", "der_y vy", "der_vx lam x", "der_vy lam y", "x y"]
)

ROD = named(
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


def test_plain_ode_needs_no_differentiation() -> None:
    reduction = ODE.reduce()
    assert reduction.differentiated == ()
    assert reduction.differentiation_counts() == {}
    assert reduction.n_var == 2
    assert reduction.eq_to_var == (ODE["der_x"],)
    assert reduction.var_to_eq == (-1, 0)
    assert_perfect(reduction)


def test_pendulum_differentiates_constraint_twice_and_position_equations_once() -> None:
    reduction = PENDULUM.reduce()
    assert reduction.differentiation_counts() == {4: 2, 0: 1, 1: 1}
    origins = {reduction.origin(e) for e in range(reduction.n_original_eq, reduction.n_eq)}
    assert origins == {(4, 1), (4, 2), (0, 1), (1, 1)}
    names = all_names(PENDULUM, reduction)
    assert set(names[len(PENDULUM.names) :]) == {"der_der_x", "der_der_y"}
    matched = {names[v] for v in reduction.eq_to_var if v != -1}
    assert matched == {"der_der_x", "der_der_y", "der_vx", "der_vy", "lam"}
    assert_perfect(reduction)


def test_pendulum_structural_incidence_of_derivatives() -> None:
    reduction = PENDULUM.reduce()
    names = all_names(PENDULUM, reduction)
    first = reduction.eq_derivative[4]
    second = reduction.eq_derivative[first]
    assert reduction.eq_derivative[second] == -1
    assert {names[v] for v in reduction.incidence[first]} == {"x", "y", "der_x", "der_y"}
    assert {names[v] for v in reduction.incidence[second]} == {
        "x",
        "y",
        "der_x",
        "der_y",
        "der_der_x",
        "der_der_y",
    }
    speed = reduction.eq_derivative[0]
    assert {names[v] for v in reduction.incidence[speed]} == {"der_x", "vx", "der_der_x", "der_vx"}
    assert all(p < reduction.n_original_eq + k for k, p in enumerate(reduction.differentiated))


def test_rigid_rod_between_two_masses() -> None:
    reduction = ROD.reduce()
    assert reduction.differentiation_counts() == {8: 2, 0: 1, 1: 1, 2: 1, 3: 1}
    assert reduction.n_var == len(ROD.names) + 4
    assert_perfect(reduction)


def test_hook_supplies_the_exact_incidence() -> None:
    rows = list(PENDULUM.incidence)  # the caller's equations, extended as it differentiates
    calls: list[int] = []

    def exact(eq: int, var_derivative: Sequence[int]) -> list[int]:
        calls.append(eq)
        if eq in (0, 1):  # der(p) = v  ->  der(der(p)) = der(v): no p, no v
            row = [var_derivative[v] for v in rows[eq]]
        else:
            row = sorted(set(rows[eq]) | {var_derivative[v] for v in rows[eq]})
        rows.append(tuple(row))
        return row

    reduction = PENDULUM.reduce(differentiate_equation=exact)
    assert calls == [4, 5, 0, 1]
    assert [set(row) for row in reduction.incidence] == [set(row) for row in rows]
    names = all_names(PENDULUM, reduction)
    speed = reduction.eq_derivative[0]
    assert {names[v] for v in reduction.incidence[speed]} == {"der_der_x", "der_vx"}
    assert reduction.differentiation_counts() == {4: 2, 0: 1, 1: 1}
    assert_perfect(reduction)


def test_hook_may_not_add_unrelated_variables() -> None:
    with pytest.raises(ValueError, match="derivative of equation 4 may only contain"):
        PENDULUM.reduce(differentiate_equation=lambda eq, vd: [PENDULUM["lam"]])


def test_redundant_equations_are_structurally_singular() -> None:
    system = named("x", "y", ["der_x y", "y", "y"])
    with pytest.raises(StructurallySingular) as info:
        system.reduce()
    assert info.value.equations == (1, 2)
    assert info.value.variables == (system["y"],)


def test_constraint_on_a_state_and_its_derivative_is_singular() -> None:
    system = named("x", "", ["x", "der_x"])
    with pytest.raises(StructurallySingular) as info:
        system.reduce()
    assert info.value.equations == (0, 1)
    assert info.value.variables == (system["x"], system["der_x"])


def test_equation_without_variables_is_singular() -> None:
    system = named("x", "", ["der_x x", ""])
    with pytest.raises(StructurallySingular) as info:
        system.reduce()
    assert info.value.equations == (1,)


def test_hook_that_never_adds_derivatives_stops_after_max_steps() -> None:
    position = [PENDULUM["x"], PENDULUM["y"]]
    with pytest.raises(StructurallySingular, match="after differentiating 5 times") as info:
        PENDULUM.reduce(differentiate_equation=lambda eq, vd: position, max_steps=5)
    assert info.value.equations == (4,)
    assert info.value.variables == (PENDULUM["x"], PENDULUM["y"])


@pytest.mark.parametrize(
    ("var_derivative", "message"),
    [
        ([2, 2, -1], "variable 2 is the derivative of both 0 and 1"),
        ([0, -1, -1], r"var_derivative\[0\] = 0 is not a valid index"),
        ([1, 0, -1], "variable 0 is its own repeated derivative"),
        ([3, -1, -1], r"var_derivative\[0\] = 3 is not a valid index"),
    ],
)
def test_inconsistent_derivative_maps_are_rejected(var_derivative: list[int], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        pantelides([[0, 2]], var_derivative, [-1], 3)


def test_large_index_one_chain_takes_the_fast_path() -> None:
    # Variables: x_i (0..n-1), der(x_i) (n..2n-1), z_i (2n..3n-1).
    # Equations: der(x_i) = z_i and z_i = x_i + z_{i-1}: 10,000 in all.
    n = 5000
    var_derivative = [n + i for i in range(n)] + [-1] * (2 * n)
    incidence = [(n + i, 2 * n + i) for i in range(n)]
    incidence += [(2 * n + i, i, *((2 * n + i - 1,) if i else ())) for i in range(n)]

    def never_called(eq: int, var_derivative: Sequence[int]) -> list[int]:
        raise AssertionError("an index-1 system must not be differentiated")

    reduction = pantelides(
        incidence, var_derivative, [-1] * (2 * n), 3 * n, differentiate_equation=never_called
    )
    assert reduction.differentiated == ()
    assert reduction.n_var == 3 * n
    assert reduction.incidence == tuple(incidence)
    assert_perfect(reduction)
