"""The engines of an ensemble: a chunk of runs (their varied values) -> :class:`Chunk`.

- ``c`` (the CPU default): the batched C kernel (:mod:`springc.integrate.native_ensemble`)
  around the model's C file, OpenMP over the cores; each run's parameters are completed
  and its start values computed in the kernel (``springc_parameters``,
  ``springc_start``), so no Python runs per run;
- ``numba``: the numba ensemble kernel (:func:`springc.integrate.ensemble`), the
  parameters and start values prepared in Python per run;
- the GPU (``device="gpu"``): the same C kernel text compiled for CUDA by CuPy's NVRTC,
  one thread per run (:mod:`springc.integrate.gpu_ensemble`).

Hybrid models (events: when-clauses, relations on states, ``sample``, time events) run
on the C kernel, on the CPU and the GPU: each run with its own events, the event
functions of the C model called in the kernel (see ``ensemble_dop853.c``); the numba
engine refuses them by name.

All three take the same steps (DOP853 with springc's plain-loop sums, see
``benchmarks/README.md`` for their throughput). A model with an initial problem gets
its start values from Python (:func:`springc.simulation.initial_state`) on every engine.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SimulationError, SpringcError, UsageError
from ..pipeline import CompiledModel
from ..simulation import initial_state

ENGINES = ("c", "numba")
DEVICES = ("cpu", "gpu")
FAILED_PREPARATION = -1  # the kernel's BAD_START: parameters or start values not finite


@dataclass(frozen=True)
class Plan:
    """What every run of an ensemble shares."""

    grid: np.ndarray
    rtol: float
    atol: float
    max_steps: int
    columns: tuple[int, ...]
    traj_columns: tuple[int, ...]
    every: int
    threads: int = 0  # 0: every core


@dataclass(frozen=True)
class Chunk:
    """The outcome of a chunk of runs, one row per run (see
    :class:`springc.integrate.Ensemble`); ``prepared``: the message of each run whose
    parameters or start values Python could not compute."""

    summary: np.ndarray
    trajectories: np.ndarray
    status: np.ndarray
    steps: np.ndarray
    rhs_evaluations: np.ndarray
    failure_time: np.ndarray
    prepared: Mapping[int, str]


Engine = Callable[[np.ndarray], Chunk]
"""A chunk's varied values (one row per run) -> its outcome."""


def prepare(model: CompiledModel, names: Sequence[str], values: np.ndarray,
            fixed: Mapping[str, float], t0: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, str]]:
    """Parameter vectors, start states and work arrays of a chunk's runs (Python per
    run: the generated module's ``parameters``, ``start`` and ``guesses``), and the
    message of each run whose values could not be computed."""
    module = model.module
    n_p, n = len(model.parameter_names), len(model.states)
    P = np.zeros((len(values), n_p))
    X0 = np.zeros((len(values), n))
    Z = np.zeros((len(values), np.asarray(module.guesses(module.parameters(dict(fixed)))).size))
    failed: dict[int, str] = {}
    for r, row in enumerate(values):
        settings = dict(fixed)
        settings.update(zip(names, (float(v) for v in row)))
        try:
            P[r] = module.parameters(settings)
            if not np.isfinite(P[r]).all():
                raise SimulationError("a parameter value is not finite")
            X0[r] = initial_state(model, P[r], t0)
            Z[r] = module.guesses(P[r])
        except (ArithmeticError, ValueError, SpringcError) as err:
            failed[r] = str(err)
            P[r], X0[r] = np.nan, np.nan
    return P, X0, Z, failed


