"""The batched C ensemble kernel (``ensemble_dop853.c``) on the seed written by hand in C
(``seed_model.c``, the cmodel interface), against the numba ensemble and the compiled
single run on the same seed written in numba: the same steps and values (the kernel's
sums run in numba's order), the same bytes with 1 or 2 threads, failures per run, the
parameters completed in the kernel, and the CUDA text of the same kernel run on the CPU
(compiled as C++ with a stand-in for the launch)."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from springc.integrate import Status, dop853, ensemble
from springc.integrate.native_ensemble import (
    BAD_START,
    OPENMP,
    NativeEnsemble,
    Outputs,
    Runs,
    kernel_text,
    trajectory_points,
)
from springc.pipeline import openmp_flags
from springc.pipeline.c_build import build_library

HERE = Path(__file__).resolve().parent
SEED_C = (HERE / "seed_model.c").read_text(encoding="utf-8")
BASE = np.array([1.0, 1.0, -1.0, 0.0, 0.0, 1e4, 1.0, 0.0, 0.0, 0.0, -9.81])
K, M = 5, 0  # the indices of spring.k and mass.m in the parameter vector
RTOL, ATOL = 1e-6, np.full(4, 1e-9)
GRID = np.linspace(0.0, 2.0, 21)


@njit(cache=True, error_model="numpy")
def seed_rhs(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    d = np.empty(4)
    dir1, dir2 = x[0] - p[7], x[1] - p[8]
    length = math.sqrt(dir1 * dir1 + dir2 * dir2)
    d[0], d[1] = x[2], x[3]
    d[2] = -p[5] * dir1 * (length - p[6]) / length / p[0] + p[9]
    d[3] = -p[5] * dir2 * (length - p[6]) / length / p[0] + p[10]
    return d


@njit(cache=True, error_model="numpy")
def seed_observed(t: float, x: np.ndarray, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    out = np.empty(3)
    out[0], out[1] = x[0] - p[7], x[1] - p[8]
    out[2] = math.sqrt(out[0] * out[0] + out[1] * out[1])
    return out


@pytest.fixture(scope="module")
def kernel(tmp_path_factory: pytest.TempPathFactory) -> NativeEnsemble:
    flags = openmp_flags(OPENMP)  # none with zig cc (no OpenMP runtime)
    data = build_library(kernel_text(SEED_C), tmp_path_factory.mktemp("c"), flags)
    return NativeEnsemble(data, 4)


def _runs(column: int, values: np.ndarray) -> Runs:
    given = np.zeros(BASE.size, dtype=np.int32)
    given[column] = 1
    return Runs(values.reshape(-1, 1).astype(float), np.array([column], dtype=np.int64),
                BASE, given)


def _prepared(column: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    P = np.tile(BASE, (len(values), 1))
    P[:, column] = values
    return P, P[:, 1:5].copy(), np.zeros((len(values), 1))


def _run(kernel: NativeEnsemble, runs: Runs, grid: np.ndarray = GRID, **options: object
         ) -> Outputs:
    settings: dict[str, object] = {"rtol": RTOL, "atol": ATOL, "max_step": np.inf,
                                   "max_steps": 0, **options}
    return kernel.run(runs, grid, **settings)  # type: ignore[arg-type]


def test_the_c_kernel_takes_the_numba_ensembles_steps(kernel: NativeEnsemble) -> None:
    ks = np.geomspace(1e3, 1e5, 40)
    columns = [0, 3, 6]  # mass.pos[1], mass.v[2], spring.x (observed)
    out = _run(kernel, _runs(K, ks), columns=columns, traj_columns=[1, 6], every=3)
    P, X0, Z = _prepared(K, ks)
    reference = ensemble(seed_rhs, GRID, X0, P, Z, rtol=RTOL, atol=ATOL,
                         observed=seed_observed, columns=columns, traj_columns=[1, 6],
                         every=3)
    assert (out.status == 0).all()
    # the same steps: the kernel's sums run in numba's order (no fused multiply-adds)
    assert (out.counts[:, 0] + out.counts[:, 1]).tolist() == reference.steps.tolist()
    assert out.counts[:, 2].tolist() == reference.rhs_evaluations.tolist()
    np.testing.assert_allclose(out.finals, reference.finals, rtol=1e-12, atol=0)
    np.testing.assert_allclose(out.summary, reference.summary, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out.trajectories, reference.trajectories, rtol=1e-12,
                               atol=1e-15)


def test_trajectories_are_the_single_runs_states_on_the_kept_times(
        kernel: NativeEnsemble) -> None:
    ks = np.array([1e3, 3e4])
    out = _run(kernel, _runs(K, ks), traj_columns=[1, 6], every=3)
    kept = trajectory_points(GRID.size, 3)
    assert kept.tolist() == [0, 3, 6, 9, 12, 15, 18, 20]
    P, X0, Z = _prepared(K, ks)
    for r in range(2):
        single = dop853(seed_rhs, GRID, X0[r], P[r], Z[r].copy(), rtol=RTOL, atol=ATOL,
                        observed=seed_observed, scipy_arithmetic=False)
        expected = np.column_stack([single.states[kept, 1], single.observed[kept, 2]])
        np.testing.assert_allclose(out.trajectories[r], expected, rtol=1e-12, atol=1e-15)


def test_the_bytes_do_not_depend_on_the_number_of_threads(kernel: NativeEnsemble) -> None:
    runs = _runs(K, np.geomspace(1e3, 1e5, 30))
    one = _run(kernel, runs, columns=[0, 6], traj_columns=[2], threads=1)
    two = _run(kernel, runs, columns=[0, 6], traj_columns=[2], threads=2)
    for name in ("summary", "trajectories", "finals", "status", "counts", "failure_time"):
        assert getattr(one, name).tobytes() == getattr(two, name).tobytes(), name


def test_a_failed_run_keeps_its_status_and_the_others_succeed(kernel: NativeEnsemble) -> None:
    out = _run(kernel, _runs(M, np.array([0.5, 0.0, math.nan, 2.0])), columns=[0])
    assert out.status.tolist() == [Status.SUCCESS, Status.NON_FINITE_DERIVATIVE, BAD_START,
                                   Status.SUCCESS]
    assert out.failure_time[1] == 0.0 and out.counts[1, 2] == 1
    assert np.isnan(out.summary[1:3]).all() and np.isfinite(out.summary[[0, 3]]).all()
    limited = _run(kernel, _runs(K, np.array([1e4])), max_steps=5)
    P, X0, Z = _prepared(K, np.array([1e4]))
    single = dop853(seed_rhs, GRID, X0[0], P[0], Z[0].copy(), rtol=RTOL, atol=ATOL,
                    max_steps=5, scipy_arithmetic=False)
    assert limited.status[0] == single.status == Status.MAX_STEPS
    assert limited.failure_time[0] == pytest.approx(single.failure_time, rel=1e-12)


def test_prepared_rows_and_rows_completed_in_the_kernel_agree(kernel: NativeEnsemble) -> None:
    ks = np.array([2e3, 5e4])
    P, X0, Z = _prepared(K, ks)
    prepared = Runs(np.zeros((2, 0)), np.zeros(0, dtype=np.int64), BASE,
                    np.zeros(BASE.size, dtype=np.int32), P, X0, Z)
    a, b = _run(kernel, prepared, columns=[2]), _run(kernel, _runs(K, ks), columns=[2])
    assert a.finals.tobytes() == b.finals.tobytes()
    assert a.summary.tobytes() == b.summary.tobytes()


CUDA_STAND_IN = """#include <math.h>
#define __global__
#define __device__
#define __forceinline__ inline
struct sc_dim3 { unsigned x; };
static sc_dim3 threadIdx, blockIdx, blockDim, gridDim;
#define SC_EMULATE_CUDA "cuda_emulation.h"
"""


def test_the_cuda_text_of_the_kernel_gives_the_c_kernels_results(
        kernel: NativeEnsemble, tmp_path: Path) -> None:
    system = shutil.which("c++") or shutil.which("g++")  # the CUDA text is C++
    cxx = [system] if system else [sys.executable, "-m", "ziglang", "c++"]
    source = tmp_path / "cuda.cpp"
    source.write_text(CUDA_STAND_IN + kernel_text(SEED_C, cuda=True), encoding="utf-8")
    library = tmp_path / "cuda.so"
    subprocess.run([*cxx, "-O1", "-ffp-contract=off", "-fPIC", "-shared", f"-I{HERE}",
                    str(source), "-o", str(library)], check=True)
    emulated = NativeEnsemble(library.read_bytes(), 4, entry="sc_emulated_launch")
    runs = _runs(K, np.geomspace(1e3, 1e5, 300))  # three blocks of 128 threads
    gpu = _run(emulated, runs, columns=[0, 6], traj_columns=[3], every=4, threads=128)
    cpu = _run(kernel, runs, columns=[0, 6], traj_columns=[3], every=4)
    assert gpu.counts.tolist() == cpu.counts.tolist()
    np.testing.assert_allclose(gpu.finals, cpu.finals, rtol=1e-12, atol=0)
    np.testing.assert_allclose(gpu.summary, cpu.summary, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(gpu.trajectories, cpu.trajectories, rtol=1e-12, atol=1e-15)
