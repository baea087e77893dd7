"""The ensemble on an NVIDIA GPU: the C kernel text compiled by CuPy's NVRTC.

The same text as the C engine (:func:`.native_ensemble.kernel_text` with ``cuda``): the
entry ``springc_ensemble`` is a ``__global__`` kernel, one thread per run (each with its
own adaptive steps and status), the model's functions ``__device__`` functions inlined
into it. The inputs go to the device once per call, the outputs come back once. CuPy is
imported on the first call only; without CuPy, or without a CUDA device, the call raises
:class:`NoCudaDevice` ("no CUDA device found"). Imports nothing from springc.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .native_ensemble import (
    CompileFailed,
    Outputs,
    Runs,
    kernel_arguments,
    kernel_text,
    trajectory_points,
)

THREADS_PER_BLOCK = 128
MAX_WORK_BYTES = 64 * 1024
"""The largest per-thread work array (local memory) the GPU engine takes: about 250
states."""
INT_ARGUMENTS = (0, 21)
"""The positions (in :func:`.native_ensemble.kernel_arguments`) of the C ``int``s."""


class NoCudaDevice(RuntimeError):
    """CuPy is missing, or it finds no CUDA device."""


def cupy_module() -> Any:
    """CuPy, with at least one CUDA device; else :class:`NoCudaDevice`."""
    try:
        import cupy
    except ImportError:
        raise NoCudaDevice("no CUDA device found (CuPy is not installed; on a machine "
                           "with an NVIDIA GPU: pip install cupy-cuda12x)") from None
    try:
        count = int(cupy.cuda.runtime.getDeviceCount())
    except Exception as err:  # CUDARuntimeError, or a driver CuPy cannot load
        raise NoCudaDevice(f"no CUDA device found ({err})") from None
    if count < 1:
        raise NoCudaDevice("no CUDA device found")
    return cupy


def work_bytes(n_states: int, n_params: int, n_z: int, n_observed: int,
               crossings: int | None = None) -> int:
    """The bytes of one thread's work array (``SC_WORK`` of the kernel; ``crossings``:
    the zero-crossing functions of a hybrid model, None for a continuous one)."""
    hybrid = 0 if crossings is None else 3 * max(crossings, 1) + 100
    return 8 * (31 * max(n_states, 1) + max(n_params, 1) + max(n_z, 1) + max(n_observed, 1)
                + hybrid)


class GpuEnsemble:
    """The kernel of one model, compiled for the current CUDA device."""

    def __init__(self, model_c: str, n_states: int, positive: Sequence[bool] = ()) -> None:
        self.cupy = cupy_module()
        self.n = n_states
        try:
            module = self.cupy.RawModule(code=kernel_text(model_c, cuda=True, positive=positive),
                                         options=("--std=c++14",))
            self.kernel = module.get_function("springc_ensemble")
        except self.cupy.cuda.compiler.CompileException as err:
            raise CompileFailed(str(err)) from None

    def device_name(self) -> str:
        """The GPU's name, as CUDA gives it."""
        props = self.cupy.cuda.runtime.getDeviceProperties(self.cupy.cuda.Device().id)
        name = props["name"]
        return name.decode() if isinstance(name, bytes) else str(name)

    def run(self, runs: Runs, grid: np.ndarray, *, rtol: float, atol: np.ndarray,
            max_step: float, max_steps: int, columns: Sequence[int] = (),
            traj_columns: Sequence[int] = (), every: int = 1) -> Outputs:
        """Integrate every run on the GPU (one thread each); the outputs on the host."""
        cp = self.cupy
        columns_ = np.ascontiguousarray(columns, dtype=np.int64).reshape(-1)
        traj_ = np.ascontiguousarray(traj_columns, dtype=np.int64).reshape(-1)
        points = len(trajectory_points(grid.size, every)) if traj_.size else 0
        host = Outputs.empty(runs.count, self.n, columns_.size, points, traj_.size)
        args = kernel_arguments(runs, grid, rtol, atol, max_step, max_steps, columns_,
                                traj_, every, self.n, host)
        device: list[Any] = [np.int64(runs.count)]
        outputs = []
        for position, a in enumerate(args):
            if isinstance(a, np.ndarray):
                on_device = cp.asarray(np.ascontiguousarray(a))
                device.append(on_device)
                if any(a is o for o in host.__dict__.values()):
                    outputs.append((a, on_device))
            elif isinstance(a, float):
                device.append(np.float64(a))
            elif position in INT_ARGUMENTS:
                device.append(np.int32(a))
            else:
                device.append(np.int64(a))
        blocks = max(1, -(-runs.count // THREADS_PER_BLOCK))
        self.kernel((blocks,), (THREADS_PER_BLOCK,), tuple(device))
        cp.cuda.Device().synchronize()
        for target, on_device in outputs:
            target[...] = cp.asnumpy(on_device)
        return host
