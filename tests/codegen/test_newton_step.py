"""The Newton correction of torn blocks (``codegen.newton_step``): numpy's solution
where the Jacobian is regular, the basic solution with the free unknowns' new values
0 where it is singular and consistent, NaN where it is inconsistent."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from springc.codegen.newton_step import NEWTON_SOLVE, newton_solve


def _helper() -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    namespace: dict[str, object] = {"np": np}
    exec(NEWTON_SOLVE, namespace)  # the text generated modules define
    return namespace["_newton_solve"]  # type: ignore[return-value]


def test_regular_jacobian_is_numpys_solution() -> None:
    a, r = np.array([[2.0, 1.0], [1.0, 3.0]]), np.array([1.0, 2.0])
    assert np.array_equal(_helper()(a, r, np.zeros(2)), np.linalg.solve(a, r))


def test_singular_consistent_jacobian_sets_the_free_unknown_to_zero() -> None:
    # two stuck brakes: only the sum of their path parameters is determined
    a, r, t = np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([0.0, 3.0]), np.array([5.0, 7.0])
    d = _helper()(a, r, t)
    assert np.allclose(a @ d, r, rtol=0, atol=1e-15)
    assert np.allclose(t - d, [9.0, 0.0], rtol=0, atol=1e-15)


def test_singular_inconsistent_jacobian_gives_nan() -> None:
    a, r = np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([1.0, 3.0])
    assert np.isnan(_helper()(a, r, np.zeros(2))).all()


def test_the_generated_line_guards_non_finite_entries() -> None:
    assert newton_solve("_D1", "_J1", "_R1", "_T1", 2) == (
        "_D1 = _newton_solve(_J1, _R1, _T1) if np.isfinite(_J1).all() and "
        "np.isfinite(_R1).all() else np.full(2, np.nan)")
