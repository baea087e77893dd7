"""Where the batches run: local processes (default) or a Dask distributed scheduler.

Both engines map a function over tasks (:func:`local_map`, :func:`dask_map`) and yield
each task's result as soon as it completes, in completion order; a study's tasks are
batches of runs (:func:`springc.studies.job.run_batch`), and :class:`Executor` offers
the same engines to other callers (``springc tradeoff`` runs its solvers through it):

- :func:`local_map`: a ``concurrent.futures.ProcessPoolExecutor`` of the ``spawn``
  context (a fresh interpreter per worker: no state of the caller is inherited, and it
  works the same on every platform). BLAS is pinned to one thread in the workers
  (``OPENBLAS_NUM_THREADS=1`` and the like, unless the caller set them), since the
  solvers' vectors are small and the processes already use the cores.
- :func:`dask_map`: a ``distributed.Client`` connected to a running scheduler
  (``dask scheduler`` + ``dask worker ADDRESS``). Dask's nanny pins BLAS to one thread
  in its workers by default. Workers need springc installed (the same version); the
  compiled model travels with each batch, so they need no model files.

Leaving the iteration early (an error, Ctrl-C) cancels the batches not started; the
local pool waits for its running batches, which are short (see :func:`batches`).
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing
import os
import socket
import struct
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from ..errors import SimulationError, UsageError
from .job import RunJob, RunRecord, run_batch

Batch = tuple[tuple[int, tuple[float, ...]], ...]
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
T = TypeVar("T")
R = TypeVar("R")
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


def local_map(function: Callable[[T], R], items: Sequence[T], workers: int
              ) -> Iterator[tuple[int, R]]:
    """``function(item)`` for every item on ``workers`` local processes: (index of the
    item, result) as each completes. ``function`` and the items must pickle."""
    context = multiprocessing.get_context("spawn")
    with single_threaded_blas():
        pool = ProcessPoolExecutor(workers, mp_context=context)
        futures: dict[Future[R], int] = {}
        try:
            futures = {pool.submit(function, item): i for i, item in enumerate(items)}
            for future in as_completed(futures):
                yield futures[future], future.result()
        except BrokenProcessPool:
            raise SimulationError(
                "a worker process of the study ended abruptly (killed, or out of memory?)",
                hint="runs already written are kept: rerun with --resume (and fewer "
                "--workers if memory is short)") from None
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def local_batches(job: RunJob, work: Sequence[Batch], workers: int
                  ) -> Iterator[list[RunRecord]]:
    """Run ``work`` on ``workers`` local processes; each batch's records when done."""
    for _, records in local_map(functools.partial(run_batch, job), work, workers):
        yield records


CONNECT_SECONDS = 10.0
"""How long connecting to a scheduler (and reading its greeting) may take."""
MAX_GREETING = 1 << 24
"""The largest first message a Dask scheduler is believed to send (its handshake is a
few hundred bytes): a larger length read from a service is not Dask's protocol."""


def connect(address: str) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address``: a UsageError naming
    ``--scheduler`` if there is none, or if the service there is not a Dask scheduler
    (within about ``CONNECT_SECONDS``)."""
    try:
        from distributed import Client
    except ImportError:
        raise UsageError("--scheduler needs Dask distributed: pip install "
                         "'springc[cluster]'", option="--scheduler") from None
    problem = probe(address)
    if problem is None:
        try:
            return Client(address, timeout=f"{CONNECT_SECONDS}s",  # type: ignore[no-untyped-call]
                          set_as_default=False)
        except (OSError, TimeoutError, ValueError, MemoryError) as err:
            problem = str(err)
    raise UsageError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                     f"({problem})", option="--scheduler",
                     hint="start one with 'dask scheduler' and workers with "
                     "'dask worker ADDRESS'")


def probe(address: str) -> str | None:
    """Why the TCP service at ``address`` (``tcp://HOST:PORT`` or ``HOST:PORT``) is not a
    Dask scheduler, read from its first bytes: a scheduler greets every connection with
    a message whose 8-byte length comes first. ``None`` if it may be one, or if the
    address is of another kind (Dask's own client judges those)."""
    scheme, _, rest = address.rpartition("://")
    host, colon, port = rest.rpartition(":")
    if scheme not in ("", "tcp") or not colon or not port.isdigit() or int(port) > 65535:
        return None
    try:
        with socket.create_connection((host.strip("[]"), int(port)),
                                      timeout=CONNECT_SECONDS) as sock:
            head = b""
            while len(head) < 8:
                chunk = sock.recv(8 - len(head))
                if not chunk:
                    return "the service closed the connection without a greeting"
                head += chunk
    except TimeoutError:
        return f"no greeting within {CONNECT_SECONDS:g} s: not a Dask scheduler"
    except OSError as err:
        return err.strerror or str(err)
    (length,) = struct.unpack("Q", head)
    if not 0 < length <= MAX_GREETING:
        return "the service there does not speak Dask's protocol"
    return None


def dask_workers(client: Any) -> int:
    """The threads of the Dask cluster (at least 1)."""
    info = client.scheduler_info()
    return max(1, sum(int(w.get("nthreads", 1)) for w in info["workers"].values()))


def dask_map(client: Any, function: Callable[[T], R], items: Sequence[T]
             ) -> Iterator[tuple[int, R]]:
    """``function(item)`` for every item on the Dask cluster of ``client``: (index of the
    item, result) as each completes."""
    from distributed import as_completed as dask_completed

    futures = [client.submit(function, item, pure=False) for item in items]
    index = {future.key: i for i, future in enumerate(futures)}
    try:
        for future in dask_completed(futures, loop=client.loop):  # type: ignore[no-untyped-call]
            yield index[future.key], future.result()
    finally:
        client.cancel(futures)


def dask_batches(client: Any, job: RunJob, work: Sequence[Batch]
                 ) -> Iterator[list[RunRecord]]:
    """Run ``work`` on the Dask cluster of ``client``; each batch's records when done."""
    for _, records in dask_map(client, functools.partial(run_batch, job), work):
        yield records


class Executor:
    """Where a study's independent tasks run: ``workers`` local processes (default: one
    per core), or the Dask scheduler at ``scheduler``. :meth:`map` yields (index,
    result) as tasks complete; ``tradeoff`` runs its solvers through it."""

    def __init__(self, workers: int | None = None, scheduler: str | None = None) -> None:
        if workers is not None and workers < 1:
            raise UsageError(f"--workers must be at least 1, not {workers}",
                             option="--workers")
        self.workers, self.scheduler = workers, scheduler

    def describe(self, tasks: int) -> str:
        """The engine's name for ``tasks`` tasks: ``2 local processes``, ``Dask at ...``."""
        if self.scheduler is not None:
            return f"Dask at {self.scheduler}"
        count = min(tasks, self.workers or default_workers())
        return f"{count} local process{'es' if count > 1 else ''}"

    def map(self, function: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[int, R]]:
        """``function(item)`` for every item, (index, result) in completion order."""
        if not items:
            return
        if self.scheduler is not None:
            client = connect(self.scheduler)
            try:
                yield from dask_map(client, function, items)
            finally:
                client.close()
            return
        yield from local_map(function, items, min(len(items),
                                                  self.workers or default_workers()))
