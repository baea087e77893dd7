"""The C ensemble built by zig cc (the ziglang package: a C compiler from PyPI, with no
OpenMP runtime): OpenMP is a tested capability of the compiler found, zig's kernel runs
its serial loop, and its table equals the system compiler's (OpenMP, any thread count)
within 1e-12 relative on a few hundred runs of the seed."""

from __future__ import annotations

import shlex
import shutil
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import springc
from springc.integrate import OPENMP
from springc.pipeline import openmp_flags
from springc.studies import EnsembleOptions, parse_parameter, run_ensemble

SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")
ZIG = [sys.executable, "-m", "ziglang", "cc"]
SYSTEM = next((c for c in map(shutil.which, ("cc", "gcc", "clang")) if c), None)


def _table(tmp_path: Path, compiler: list[str], threads: int, name: str
           ) -> dict[str, list[float]]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("CC", shlex.join(compiler))
        model = springc.compile_model(SEED)
        options = EnsembleOptions((parse_parameter("spring.k=1e3:1e5:log:300"),), stop=2.0,
                                  rtol=1e-6, atol=1e-9, engine="c", threads=threads)
        summary = run_ensemble(model, options, str(tmp_path / f"{name}.parquet"))
    assert (summary.engine, summary.failed) == ("c", 0)
    return pq.read_table(tmp_path / f"{name}.parquet").to_pydict()  # type: ignore[no-any-return]


def test_zig_cc_has_no_openmp_runtime_so_the_kernel_is_built_without(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CC", shlex.join(ZIG))
    assert openmp_flags(OPENMP) == ()


def test_the_zig_ensemble_equals_the_system_compilers_at_any_thread_count(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path / "cache"))
    # where the machine has no system compiler, zig is compared with itself
    reference = [SYSTEM] if SYSTEM is not None else ZIG
    zig = _table(tmp_path, ZIG, 0, "zig")
    tables = [_table(tmp_path, reference, threads, f"ref{threads}") for threads in (1, 3)]
    assert tables[0] == tables[1]  # one library: the same bits whatever the threads
    assert list(zig) == list(tables[0]) and len(zig["steps"]) == 300
    assert zig["steps"] == tables[0]["steps"]
    floats = [c for c, values in zig.items() if isinstance(values[0], float)]
    assert len(floats) >= 5 * 3  # five statistics of each output
    for column, values in zig.items():
        if column in floats:
            np.testing.assert_allclose(values, tables[0][column], rtol=1e-12, atol=1e-300,
                                       err_msg=column)
        else:  # the run's values, status, steps
            assert values == tables[0][column], column
