"""Processes that need the same kernel at once compile it once (springc.integrate's
compile lock beside numba's cache); counted from numba's cache statistics, not timed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from springc.integrate import kernels
from springc.integrate.compile_lock import cache_folder, compile_once, index_file
from springc.integrate.signatures import FIXED_STEP_SIGNATURE

SRC = Path(__file__).resolve().parents[2] / "src"
KERNEL = '''
import numpy as np
from numba import njit


@njit(cache=True)
def kernel(x):
    total = 0.0
    for value in x:
        total += value * value
    return total
'''
WORKER = '''
import json, sys, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
go = Path(sys.argv[1]) / "go"
while not go.exists():
    time.sleep(0.01)
from numba import float64, types
from springc.integrate.compile_lock import compile_once
import kernel_module
compile_once(kernel_module.kernel, float64(types.float64[::1]))
stats = kernel_module.kernel.stats
print(json.dumps([sum(stats.cache_misses.values()), sum(stats.cache_hits.values()),
                  kernel_module.kernel(__import__("numpy").arange(3.0))]))
'''


def test_processes_that_need_a_kernel_at_once_compile_it_once(tmp_path: Path) -> None:
    (tmp_path / "kernel_module.py").write_text(KERNEL)
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    env.pop("NUMBA_CACHE_DIR", None)  # numba's cache beside the module, in tmp_path
    workers = [subprocess.Popen([sys.executable, "-c", WORKER, str(tmp_path)], env=env,
                                stdout=subprocess.PIPE, text=True) for _ in range(3)]
    (tmp_path / "go").touch()
    results = [json.loads(worker.communicate(timeout=600)[0]) for worker in workers]
    assert all(worker.returncode == 0 for worker in workers)
    assert sorted(misses for misses, _, _ in results) == [0, 0, 1]  # one compile
    assert sorted(hits for _, hits, _ in results) == [0, 1, 1]  # two loads of it
    assert [value for _, _, value in results] == [5.0, 5.0, 5.0]
    assert (tmp_path / "__pycache__" / "kernel.lock").exists()


def test_a_loop_is_named_after_its_method_and_cached_beside_its_template() -> None:
    loop = kernels.dispatcher("rk45")
    assert loop is kernels.dispatcher("rk45")  # made once per process
    assert loop.py_func.__qualname__.startswith("rk45_loop_")
    assert kernels.dispatcher("rk45", blas=True).py_func.__qualname__.startswith(
        "rk45_loop_blas_")
    assert kernels.dispatcher("radau", blas=True) is kernels.dispatcher("radau")
    assert kernels.dispatcher("verlet") is kernels.dispatcher("rk4")  # one fixed-step loop
    folder, index = cache_folder(loop), index_file(loop)
    assert folder is not None and index is not None and index.parent == folder
    assert index.name.startswith("loop." + loop.py_func.__qualname__)


def test_compile_once_of_a_loaded_kernel_compiles_nothing_more() -> None:
    loop = kernels.kernel("verlet")
    assert len(loop.overloads) == 1
    compile_once(loop, FIXED_STEP_SIGNATURE)  # again: nothing new
    assert len(loop.overloads) == 1
