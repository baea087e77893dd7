"""Large scenes: 10^4 masses (20,000 states) over a short span, with the sparse
implicit solver and with auto, against the sparse matrix exponential."""

from __future__ import annotations

import numpy as np
import pytest

import springc

from .cases import big_chain

N = 10_000


@pytest.fixture(scope="module")
def chain(models_file: str, tmp_path_factory: pytest.TempPathFactory) -> springc.CompiledModel:
    mp = pytest.MonkeyPatch()
    mp.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    try:
        return springc.compile_model(models_file, "BigChain", outputs=["x[1]", "x[2]"])
    finally:
        mp.undo()


@pytest.mark.parametrize(("solver", "bound"), [("bdf", 1e-4), ("auto", 1e-6)])
def test_ten_thousand_masses(chain: springc.CompiledModel, solver: str, bound: float) -> None:
    assert len(chain.states) == 2 * N
    result = springc.simulate(chain, solver=solver, stop=1.0, interval=0.1)
    reference = big_chain(result.time, N)
    assert np.max(np.abs(result.values - reference)) < bound
    assert result.stats.solver == ("bdf" if solver == "bdf" else "dop853")
