"""Maximum matching, Dulmage-Mendelsohn parts and the incidence helpers."""

from __future__ import annotations

import numpy as np
import pytest

from springc.structure import (
    DMParts,
    Matching,
    biadjacency,
    dulmage_mendelsohn,
    maximum_matching,
    to_incidence,
    transpose,
    validate_matching,
)


def assert_valid(incidence: list[list[int]], n_var: int, matching: Matching) -> None:
    """Each pair is an edge, each vertex is used at most once, both maps agree."""
    validate_matching(biadjacency(incidence, n_var), matching)
    for eq, var in matching.pairs():
        assert var in incidence[eq]
        assert matching.var_to_eq[var] == eq


def test_biadjacency_merges_duplicates_and_sorts() -> None:
    matrix = biadjacency([[2, 0, 2], [], [1]], 3)
    assert matrix.shape == (3, 3)
    assert to_incidence(matrix) == ((0, 2), (), (1,))
    assert set(matrix.data.tolist()) == {1}


def test_biadjacency_rejects_out_of_range_variable() -> None:
    with pytest.raises(ValueError, match=r"variable index 3 outside 0\.\.2"):
        biadjacency([[0], [3]], 3)


def test_transpose_lists_equations_of_each_variable() -> None:
    assert transpose([[0, 1], [1], [2, 0]], 4) == ((0, 2), (0, 1), (2,), ())


def test_perfect_matching_is_unique_for_triangular_system() -> None:
    incidence = [[0], [0, 1], [1, 2]]
    matching = maximum_matching(incidence, 3)
    assert matching.pairs() == {(0, 0), (1, 1), (2, 2)}
    assert matching.size == 3
    assert matching.is_perfect


def test_matching_needs_augmenting_path() -> None:
    # A greedy choice of x for equation 0 would block equation 1 (which has only x).
    incidence = [[0, 1], [0], [1, 2]]
    matching = maximum_matching(incidence, 3)
    assert matching.pairs() == {(0, 1), (1, 0), (2, 2)}


def test_structurally_singular_system_is_not_perfect() -> None:
    incidence = [[0], [0], [1, 2]]
    matching = maximum_matching(incidence, 3)
    assert_valid(incidence, 3, matching)
    assert matching.size == 2
    assert not matching.is_perfect
    assert matching.eq_to_var.count(-1) == 1
    assert matching.var_to_eq.count(-1) == 1


def test_empty_systems() -> None:
    assert maximum_matching([], 0) == Matching((), ())
    assert maximum_matching([[], []], 0) == Matching((-1, -1), ())
    assert maximum_matching([], 2).is_perfect is False
    assert dulmage_mendelsohn([], 0) == DMParts((), (), (), (), (), ())


def test_random_matching_size_matches_dense_rank_bound() -> None:
    rng = np.random.default_rng(1)
    for _ in range(20):
        n_eq, n_var = rng.integers(1, 12, size=2)
        incidence = [
            sorted(set(rng.integers(0, n_var, size=rng.integers(0, 3)).tolist()))
            for _ in range(n_eq)
        ]
        matching = maximum_matching(incidence, int(n_var))
        assert_valid(incidence, int(n_var), matching)
        # Berge: no augmenting path means maximum; dulmage_mendelsohn raises otherwise.
        parts = dulmage_mendelsohn(incidence, int(n_var), matching)
        assert_dm_partition(incidence, int(n_var), parts)


def assert_dm_partition(incidence: list[list[int]], n_var: int, parts: DMParts) -> None:
    """The parts partition the system; over has surplus equations, under surplus variables."""
    eqs = parts.over_equations + parts.under_equations + parts.well_equations
    vars_ = parts.over_variables + parts.under_variables + parts.well_variables
    assert sorted(eqs) == list(range(len(incidence)))
    assert sorted(vars_) == list(range(n_var))
    assert not parts.over_equations or len(parts.over_equations) > len(parts.over_variables)
    assert not parts.under_variables or len(parts.under_variables) > len(parts.under_equations)
    # The well-determined part is square and perfectly matchable on its own.
    index = {v: k for k, v in enumerate(parts.well_variables)}
    well = [[index[v] for v in incidence[e] if v in index] for e in parts.well_equations]
    assert maximum_matching(well, len(index)).is_perfect


def test_from_eq_to_var_builds_inverse() -> None:
    matching = Matching.from_eq_to_var([2, -1, 0], 4)
    assert matching.var_to_eq == (2, -1, 0, -1)
    assert matching.size == 2
    with pytest.raises(ValueError, match="variable 0 matched to equations 0, 1"):
        Matching.from_eq_to_var([0, 0], 1)


def test_validate_matching_rejects_non_edge_and_wrong_sizes() -> None:
    graph = biadjacency([[0], [1]], 2)
    with pytest.raises(ValueError, match="does not contain"):
        validate_matching(graph, Matching.from_eq_to_var([1, 0], 2))
    with pytest.raises(ValueError, match="matching is for 1 equations"):
        validate_matching(graph, Matching.from_eq_to_var([0], 2))
    with pytest.raises(ValueError, match="disagree"):
        validate_matching(graph, Matching((0, 1), (1, 0)))


# Dulmage-Mendelsohn: x is variable 0, y is variable 1, z is variable 2.


