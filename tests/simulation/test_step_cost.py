"""auto's cost model (springc.simulation.step_cost): the prices of a model from its
Jacobian's sparsity, exactly, on both loops, and without numba."""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import numpy as np

from springc.simulation.step_cost import COMPILED, SCIPY, Work, step_costs

# the uneven stiff pair: x1, x2, v1, v2; der(x) = v, der(v) from x1 and x2
PAIR = SimpleNamespace(JAC_INDPTR=np.array([0, 2, 4, 5, 6]),
                       JAC_INDICES=np.array([2, 3, 2, 3, 0, 1]))


def test_prices_of_a_small_dense_model() -> None:
    """4 states, 6 non-zeros, a dense band (kl = ku = 3) on the compiled loop."""
    costs = step_costs(PAIR, compiled=True)
    assert (costs.rhs, costs.jacobian) == (1000 + 20 * (4 + 6), 1000 + 20 * 6)
    assert costs.factorization == 1000 + 10 * 4 * 3 * (3 + 3 + 1)  # newton_flops
    assert costs.solve == 1000 + 10 * 4 * (2 * 3 + 3 + 1)  # newton_solve_flops
    assert costs.overheads == COMPILED
    # a dop853 step of 12 evaluations; a radau step of 7 (two Newton iterations, one
    # factorization), in RHS evaluations
    assert costs.evaluations(False, Work(1, 1, 12)) == (12 * 1200 + 300 * 4) / 1200
    assert costs.evaluations(True, Work(1, 1, 7)) == (
        7 * 1200 + 1840 + 2 * 1400 + 5 * 1000 + 100 * 4) / 1200


def test_scipys_loop_prices_each_call_as_python() -> None:
    costs = step_costs(PAIR, compiled=False)
    assert costs.overheads == SCIPY and costs.rhs == 50_000 + 20 * (4 + 6)


def test_the_prices_need_no_numba() -> None:
    """scipy's loop runs auto's race where numba is not installed: the band of the
    Newton matrices is found without it."""
    code = ("import sys; sys.modules['numba'] = None\n"
            "import numpy as np\n"
            "from types import SimpleNamespace\n"
            "from springc.simulation.step_cost import step_costs\n"
            "m = SimpleNamespace(JAC_INDPTR=np.array([0, 2, 4, 5, 6]), "
            "JAC_INDICES=np.array([2, 3, 2, 3, 0, 1]))\n"
            "print(step_costs(m, compiled=False).factorization)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False)
    assert (done.returncode, done.stdout) == (0, "50840.0\n"), done.stderr
