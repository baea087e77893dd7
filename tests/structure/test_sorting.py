"""Block lower triangular ordering: blocks as sets, and their order constraints."""

from __future__ import annotations

import numpy as np
import pytest

from springc.structure import Matching, blt, maximum_matching


def assert_evaluation_order(incidence: list[list[int]], matching: Matching, blocks) -> None:
    """Blocks partition the equations and each one only uses earlier or own variables."""
    position = {}
    for k, block in enumerate(blocks):
        for eq in block:
            position[eq] = k
    assert sorted(position) == list(range(len(incidence)))
    for eq, variables in enumerate(incidence):
        for var in variables:
            assert position[matching.var_to_eq[var]] <= position[eq]


def block_sets(blocks) -> list[frozenset[int]]:
    return [frozenset(block) for block in blocks]


# The seed model: one spring from a fixed point to a mass, states mass.pos and mass.v.
SEED_VARIABLES = [
    "spring.x",
    "spring.dir[1]",
    "spring.dir[2]",
    "der(mass.pos[1])",
    "der(mass.pos[2])",
    "der(mass.v[1])",
    "der(mass.v[2])",
]
SEED_INCIDENCE = [
    [0, 1, 2],  # spring.x = sqrt(dir[1]^2 + dir[2]^2)
    [1],  # spring.dir[1] = mass.pos[1] - c[1]
    [2],  # spring.dir[2] = mass.pos[2] - c[2]
    [3],  # der(mass.pos[1]) = mass.v[1]
    [4],  # der(mass.pos[2]) = mass.v[2]
    [5, 1, 0],  # der(mass.v[1]) = -k*dir[1]*(x - l)/x/m + g[1]
    [6, 2, 0],  # der(mass.v[2]) = -k*dir[2]*(x - l)/x/m + g[2]
]


def test_seed_model_has_seven_singletons_in_dependency_order() -> None:
    matching = maximum_matching(SEED_INCIDENCE, len(SEED_VARIABLES))
    blocks = blt(SEED_INCIDENCE, matching)
    assert all(len(block) == 1 for block in blocks)
    assert set(block_sets(blocks)) == {frozenset({e}) for e in range(7)}
    assert_evaluation_order(SEED_INCIDENCE, matching, blocks)
    order = [block[0] for block in blocks]
    assert order.index(1) < order.index(0) and order.index(2) < order.index(0)
    assert order.index(0) < order.index(5) and order.index(0) < order.index(6)
    # Ties go to the smallest equation index, so the order is fully determined.
    assert order == [1, 2, 0, 3, 4, 5, 6]


def test_massless_node_between_two_springs_forms_one_linear_loop() -> None:
    # Variables: 0 node.x, 1 spring1.f, 2 spring2.f, 3 der(mass.x), 4 der(mass.v).
    incidence = [
        [1, 0],  # spring1.f = k1 * (node.x - l1)
        [2, 0],  # spring2.f = k2 * (mass.x - node.x - l2)
        [1, 2],  # spring1.f - spring2.f = 0  (no mass at the node)
        [3],  # der(mass.x) = mass.v
        [4, 2],  # m * der(mass.v) = -spring2.f
    ]
    matching = maximum_matching(incidence, 5)
    blocks = blt(incidence, matching)
    assert set(block_sets(blocks)) == {frozenset({0, 1, 2}), frozenset({3}), frozenset({4})}
    assert_evaluation_order(incidence, matching, blocks)
    sets = block_sets(blocks)
    assert sets.index(frozenset({0, 1, 2})) < sets.index(frozenset({4}))


def test_blocks_do_not_depend_on_which_perfect_matching_is_used() -> None:
    # Two equations in x, y both: one loop whichever way they are matched.
    incidence = [[0, 1], [0, 1], [2, 0]]
    first = blt(incidence, Matching.from_eq_to_var([0, 1, 2], 3))
    second = blt(incidence, Matching.from_eq_to_var([1, 0, 2], 3))
    assert first == second == ((0, 1), (2,))


def test_nested_loops_and_a_diamond() -> None:
    # 0: a        1: b(a, c)  2: c(b)     -> loop {1, 2} after {0}
    # 3: d(a)     4: e(c, d, f) 5: f(e)   -> loop {4, 5} after {1, 2} and {3}
    incidence = [[0], [1, 0, 2], [2, 1], [3, 0], [4, 2, 3, 5], [5, 4]]
    matching = maximum_matching(incidence, 6)
    blocks = blt(incidence, matching)
    assert blocks == ((0,), (1, 2), (3,), (4, 5))
    assert_evaluation_order(incidence, matching, blocks)


def test_blt_requires_perfect_matching() -> None:
    incidence = [[0], [0]]
    with pytest.raises(ValueError, match="perfect matching"):
        blt(incidence, maximum_matching(incidence, 1))


def test_blt_of_empty_system() -> None:
    assert blt([], Matching((), ())) == ()


def random_system(n_eq: int, seed: int) -> tuple[list[list[int]], list[frozenset[int]]]:
    """A permuted chain of small loops with random references to earlier loops.

    Returns the incidence and the loops (the expected blocks) in equation indices.
    """
    rng = np.random.default_rng(seed)
    # Step 1: cut 0..n_eq-1 into loops of 1 to 3 equations.
    stops = np.cumsum(rng.choice([1, 1, 1, 2, 3], size=n_eq))
    stops = np.append(stops[stops < n_eq], n_eq)
    starts = np.concatenate([[0], stops[:-1]])
    size = np.repeat(stops - starts, stops - starts)
    start = np.repeat(starts, stops - starts)
    # Step 2: equation i holds variable i, its loop neighbour's variable (cyclically)
    # and two variables of earlier loops (when there are any).
    i = np.arange(n_eq)
    neighbour = start + (i - start + 1) % size
    earlier = (rng.random((2, n_eq)) * start).astype(np.int64)
    has_earlier = start > 0
    # Step 3: renumber equations and variables at random.
    eq_perm = rng.permutation(n_eq)
    var_perm = rng.permutation(n_eq)
    columns = [var_perm[c].tolist() for c in (i, neighbour, earlier[0], earlier[1])]
    incidence: list[list[int]] = [[] for _ in range(n_eq)]
    for k, (own, other, e0, e1, old) in enumerate(zip(*columns, has_earlier.tolist(), strict=True)):
        incidence[eq_perm[k]] = [own, other, e0, e1] if old else [own, other]
    loops = [frozenset(eq_perm[a:b].tolist()) for a, b in zip(starts, stops, strict=True)]
    return incidence, loops


def test_random_large_system_blocks_and_order() -> None:
    incidence, loops = random_system(100_000, seed=7)
    matching = maximum_matching(incidence, len(incidence))
    assert matching.is_perfect
    blocks = blt(incidence, matching)
    assert set(block_sets(blocks)) == set(loops)
    assert len(blocks) == len(loops)
    assert_evaluation_order(incidence, matching, blocks)
