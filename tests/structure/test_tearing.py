"""Tearing of algebraic loops: number of tearing variables and a valid inner order."""

from __future__ import annotations

import numpy as np
import pytest

from springc.structure import Matching, Tearing, blt, maximum_matching, tear


def always(eq: int, var: int) -> bool:
    return True


def never(eq: int, var: int) -> bool:
    return False


def assert_valid_tearing(block, incidence, matching: Matching, solvable, result: Tearing) -> None:
    """Unknowns split into tearing and inner variables, equations into residual and inner
    ones; each inner variable is solvable from its equation given what is already known."""
    unknowns = {matching.eq_to_var[e] for e in block}
    inner_eqs = [e for e, _ in result.inner]
    inner_vars = [v for _, v in result.inner]
    assert sorted(inner_eqs + list(result.residual_equations)) == sorted(block)
    assert sorted(inner_vars + list(result.tearing_variables)) == sorted(unknowns)
    assert len(result.tearing_variables) == len(result.residual_equations)
    known = set(result.tearing_variables)
    for eq, var in result.inner:
        assert var in incidence[eq] and solvable(eq, var)
        assert {v for v in incidence[eq] if v in unknowns} - known == {var}
        known.add(var)


def cyclic_chain(n: int) -> list[list[int]]:
    """Equation i: x[i] = f(x[i-1]); equation 0 closes the loop with x[n-1]."""
    return [[i, (i - 1) % n] for i in range(n)]


def test_chain_loop_needs_one_tearing_variable() -> None:
    incidence = cyclic_chain(6)
    matching = maximum_matching(incidence, 6)
    result = tear(range(6), incidence, matching, always)
    assert len(result.tearing_variables) == 1
    assert len(result.inner) == 5
    assert_valid_tearing(range(6), incidence, matching, always, result)


def test_chain_loop_with_one_unsolvable_pair_still_needs_one() -> None:
    incidence = cyclic_chain(5)
    matching = maximum_matching(incidence, 5)

    def solvable(eq: int, var: int) -> bool:
        return (eq, var) != (2, 2)  # x[2] appears nonlinearly in equation 2

    result = tear(range(5), incidence, matching, solvable)
    assert len(result.tearing_variables) == 1
    assert_valid_tearing(range(5), incidence, matching, solvable, result)


def test_nothing_solvable_tears_every_variable() -> None:
    incidence = [[0, 1, 2], [1, 2], [2, 0]]
    matching = maximum_matching(incidence, 3)
    result = tear([0, 1, 2], incidence, matching, never)
    assert set(result.tearing_variables) == {0, 1, 2}
    assert set(result.residual_equations) == {0, 1, 2}
    assert result.inner == ()


def test_variable_solvable_nowhere_is_the_tearing_variable() -> None:
    # x0 appears only inside sin(): it must be iterated; x1, x2 follow explicitly.
    incidence = [[0, 1], [1, 2], [2, 0]]
    matching = maximum_matching(incidence, 3)

    def solvable(eq: int, var: int) -> bool:
        return var != 0

    result = tear([0, 1, 2], incidence, matching, solvable)
    assert result.tearing_variables == (0,)
    assert_valid_tearing([0, 1, 2], incidence, matching, solvable, result)


def test_massless_node_loop_is_torn_with_one_variable() -> None:
    # Variables: 0 node.x, 1 spring1.f, 2 spring2.f, 3 der(mass.x), 4 der(mass.v).
    incidence = [[1, 0], [2, 0], [1, 2], [3], [4, 2]]
    matching = maximum_matching(incidence, 5)
    blocks = blt(incidence, matching)
    loop = next(block for block in blocks if len(block) > 1)
    result = tear(loop, incidence, matching, always)
    assert len(result.tearing_variables) == 1
    assert len(result.residual_equations) == 1
    assert_valid_tearing(loop, incidence, matching, always, result)


def test_known_variables_from_earlier_blocks_are_ignored() -> None:
    # Variable 0 is computed by equation 0 in an earlier block; the loop is {1, 2}.
    incidence = [[0], [1, 2, 0], [2, 1, 0]]
    matching = Matching.from_eq_to_var([0, 1, 2], 3)
    result = tear([1, 2], incidence, matching, always)
    assert len(result.tearing_variables) == 1
    assert_valid_tearing([1, 2], incidence, matching, always, result)
    assert 0 not in result.tearing_variables


def test_seed_model_singletons_need_no_tearing() -> None:
    incidence = [[0, 1, 2], [1], [2], [3], [4], [5, 1, 0], [6, 2, 0]]
    matching = maximum_matching(incidence, 7)
    for block in blt(incidence, matching):
        result = tear(block, incidence, matching, always)
        assert result.tearing_variables == ()
        assert result.inner == ((block[0], matching.eq_to_var[block[0]]),)


def test_singleton_that_cannot_be_solved_becomes_residual() -> None:
    result = tear([0], [[0]], Matching((0,), (0,)), never)
    assert result == Tearing(tearing_variables=(0,), residual_equations=(0,), inner=())


def test_heuristic_prefers_variable_that_unlocks_most_equations() -> None:
    # Equations 0..3 each hold the hub h (variable 0) and one leaf; the leaves link in a
    # ring through equation 4. Tearing the hub frees all leaves at once.
    incidence = [[1, 0], [2, 0], [3, 0], [4, 0], [1, 2, 3, 4, 0]]
    matching = maximum_matching(incidence, 5)
    result = tear(range(5), incidence, matching, always)
    assert result.tearing_variables == (0,)
    assert_valid_tearing(range(5), incidence, matching, always, result)


def test_rejects_block_equation_without_matched_variable() -> None:
    with pytest.raises(ValueError, match="not matched"):
        tear([0], [[0]], Matching((-1,), (-1,)), always)


def test_random_loops_give_valid_tearings() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        n = int(rng.integers(2, 12))
        incidence = [
            sorted({i, *rng.integers(0, n, size=rng.integers(1, 4)).tolist()}) for i in range(n)
        ]
        matching = Matching.from_eq_to_var(range(n), n)
        unsolvable = {(e, v) for e, row in enumerate(incidence) for v in row if rng.random() < 0.3}

        def solvable(eq: int, var: int, unsolvable=unsolvable) -> bool:
            return (eq, var) not in unsolvable

        for block in blt(incidence, matching):
            result = tear(block, incidence, matching, solvable)
            assert_valid_tearing(block, incidence, matching, solvable, result)


def test_large_ring_loop_tears_once() -> None:
    incidence = cyclic_chain(20_000)
    matching = maximum_matching(incidence, 20_000)
    (block,) = blt(incidence, matching)
    result = tear(block, incidence, matching, always)
    assert len(result.tearing_variables) == 1
    assert_valid_tearing(block, incidence, matching, always, result)
