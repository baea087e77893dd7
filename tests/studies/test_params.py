"""Parameter specifications, grids and samples: exact values, reproducibility, the
Latin hypercube's stratification, and the messages for bad specifications."""

from __future__ import annotations

import numpy as np
import pytest

from springc.errors import UsageError
from springc.studies import Distribution, grid, parse_parameter, sample, unit_points


def test_lists_and_ranges_give_exact_values() -> None:
    assert parse_parameter("m=0.5,1,2").values == (0.5, 1.0, 2.0)
    assert parse_parameter("k=1:100:log:3").values == (1.0, 10.0, 100.0)
    assert parse_parameter("x=0:1:5").values == (0.0, 0.25, 0.5, 0.75, 1.0)
    assert parse_parameter("x=0:1:lin:3").values == (0.0, 0.5, 1.0)
    assert parse_parameter("k=1e3:1e5:log:20").values == tuple(np.geomspace(1e3, 1e5, 20))


def test_grid_is_the_cartesian_product_first_parameter_slowest() -> None:
    table = grid([parse_parameter("a=1,2"), parse_parameter("b=10,20,30")])
    assert table.tolist() == [[1, 10], [1, 20], [1, 30], [2, 10], [2, 20], [2, 30]]


def test_ranges_without_count_and_calls_are_distributions() -> None:
    assert parse_parameter("k=1:2").distribution == Distribution("uniform", (1.0, 2.0))
    assert parse_parameter("k=1:2:log").distribution == Distribution("loguniform",
                                                                     (1.0, 2.0))
    assert parse_parameter("m=normal(1, 0.1)").distribution == Distribution(
        "normal", (1.0, 0.1))


def test_monte_carlo_maps_numpy_draws_through_the_inverse_cdf() -> None:
    table = sample([parse_parameter("a=2:4"), parse_parameter("b=normal(0, 2)")], 50,
                   "mc", seed=7)
    u = np.random.default_rng(7).random((50, 2))
    assert np.array_equal(table[:, 0], 2 + 2 * u[:, 0])
    from scipy import stats

    assert np.array_equal(table[:, 1], stats.norm(0, 2).ppf(u[:, 1]))


@pytest.mark.parametrize("spec", ["k=1e3:1e5:log", "m=normal(1, 0.1)",
                                  "x=triangular(0, 1, 4)", "y=lognormal(0, 0.5)"])
def test_latin_hypercube_puts_one_run_in_each_stratum(spec: str) -> None:
    parameter = parse_parameter(spec)
    n = 40
    values = sample([parameter, parse_parameter("other=0:1")], n, "lhs", seed=3)[:, 0]
    assert parameter.distribution is not None
    strata = np.floor(parameter.distribution.cdf(values) * n + 1e-9).astype(int)
    assert sorted(strata.tolist()) == list(range(n))


def test_samples_are_reproducible_from_the_seed() -> None:
    specs = [parse_parameter("k=1:2"), parse_parameter("m=3:4")]
    first, again = sample(specs, 20, "lhs", 11), sample(specs, 20, "lhs", 11)
    assert np.array_equal(first, again)
    assert not np.array_equal(first, sample(specs, 20, "lhs", 12))
    assert np.array_equal(unit_points(5, 2, "lhs", 1), unit_points(5, 2, "lhs", 1))


@pytest.mark.parametrize(("item", "message"), [
    ("k", "--param: expected NAME=VALUES, got 'k'"),
    ("k=1,x", "--param k=1,x: 'x' is not a number"),
    ("k=1,inf", "--param k=1,inf: inf is not a finite number"),
    ("k=0:1:log:3", "--param k=0:1:log:3: a log range needs START and STOP > 0"),
    ("k=0:1:many", "--param k=0:1:many: COUNT must be a whole number >= 1, not 'many'"),
    ("k=gamma(1, 2)", "--param k=gamma(1, 2): unknown distribution 'gamma' (choose from "
     "uniform, loguniform, normal, lognormal, triangular)"),
    ("k=normal(1)", "--param k=normal(1): normal takes 2 arguments (normal(MEAN, STD)), "
     "not 1"),
    ("k=normal(1, 0)", "--param k=normal(1, 0): STD must be > 0"),
])
def test_bad_specifications_are_named(item: str, message: str) -> None:
    with pytest.raises(UsageError) as caught:
        parse_parameter(item)
    assert caught.value.message == message
    assert caught.value.option == "--param"


def test_grid_and_samples_refuse_the_other_kind() -> None:
    with pytest.raises(UsageError, match="give --samples N"):
        grid([parse_parameter("k=1:2")])
    with pytest.raises(UsageError, match="not a list or a count"):
        sample([parse_parameter("k=1,2")], 5)
    with pytest.raises(UsageError, match="--param k is given twice"):
        grid([parse_parameter("k=1"), parse_parameter("k=2")])
