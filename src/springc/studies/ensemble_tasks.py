"""Chunks of an ensemble as tasks: a chunk of runs (rows of the parameter table) ->
:class:`.ensemble_engines.Chunk`, in this process or as the unit of a Dask task.

A :class:`ChunkTask` holds what every chunk of an ensemble shares (the compiled model,
which pickles and travels with the task, the engine, the fixed values and the
:class:`.ensemble_engines.Plan`); :func:`run_chunk` runs one chunk of it wherever it is
called, opening the engine once per process (a worker keeps the engines of the last
few ensembles it ran, :data:`OPENED`). The C kernel of a model is built once per
machine into the model's cache entry and read from there by every later process.

:func:`local_chunks` runs the chunks one after the other in this process;
:func:`dask_chunks` submits them to a Dask cluster (:func:`.engines.connect`, as
``sweep --scheduler`` does) and yields them **in run order**, keeping at most
:data:`WINDOW` tasks per worker thread in flight, so that the writer's memory stays
bounded by a few chunks whatever the number of runs. Each run reads only its own row
and the kernel reduces nothing across runs: a run's values are the same bytes whatever
the chunk size, the worker count or the order in which tasks finish.
"""

from __future__ import annotations

import collections
import pickle
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..pipeline import CompiledModel
from .ensemble_engines import Chunk, Engine, Plan, open_engine

NON_FINITE_OUTPUT = 3  # Status.NON_FINITE_STATE: a chosen variable NaN or inf on the grid
FAILED_PREPARATION = -1  # the kernel's BAD_START
WINDOW = 2
"""Tasks in flight per Dask worker thread: one running, one waiting its turn."""
OPENED: collections.OrderedDict[bytes, Engine] = collections.OrderedDict()
"""The engines this process opened, by task (the last :data:`KEPT` of them)."""
KEPT = 4


@dataclass(frozen=True)
class ChunkTask:
    """What every chunk of an ensemble shares: ``engine`` (``c``, ``numba`` or ``gpu``)
    is already resolved, so that every worker runs the same one."""

    model: CompiledModel
    engine: str
    names: tuple[str, ...]
    fixed: tuple[tuple[str, float], ...]
    plan: Plan

    def key(self) -> bytes:
        """The task without its model's data: the model's cache entry and the rest."""
        return pickle.dumps((str(self.model.path), self.model.name, self.engine,
                             self.names, self.fixed, self.plan))


def checked(result: Chunk) -> Chunk:
    """``result`` with the runs whose chosen values are not finite failed, and the runs
    Python could not prepare marked so."""
    from dataclasses import replace

    status = result.status.copy()
    finite = np.isfinite(result.summary).all(axis=(1, 2))
    status[(status == 0) & ~finite] = NON_FINITE_OUTPUT
    status[list(result.prepared)] = FAILED_PREPARATION
    return replace(result, status=status)


def opened(task: ChunkTask) -> Engine:
    """The engine of ``task`` in this process, opened on first use."""
    key = task.key()
    engine = OPENED.get(key)
    if engine is None:
        device = "gpu" if task.engine == "gpu" else "cpu"
        _, engine = open_engine(task.model, None if device == "gpu" else task.engine,
                                device, task.names, dict(task.fixed), task.plan)
        OPENED[key] = engine
        while len(OPENED) > KEPT:
            OPENED.popitem(last=False)
    OPENED.move_to_end(key)
    return engine


def run_chunk(task: ChunkTask, values: np.ndarray) -> Chunk:
    """One chunk of runs (one row of ``values`` per run) on the task's engine: the unit
    of a Dask task."""
    return checked(opened(task)(values))


Chunks = Iterator[tuple[int, np.ndarray, Chunk]]
"""(first run, the chunk's values, its outcome) in run order."""


def local_chunks(run: Callable[[np.ndarray], Chunk], values: np.ndarray, chunk: int
                 ) -> Chunks:
    """The chunks of ``values`` run in this process by ``run``, one after the other."""
    for first in range(0, len(values), chunk):
        part = values[first:first + chunk]
        yield first, part, checked(run(part))


def dask_chunks(client: Any, task: ChunkTask, values: np.ndarray, chunk: int,
                threads: int) -> Chunks:
    """The chunks of ``values`` as Dask tasks on ``client``'s cluster (``threads``:
    its worker threads), yielded in run order; leaving early cancels the rest."""
    starts = iter(range(0, len(values), chunk))
    flight: collections.deque[tuple[int, Any]] = collections.deque()

    def submit() -> None:
        first = next(starts, None)
        if first is not None:
            part = values[first:first + chunk]
            flight.append((first, client.submit(run_chunk, task, part, pure=False)))

    try:
        for _ in range(WINDOW * max(threads, 1)):
            submit()
        while flight:
            first, future = flight.popleft()
            result = future.result()
            submit()
            yield first, values[first:first + chunk], result
    finally:
        client.cancel([future for _, future in flight])


def dask_chunk_size(runs: int, threads: int, largest: int) -> int:
    """Runs per Dask task when none is asked: about four tasks per worker thread (load
    balance), at most the engine's chunk."""
    return max(1, min(largest, -(-runs // (4 * max(threads, 1)))))


def task_threads(threads: int | None, scheduler: str | None) -> int:
    """The kernel's threads per call: as asked; else every core in this process (0),
    one per Dask task (Dask runs a task per worker thread)."""
    if threads is not None:
        return threads
    return 1 if scheduler is not None else 0


def fixed_items(fixed: Mapping[str, float]) -> tuple[tuple[str, float], ...]:
    return tuple((k, float(v)) for k, v in fixed.items())
