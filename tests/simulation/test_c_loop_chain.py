"""The 1,000-mass chain on the C loop: 2,000 states and no Jacobian in C (its 3,998
non-zeros are over ``codegen.JACOBIAN_LIMIT``), within the C loop's
``C_LOOP_DIFFERENCED_STATES``. Which loop it takes (exactly), and its states against
the chain's normal modes: dop853, and radau and bdf with the Jacobian differenced by
groups of columns in C (far fewer evaluations than the 2,001 per Jacobian of dense
differences)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.pipeline import c_kernels

ROOT = Path(__file__).resolve().parents[2]
SCENES = str(ROOT / "models" / "Scenes.mdl")
N = 1000
K, MASS, DS = 100.0, 1.0, 0.5  # Scenes.Chain's spring constant, mass, first displacement
C_REASON = ("{} ran in the compiled loop (C, no Python per step: a C compiler was "
            "found; SPRINGC_LOOP=numba runs numba's)")


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> Iterator[springc.CompiledModel]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        patch.setenv("SPRINGC_LOOP", "c")
        yield springc.compile_model(SCENES, "Scenes.Chain", parameters={"N": N})


def normal_modes(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The displacements from rest (mass i at i * L) and the velocities (masses x
    times) of N equal masses and springs, fixed at the left end, free at the right,
    the first mass displaced by DS at rest: the stiffness matrix's eigenvectors are
    sin(i theta_j), theta_j = (2j - 1) pi / (2N + 1), with sum_i sin(i theta_j)**2 =
    (2N + 1) / 4, and the frequencies 2 sqrt(K / MASS) sin(theta_j / 2)."""
    theta = (2 * np.arange(1, N + 1) - 1) * np.pi / (2 * N + 1)
    omega = 2 * np.sqrt(K / MASS) * np.sin(theta / 2)
    weights = DS * np.sin(theta) * 4 / (2 * N + 1)
    modes = np.sin(np.outer(np.arange(1, N + 1), theta)) * weights
    return modes @ np.cos(np.outer(omega, t)), -(modes * omega) @ np.sin(np.outer(omega, t))


def test_the_chain_is_compiled_for_the_c_loop_without_a_jacobian_in_c(
        chain: springc.CompiledModel) -> None:
    assert (len(chain.states), chain.module.BACKEND) == (2 * N, "python")
    assert len(chain.module.JAC_ROWS) == 3998  # over JACOBIAN_LIMIT (2,000)
    assert "#define SPRINGC_HAS_JACOBIAN 0\n" in c_kernels.c_source(chain)
    assert c_kernels.known_refusal(chain) is None


@pytest.mark.parametrize(("solver", "s_tol", "v_tol"), [
    ("dop853", 1e-7, 1e-6),  # measured 5.0e-9 and 1.2e-7 (default rtol 1e-6)
    ("radau", 3e-6, 5e-5),  # measured 3.2e-7 and 4.9e-6
    ("bdf", 2e-6, 3e-5),  # measured 1.6e-7 and 2.9e-6
])
def test_the_chain_runs_on_the_c_loop_and_meets_its_normal_modes(
        chain: springc.CompiledModel, monkeypatch: pytest.MonkeyPatch, solver: str,
        s_tol: float, v_tol: float) -> None:
    monkeypatch.setenv("SPRINGC_LOOP", "c")
    run = springc.simulate(chain, solver=solver, stop=2.0)
    assert (run.stats.engine, run.stats.solver) == ("compiled", solver)
    assert run.stats.engine_reason == C_REASON.format(solver)
    masses = np.arange(1, N + 1)
    s = np.array([run[f"m[{i}].s"] for i in masses]) - masses[:, None]
    v = np.array([run[f"m[{i}].v"] for i in masses])
    u_exact, v_exact = normal_modes(run.time)
    assert float(np.abs(s - u_exact).max()) <= s_tol
    assert float(np.abs(v - v_exact).max()) <= v_tol
    if solver != "dop853":  # grouped differences: a dense Jacobian alone takes 2,001
        assert run.stats.jacobian_evaluations >= 1
        assert run.stats.rhs_evaluations < 2001 * run.stats.jacobian_evaluations
