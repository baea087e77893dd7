"""Where the batches run: local processes (default) or a Dask distributed scheduler.

Both engines take the same function (:func:`springc.studies.job.run_batch`) and yield
each batch's records as soon as it completes, in completion order:

- :func:`local_batches`: a ``concurrent.futures.ProcessPoolExecutor`` of the ``spawn``
  context (a fresh interpreter per worker: no state of the caller is inherited, and it
  works the same on every platform). BLAS is pinned to one thread in the workers
  (``OPENBLAS_NUM_THREADS=1`` and the like, unless the caller set them), since the
  solvers' vectors are small and the processes already use the cores.
- :func:`dask_batches`: a ``distributed.Client`` connected to a running scheduler
  (``dask scheduler`` + ``dask worker ADDRESS``). Dask's nanny pins BLAS to one thread
  in its workers by default. Workers need springc installed and the model files readable
  at the same absolute paths (a shared folder).

Leaving the iteration early (an error, Ctrl-C) cancels the batches not started; the
local pool waits for its running batches, which are short (see :func:`batches`).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from collections.abc import Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from ..errors import SimulationError, UsageError
from .job import RunJob, RunRecord, run_batch

Batch = tuple[tuple[int, tuple[float, ...]], ...]
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
MAX_BATCH = 16
"""The most runs in one batch: a batch is the unit of scheduling and of resuming."""


def batches(runs: Sequence[tuple[int, tuple[float, ...]]], workers: int) -> list[Batch]:
    """``runs`` cut into batches: about eight per worker for load balance, at most
    :data:`MAX_BATCH` runs each so that progress and resuming stay fine-grained."""
    size = max(1, min(MAX_BATCH, len(runs) // max(1, 8 * workers)))
    return [tuple(runs[i:i + size]) for i in range(0, len(runs), size)]


def default_workers() -> int:
    """The cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def single_threaded_blas() -> Iterator[None]:
    """Set the BLAS thread variables to 1 (where unset) while the workers start."""
    added = [name for name in BLAS_THREADS if name not in os.environ]
    for name in added:
        os.environ[name] = "1"
    try:
        yield
    finally:
        for name in added:
            os.environ.pop(name, None)


def local_batches(job: RunJob, work: Sequence[Batch], workers: int
                  ) -> Iterator[list[RunRecord]]:
    """Run ``work`` on ``workers`` local processes; each batch's records when done."""
    context = multiprocessing.get_context("spawn")
    with single_threaded_blas():
        pool = ProcessPoolExecutor(workers, mp_context=context)
        futures: list[Future[list[RunRecord]]] = []
        try:
            futures = [pool.submit(run_batch, job, batch) for batch in work]
            for future in as_completed(futures):
                yield future.result()
        except BrokenProcessPool:
            raise SimulationError(
                "a worker process of the study ended abruptly (killed, or out of memory?)",
                hint="runs already written are kept: rerun with --resume (and fewer "
                "--workers if memory is short)") from None
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def connect(address: str) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address`` (a UsageError naming
    ``--scheduler`` if there is none)."""
    try:
        from distributed import Client
    except ImportError:
        raise UsageError("--scheduler needs Dask distributed: pip install "
                         "'springc[cluster]'", option="--scheduler") from None
    try:
        return Client(address, timeout="10s",  # type: ignore[no-untyped-call]
                      set_as_default=False)
    except (OSError, TimeoutError, ValueError) as err:
        raise UsageError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                         f"({err})", option="--scheduler",
                         hint="start one with 'dask scheduler' and workers with "
                         "'dask worker ADDRESS'") from None


def dask_workers(client: Any) -> int:
    """The threads of the Dask cluster (at least 1)."""
    info = client.scheduler_info()
    return max(1, sum(int(w.get("nthreads", 1)) for w in info["workers"].values()))


def dask_batches(client: Any, job: RunJob, work: Sequence[Batch]
                 ) -> Iterator[list[RunRecord]]:
    """Run ``work`` on the Dask cluster of ``client``; each batch's records when done."""
    from distributed import as_completed as dask_completed

    futures = [client.submit(run_batch, job, batch, pure=False)
               for batch in work]
    try:
        for future in dask_completed(futures, loop=client.loop):  # type: ignore[no-untyped-call]
            yield future.result()
    finally:
        client.cancel(futures)
