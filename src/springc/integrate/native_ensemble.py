"""The batched C ensemble: the model's C text + runs -> an :class:`.batch.Ensemble`.

One kernel source (``ensemble_dop853.c``: DOP853 per run, springc's compiled DOP853
with plain-loop sums, every sum in the same order) is put together with the model's C
functions (the ``cmodel`` interface: ``springc_parameters``, ``springc_start``,
``springc_rhs``, ``springc_observed`` and the ``SPRINGC_N_*`` sizes) and compiled in two
ways from the same text: by the system C compiler into a shared library (OpenMP over
the runs, loaded here with ctypes; built by :func:`springc.pipeline.kernel_library`),
and in :mod:`.gpu_ensemble` by CuPy's NVRTC as a CUDA kernel (one thread per run).
:func:`kernel_text` is that text, :class:`NativeEnsemble` the C side's call. Imports
nothing from springc.
"""

from __future__ import annotations

import ctypes
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import dop853_tableau as tableau
from .status import Status

KERNEL = Path(__file__).with_name("ensemble_dop853.c")
CORE = Path(__file__).with_name("dop853_core.c")
"""DOP853's step arithmetic, shared with the single-run loop (:mod:`.native_loop`)."""
BAD_START = -1
"""The status of a run whose parameters or start values are not finite (or whose start
values' Newton iteration failed): it is not integrated."""
UNSETTLED = 8
"""The status of a hybrid run whose event iteration did not settle."""
CHATTERING = 9
"""The status of a hybrid run with more than 100 events within 1e-6 of its span (as
``springc.simulation.events.EventLoop.check_zeno``)."""
OPENMP = ("-fopenmp",)
"""The compiler argument of the parallel loop over the runs, used where the compiler
found builds and loads an OpenMP program (:func:`springc.pipeline.openmp_flags`; without
it the kernel's serial loop, one thread, the same results). The other flags are the C
model's (:func:`springc.pipeline.kernel_library`): -O2, no fused multiply-adds, so the
sums round as numba's do."""
LANES = 4
"""Runs in progress per thread on the CPU, their steps interleaved (see the kernel)."""
STATISTICS = 5  # final, min, max, mean, time of the max (see .batch.STATISTICS)


class CompileFailed(RuntimeError):
    """The CUDA compiler refused the kernel text (its messages are the error's text)."""


def c_array(name: str, values: np.ndarray, qualifier: str) -> str:
    flat = np.asarray(values, dtype=float).ravel()
    return (f"{qualifier} double {name}[{flat.size}] = {{"
            + ", ".join(repr(float(v)) for v in flat) + "};\n")


def c_weighted_sum(name: str, weights: np.ndarray, function: str) -> str:
    """``out[i] = sum_j weights[j] K[j, i]`` as C, summed from 0.0 in the order of j as
    numba's plain loop does, without the zero weights (the stages are finite, so each
    of those adds +0.0 or -0.0 to a sum that started at +0.0: the same value)."""
    terms = "".join(f"        acc += K[{j} * SC_NXS + i] * {float(w)!r};\n"
                    for j, w in enumerate(weights) if w != 0.0)
    return (f"{function} void {name}(const double *K, double *out) {{\n"
            "    for (int i = 0; i < SC_NX; i++) {\n        double acc = 0.0;\n"
            f"{terms}        out[i] = acc;\n    }}\n}}\n")


def c_switch(name: str, rows: list[str], function: str) -> str:
    cases = "".join(f"    case {k}: {row}(K, out); break;\n" for k, row in enumerate(rows)
                    if row)
    return (f"{function} void {name}(int row, const double *K, double *out) {{\n"
            f"    switch (row) {{\n{cases}    default: break;\n    }}\n}}\n")