def numba_engine(model: CompiledModel, names: Sequence[str], fixed: Mapping[str, float],
                 plan: Plan) -> Engine:
    """The numba ensemble kernel (the model's numba functions)."""
    from ..integrate import ensemble

    if getattr(model.module, "EVENTS", False):
        raise SimulationError(f"{model.name} has events ({event_constructs(model)}), which "
                              "the numba ensemble engine does not run",
                              hint="use the C engine (--engine c, the default where a C "
                              "compiler is found)")
    if getattr(model.module, "BACKEND", "") != "numba":
        raise SimulationError(f"the numba ensemble engine needs the numba backend, not "
                              f"{model.module.BACKEND}", hint="compile with --backend numba")

    def run(values: np.ndarray) -> Chunk:
        import numba

        P, X0, Z, prepared = prepare(model, names, values, fixed, float(plan.grid[0]))
        threads = numba.get_num_threads()
        try:
            if plan.threads:
                numba.set_num_threads(min(plan.threads, numba.config.NUMBA_NUM_THREADS))  # type: ignore[attr-defined]
            result = ensemble(model.module.rhs, plan.grid, X0, P, Z, rtol=plan.rtol,
                              atol=plan.atol, observed=model.module.observed,
                              columns=plan.columns, max_steps=plan.max_steps,
                              traj_columns=plan.traj_columns, every=plan.every)
        finally:
            numba.set_num_threads(threads)
        return Chunk(result.summary, result.trajectories, result.status, result.steps,
                     result.rhs_evaluations, result.failure_time, prepared)

    return run


def c_runs(model: CompiledModel, names: Sequence[str], fixed: Mapping[str, float],
           plan: Plan) -> Callable[[np.ndarray], tuple[Any, dict[int, str]]]:
    """A chunk's values -> the C kernel's :class:`~springc.integrate.native_ensemble.Runs`
    (completed in the kernel, or prepared in Python for a model with an initial
    problem) and the messages of the runs Python could not prepare."""
    from ..integrate import Runs

    index = {n: i for i, n in enumerate(model.parameter_names)}
    varied = np.array([index[n] for n in names], dtype=np.int64)
    base = np.asarray(model.module.parameters(dict(fixed)), dtype=float)
    given = np.zeros(max(len(base), 1), dtype=np.int32)
    given[[index[n] for n in (*fixed, *names) if n in index]] = 1

    def runs(values: np.ndarray) -> tuple[Any, dict[int, str]]:
        values = np.ascontiguousarray(values, dtype=float)
        if not getattr(model.module, "INITIAL_CONDITIONS", 0):
            return Runs(values, varied, base, given), {}
        P, X0, Z, prepared = prepare(model, names, values, fixed, float(plan.grid[0]))
        return Runs(values, varied, base, given, P, X0, Z), prepared

    return runs


def _chunk(out: Any, prepared: dict[int, str]) -> Chunk:
    return Chunk(out.summary, out.trajectories, out.status,
                 out.counts[:, 0] + out.counts[:, 1], out.counts[:, 2], out.failure_time,
                 prepared)


def relation_signs(model: CompiledModel) -> tuple[bool, ...]:
    """Per zero-crossing function of a hybrid model: whether its relation holds where
    the function is positive (``>``, ``>=``); the kernel's held signs."""
    return tuple(op in (">", ">=") for op in getattr(model.module, "RELATION_OPS", ()))


def c_engine(model: CompiledModel, names: Sequence[str], fixed: Mapping[str, float],
             plan: Plan) -> Engine:
    """The batched C kernel on every core (the model's C file)."""
    from ..integrate import OPENMP, NativeEnsemble, kernel_text
    from ..pipeline import c_source, kernel_library, openmp_flags

    text = kernel_text(c_source(model), positive=relation_signs(model))
    # OpenMP where the compiler's probe builds and loads, else the serial loop
    data = kernel_library(model, text, openmp_flags(OPENMP), tag="ensemble")
    kernel = NativeEnsemble(data, len(model.states))
    make = c_runs(model, names, fixed, plan)
    atol = np.full(max(len(model.states), 1), plan.atol)

    def run(values: np.ndarray) -> Chunk:
        runs, prepared = make(values)
        out = kernel.run(runs, plan.grid, rtol=plan.rtol, atol=atol, max_step=np.inf,
                         max_steps=plan.max_steps, columns=plan.columns,
                         traj_columns=plan.traj_columns, every=plan.every,
                         threads=plan.threads)
        return _chunk(out, prepared)

    return run