def test_dm_overdetermined_blames_all_three_equations() -> None:
    # x = 1; y = 2; x + y = 3
    parts = dulmage_mendelsohn([[0], [1], [0, 1]], 2)
    assert set(parts.over_equations) == {0, 1, 2}
    assert set(parts.over_variables) == {0, 1}
    assert parts.under_equations == parts.under_variables == ()
    assert parts.well_equations == parts.well_variables == ()


def test_dm_underdetermined_single_equation() -> None:
    # x + y = 1
    parts = dulmage_mendelsohn([[0, 1]], 2)
    assert set(parts.under_equations) == {0}
    assert set(parts.under_variables) == {0, 1}
    assert parts.over_equations == parts.over_variables == ()
    assert parts.well_equations == parts.well_variables == ()


def test_dm_mixed_system_does_not_blame_well_determined_part() -> None:
    # 0: a = 1          (well: a)
    # 1: b = a + 2      (well: b)
    # 2: c = 1          \
    # 3: c = 2           > over: c twice determined, plus d from c
    # 4: d = c          /
    # 5: e + f = b      under: e, f with one equation (b is known from the well part)
    incidence = [[0], [0, 1], [2], [2], [2, 3], [4, 5, 1]]
    parts = dulmage_mendelsohn(incidence, 6)
    assert set(parts.over_equations) == {2, 3}
    assert set(parts.over_variables) == {2}
    assert set(parts.under_equations) == {5}
    assert set(parts.under_variables) == {4, 5}
    assert set(parts.well_equations) == {0, 1, 4}
    assert set(parts.well_variables) == {0, 1, 3}


def test_dm_over_part_reaches_through_alternating_paths() -> None:
    # 0: x = 1; 1: y = x; 2: y = 3; 3: z = 0  -> x, y over-determined by 0, 1, 2.
    parts = dulmage_mendelsohn([[0], [0, 1], [1], [2]], 3)
    assert set(parts.over_equations) == {0, 1, 2}
    assert set(parts.over_variables) == {0, 1}
    assert parts.well_equations == (3,)
    assert parts.well_variables == (2,)


def test_dm_under_part_reaches_through_alternating_paths() -> None:
    # 0: x + y = z; 1: z = 2 * w; 2: v = 1  -> v well, the rest under-determined.
    parts = dulmage_mendelsohn([[0, 1, 2], [2, 3], [4]], 5)
    assert set(parts.under_variables) == {0, 1, 2, 3}
    assert set(parts.under_equations) == {0, 1}
    assert parts.well_equations == (2,)
    assert parts.well_variables == (4,)
    assert parts.over_equations == ()


def test_dm_parts_independent_of_chosen_maximum_matching() -> None:
    incidence = [[0], [0, 1], [1], [2], [3, 4]]
    first = dulmage_mendelsohn(incidence, 5, Matching.from_eq_to_var([0, 1, -1, 2, 3], 5))
    second = dulmage_mendelsohn(incidence, 5, Matching.from_eq_to_var([-1, 0, 1, 2, 4], 5))
    assert first == second
    assert set(first.over_equations) == {0, 1, 2}
    assert set(first.under_variables) == {3, 4}
    assert first.well_equations == (3,)


def test_dm_rejects_non_maximum_matching() -> None:
    with pytest.raises(ValueError, match="not maximum"):
        dulmage_mendelsohn([[0], [1]], 2, Matching.from_eq_to_var([0, -1], 2))


def test_augmenting_path_flips_the_path_and_reports_what_it_visited() -> None:
    from springc.structure.matching import UNMATCHED, augmenting_path

    # left 0 - right {0, 1}; left 1 - right {0}; right 0 is matched to left 1 ...
    neighbours = {0: [0], 1: [0, 1], 2: [1]}
    mate = {0: 1}  # right 0 <- left 1
    found = augmenting_path(0, neighbours.__getitem__, lambda r: mate.get(r, UNMATCHED))
    assert found.pairs == ((0, 0), (1, 1))  # 0 takes right 0, 1 moves on to right 1
    assert found.left == (0, 1) and found.right == (0, 1)
    # ... and with right 1 excluded no path exists; the visited part is returned.
    blocked = augmenting_path(0, neighbours.__getitem__, lambda r: mate.get(r, UNMATCHED),
                              usable=lambda r: r != 1)
    assert blocked.pairs == () and blocked.left == (0, 1) and blocked.right == (0,)


def test_perfectly_matchable_agrees_with_the_maximum_matching() -> None:
    """The Python search of the balance check against scipy's Hopcroft-Karp on 300
    random square incidences (dense enough that about half have a perfect matching),
    and two closed cases: a chain (matchable) and two equations in one variable."""
    from springc.structure import perfectly_matchable

    rng = np.random.default_rng(7)
    answers = []
    for _ in range(300):
        n = int(rng.integers(1, 30))
        rows = [sorted(set(rng.integers(0, n, size=int(rng.integers(1, 5))).tolist()))
                for _ in range(n)]
        expected = maximum_matching(rows, n).is_perfect
        assert perfectly_matchable(rows, n) is expected
        answers.append(expected)
    assert 60 < sum(answers) < 240
    assert perfectly_matchable([[0, 1], [1, 2], [2]], 3) is True
    assert perfectly_matchable([[0], [0], [1, 2]], 3) is False
    assert perfectly_matchable([[0, 1]], 2) is False  # not square