def prelude(cuda: bool, positive: Sequence[bool] = ()) -> str:
    """The definitions before the kernel: the status codes and the DOP853 tableau, its
    weighted sums written out (``sc_a_row``, ``sc_b_sum``, ``sc_e5_sum``, ``sc_e3_sum``,
    ``sc_d_row``), ``DOP_C``, and ``SC_POSITIVE`` (1.0 where relation k of a hybrid
    model holds for a positive zero-crossing function: ``>`` and ``>=``)."""
    function = "static __device__" if cuda else "static inline"
    qualifier = "static __device__ const" if cuda else "static const"
    parts = ["#define SC_NX SPRINGC_N_STATES\n",
             "#define SC_NXS (SPRINGC_N_STATES > 0 ? SPRINGC_N_STATES : 1)\n"]
    parts += [f"#define SC_{s.name} {int(s)}\n" for s in Status]
    parts.append(f"#define SC_BAD_START {BAD_START}\n#define SC_UNSETTLED {UNSETTLED}\n"
                 f"#define SC_CHATTERING {CHATTERING}\n")
    parts.append(c_array("DOP_C", tableau.C, qualifier))
    parts.append(c_array("SC_POSITIVE", np.array([1.0 if k else 0.0 for k in positive] or
                                                  [0.0]), qualifier))
    rows = [""] + [f"sc_a_{s}" for s in range(1, tableau.STAGES_EXTENDED)]
    parts += [c_weighted_sum(rows[s], tableau.A[s, :s], function)
              for s in range(1, tableau.STAGES_EXTENDED)]
    parts.append(c_switch("sc_a_row", rows, function))
    parts += [c_weighted_sum("sc_b_sum", tableau.B, function),
              c_weighted_sum("sc_e5_sum", tableau.E5, function),
              c_weighted_sum("sc_e3_sum", tableau.E3, function)]
    d_rows = [f"sc_d_{r}" for r in range(len(tableau.D))]
    parts += [c_weighted_sum(d_rows[r], tableau.D[r], function) for r in range(len(tableau.D))]
    parts.append(c_switch("sc_d_row", d_rows, function))
    return "".join(parts)


CUDA_MACROS = "".join(f"#ifndef {name}\n#define {name} {value}\n#endif\n" for name, value in (
    ("HUGE_VAL", "__longlong_as_double(0x7ff0000000000000LL)"),
    ("INFINITY", "__int_as_float(0x7f800000)"),
    ("NAN", "__int_as_float(0x7fffffff)"),
    ("M_PI", "3.14159265358979323846"),
    ("M_E", "2.7182818284590452354")))
"""The macros of ``math.h`` the C model may use, which NVRTC does not define (as CUDA's
``math_constants.h`` writes them)."""


def kernel_text(model_c: str, cuda: bool = False, positive: Sequence[bool] = ()) -> str:
    """The whole translation unit: the model's C text, then the tableau and the kernel
    (``positive``: per zero-crossing function of a hybrid model, whether its relation is
    ``>`` or ``>=``: the held signs, see :func:`prelude`).

    For CUDA (``cuda``) the model's functions become ``__device__`` functions
    (``SPRINGC_FN``), its host-only name tables are left out (``SPRINGC_NO_TABLES``) and
    its ``#include`` lines are dropped (NVRTC has the math functions built in)."""
    if cuda:
        model = "".join(line for line in model_c.splitlines(keepends=True)
                        if not line.lstrip().startswith("#include"))
        head = ("#define SC_CUDA 1\n#define SPRINGC_NO_TABLES 1\n"
                "#define SPRINGC_FN static __device__ __forceinline__\n" + CUDA_MACROS)
    else:
        model = model_c
        head = ("#include <math.h>\n#define SPRINGC_NO_TABLES 1\n#undef SPRINGC_FN\n"
                f"#define SPRINGC_FN static inline\n#define SC_LANES {LANES}\n")
    return (head + model + "\n" + prelude(cuda, positive) + CORE.read_text(encoding="utf-8")
            + KERNEL.read_text(encoding="utf-8"))


@dataclass(frozen=True)
class Runs:
    """The runs of a call. Either ``P``, ``X0`` and ``Z`` (one row per run, computed
    beforehand), or ``values`` (one row per run) of the parameters at ``index``, put
    into ``base`` and completed in the kernel (``springc_parameters`` with ``given``
    marking the parameters set by the user, then ``springc_start``)."""

    values: np.ndarray
    index: np.ndarray
    base: np.ndarray
    given: np.ndarray
    P: np.ndarray | None = None
    X0: np.ndarray | None = None
    Z: np.ndarray | None = None

    @property
    def count(self) -> int:
        return len(self.values) if self.P is None else len(self.P)