def gpu_engine(model: CompiledModel, names: Sequence[str], fixed: Mapping[str, float],
               plan: Plan) -> Engine:
    """The C kernel on the GPU through CuPy (one thread per run)."""
    from ..integrate import GpuEnsemble, NoCudaDevice
    from ..pipeline import c_source

    try:
        kernel = GpuEnsemble(c_source(model), len(model.states), relation_signs(model))
    except NoCudaDevice as err:
        raise UsageError(f"--device gpu: {err}", option="--device",
                         hint="run on the CPU (--device cpu, the default)") from None
    make = c_runs(model, names, fixed, plan)
    atol = np.full(max(len(model.states), 1), plan.atol)

    def run(values: np.ndarray) -> Chunk:
        runs, prepared = make(values)
        out = kernel.run(runs, plan.grid, rtol=plan.rtol, atol=atol, max_step=np.inf,
                         max_steps=plan.max_steps, columns=plan.columns,
                         traj_columns=plan.traj_columns, every=plan.every)
        return _chunk(out, prepared)

    return run


def event_constructs(model: CompiledModel, shown: int = 3) -> str:
    """The event constructs of a hybrid model, in words: its zero-crossing relations as
    the C model writes them (``the relation h < 0``), ``sample(...)``, time events."""
    import re

    from ..pipeline import c_source

    parts = []
    block = re.search(r"springc_crossing_texts\[[^]]*\] = \{(.*?)\n\};",
                      c_source(model), re.S)
    texts = [bytes(re.sub(r"\\([0-7]{3})", lambda m: chr(int(m.group(1), 8)), t),
                   "latin-1").decode("utf-8", "replace")
             for t in re.findall(r'"((?:[^"\\]|\\.)*)"', block.group(1))] if block else []
    if texts:
        listed = ", ".join(texts[:shown]) + (f" and {len(texts) - shown} more"
                                             if len(texts) > shown else "")
        parts.append(f"the relation{'s' if len(texts) > 1 else ''} {listed}")
    if getattr(model.module, "SAMPLES", ()):
        parts.append("sample(...)")
    if getattr(model.module, "TIME_EVENTS", ()):
        parts.append("time events")
    return "; ".join(parts) or "when-clauses"


def resolve_engine(engine: str | None, device: str) -> str:
    """The engine's name without opening it (checked): ``gpu`` on the GPU, else as
    asked, else ``c`` where a C compiler is found, else ``numba``."""
    if device not in DEVICES:
        raise UsageError(f"--device {device}: not one of {', '.join(DEVICES)}",
                         option="--device")
    if engine is not None and engine not in ENGINES:
        raise UsageError(f"--engine {engine}: not one of {', '.join(ENGINES)}",
                         option="--engine")
    if device == "gpu":
        if engine == "numba":
            raise UsageError("--engine numba runs on the CPU; the GPU runs the C kernel",
                             option="--engine", hint="leave out --engine with --device gpu")
        return "gpu"
    if engine is not None:
        return engine
    from ..pipeline import CCompilerMissing, find_compiler

    try:
        find_compiler()
    except CCompilerMissing:
        return "numba"
    return "c"


def open_engine(model: CompiledModel, engine: str | None, device: str,
                names: Sequence[str], fixed: Mapping[str, float], plan: Plan
                ) -> tuple[str, Engine]:
    """The engine's name and its chunk function. ``engine`` None: ``c`` on the CPU,
    or ``numba`` where no C compiler is found (a choice fixed by measurement, see the
    module text, never by the clock)."""
    name = resolve_engine(engine, device)
    if name == "gpu":
        return "gpu", gpu_engine(model, names, fixed, plan)
    if name == "numba":
        return "numba", numba_engine(model, names, fixed, plan)
    from ..pipeline import CCompilerMissing

    try:
        return "c", c_engine(model, names, fixed, plan)
    except CCompilerMissing:
        if engine == "c":
            raise
        return "numba", numba_engine(model, names, fixed, plan)