@dataclass(frozen=True)
class Outputs:
    """What the kernel writes for a chunk (one row per run, see :class:`.batch.Ensemble`
    for the meaning): summary ``runs x columns x 5``, trajectories ``runs x points x
    variables`` (NaN where the run did not reach), finals, status, counts (accepted,
    rejected, evaluations, flag), failure time."""

    summary: np.ndarray
    trajectories: np.ndarray
    finals: np.ndarray
    status: np.ndarray
    counts: np.ndarray
    failure_time: np.ndarray

    @classmethod
    def empty(cls, runs: int, n: int, columns: int, points: int, traj: int) -> Outputs:
        return cls(np.empty((runs, columns, STATISTICS)), np.full((runs, points, traj), np.nan),
                   np.empty((runs, n)), np.empty(runs, dtype=np.int64),
                   np.empty((runs, 4), dtype=np.int64), np.empty(runs))


def trajectory_points(m: int, every: int) -> np.ndarray:
    """The output-grid indices a trajectory keeps: every ``every``-th, and the last."""
    kept = np.arange(0, m, every)
    return kept if kept[-1] == m - 1 else np.append(kept, m - 1)


def kernel_arguments(runs: Runs, grid: np.ndarray, rtol: float, atol: np.ndarray,
                     max_step: float, max_steps: int, columns: np.ndarray,
                     traj_columns: np.ndarray, every: int, n: int,
                     out: Outputs) -> list[Any]:
    """The entry's arguments after ``runs`` (arrays as they are; the caller converts)."""
    dummy = np.zeros(1)
    prepared = runs.P is not None
    n_states = n
    need_observed = int(bool((columns >= n_states).any() or (traj_columns >= n_states).any()))
    return [int(prepared), runs.values, runs.values.shape[1], runs.index, runs.base,
            runs.given, runs.P if prepared else dummy, runs.X0 if prepared else dummy,
            runs.Z if prepared else dummy, grid, grid.size, rtol, atol, max_step, max_steps,
            columns, columns.size, traj_columns, traj_columns.size, every,
            out.trajectories.shape[1], need_observed, out.summary, out.trajectories,
            out.finals, out.status, out.counts, out.failure_time]


class NativeEnsemble:
    """A compiled C ensemble library (the bytes of a shared library built from
    :func:`kernel_text`), loaded from a private temporary folder and called through
    ctypes (the call releases the GIL)."""

    def __init__(self, data: bytes, n_states: int, entry: str = "springc_ensemble") -> None:
        self.folder = tempfile.TemporaryDirectory(prefix="springc-ensemble-")  # 0700
        self.path = Path(self.folder.name) / "ensemble.so"
        self.path.write_bytes(data)
        self.n = n_states
        self.library = ctypes.CDLL(str(self.path))
        self.entry = getattr(self.library, entry)
        self.entry.restype = ctypes.c_int

    def threads(self) -> int:
        """The threads a call uses by default (OpenMP's; 1 without OpenMP)."""
        count = self.library.springc_ensemble_threads
        count.restype = ctypes.c_int
        return int(count())

    def run(self, runs: Runs, grid: np.ndarray, *, rtol: float, atol: np.ndarray,
            max_step: float, max_steps: int, columns: Sequence[int] = (),
            traj_columns: Sequence[int] = (), every: int = 1, threads: int = 0) -> Outputs:
        """Integrate every run; ``threads`` 0 is OpenMP's default."""
        columns_ = np.ascontiguousarray(columns, dtype=np.int64).reshape(-1)
        traj_ = np.ascontiguousarray(traj_columns, dtype=np.int64).reshape(-1)
        points = len(trajectory_points(grid.size, every)) if traj_.size else 0
        out = Outputs.empty(runs.count, self.n, columns_.size, points, traj_.size)
        args = kernel_arguments(runs, grid, rtol, atol, max_step, max_steps, columns_,
                                traj_, every, self.n, out)
        converted: list[Any] = [ctypes.c_longlong(runs.count)]
        keep = []
        for a in args:
            if isinstance(a, np.ndarray):
                a = np.ascontiguousarray(a)
                keep.append(a)
                converted.append(ctypes.c_void_p(a.ctypes.data))
            elif isinstance(a, float):
                converted.append(ctypes.c_double(a))
            else:
                converted.append(ctypes.c_longlong(a))
        converted = _typed(converted)
        code = self.entry(*converted, ctypes.c_int(threads))
        if code != 0:
            raise MemoryError("the ensemble kernel could not allocate its work arrays")
        return out


def _typed(args: list[Any]) -> list[Any]:
    """The ``int`` parameters of the entry (prepared, need_observed) as C ints."""
    for position in (1, 22):
        args[position] = ctypes.c_int(args[position].value)
    return args
