"""The ``springc`` command's entry point: a warm ``simulate`` replayed with the standard
library only, everything else (and every doubt) handed to the click command line.

``springc simulate`` of a model whose run springc has made before, with the same
command line, folder and environment (:func:`springc.run_record.lookup_key`), replays
that run from its record: it checks every input file and the loop library against
their recorded SHA-256 (:func:`springc.run_record.verified`), runs the answer run and
its error-control companion on the model's C loop library (:mod:`springc.native.runner`,
ctypes), estimates the error with :mod:`springc.simulation.error_rules`, writes the CSV
with :func:`springc.simulation.csv_rows.write_rows` through :mod:`springc.fileio` (the
same output rules) and prints the summary line of :func:`springc.simulation.summary.brief_line`.
No numpy, numba, scipy, click or compile path is imported: under 0.1 s of CPU where the full
command line takes over a second.

Anything else falls back to :func:`springc.cli.main` with no change in behaviour or
output: another command, a record missing or not verified, an output it would refuse
(the command line says why), a replay that does not end as the recorded run did (its
CSV digest or summary line differ, a run fails, the error rule is broken), any error.
Nothing is written before the replay is complete and checked. No decision reads the
clock.
"""

from __future__ import annotations

import array
import hashlib
import io
import math
import os
import signal
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import FrameType
from typing import Any

from . import run_record
from .errors import OutputError
from .fileio import atomic_write, check_target
from .simulation import (
    IMPLICIT_SOLVERS,
    allowed_errors,
    brief_line,
    companion_solver,
    companion_tolerances,
    largest_differences,
    worst_column,
    write_rows,
)

COMMAND = "simulate"
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE
EXIT_INTERRUPTED = 128 + signal.SIGINT


@dataclass(frozen=True)
class Launched:
    """What the command line learns of its launch (its context's ``obj``): the
    arguments the run record's key is made of (a command line started otherwise, by
    ``springc.cli.main`` in a test, writes no record)."""

    argv: tuple[str, ...]


class Fallback(Exception):
    """The warm path does not handle this run: the command line does."""


def main(argv: Sequence[str] | None = None) -> None:
    """``springc [ARGS]``: the warm replay where it applies, else the click command line."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args[:1] == [COMMAND]:
        code = warm(args)
        if code is not None:
            sys.exit(code)
    from .cli import main as command_line

    command_line(args=args, obj=Launched(tuple(args)))


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM ends the replay as an exception (unfinished outputs removed), as in the
    command line."""
    raise SystemExit(128 + signum)


def warm(args: Sequence[str]) -> int | None:
    """The exit code of the replayed run of ``springc ARGS``, or None where the command
    line must run it (nothing written then)."""
    record = run_record.read(run_record.lookup_key(args))
    if record is None:
        return None
    try:
        if signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
            signal.signal(signal.SIGTERM, _terminate)
    except ValueError:
        pass  # not the main thread
    try:
        csv, line = replay(record)
    except Fallback:
        return None
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        return EXIT_INTERRUPTED
    except (KeyError, TypeError, ValueError, IndexError, OSError, AttributeError):
        return None  # a malformed record or library: the command line runs it
    output = record["output"]
    try:
        _write(csv, output["csv"], output["protected"])
        if not output["quiet"]:
            sys.stderr.write(line + "\n")
            sys.stderr.flush()
    except Fallback:
        return None  # nothing was written
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    return 0


def replay(record: Mapping[str, Any]) -> tuple[str, str]:
    """Run ``record`` again and check it against the record: the CSV text and the
    summary line, or :class:`Fallback` (nothing is written here)."""
    output = record["output"]
    target = output["csv"]
    if output["kind"] != "csv":
        raise Fallback
    if target is not None:
        try:
            check_target(target, output["protected"])
        except OutputError:
            raise Fallback from None  # the command line says why, in its own words
    data = run_record.verified(record)
    if data is None:
        raise Fallback
    from .native import LoopLibrary

    try:
        library = LoopLibrary(data)
    except (RuntimeError, OSError):  # not a loop library of this interface
        raise Fallback from None
    run = record["run"]
    if list(library.names("states")) != run["states"] or \
            list(library.names("observed")) != run["observed"]:
        raise Fallback
    began = time.perf_counter()
    answer = run["answer"]
    columns, steps = _outputs(library, run, answer["solver"], answer["rtol"], answer["atol"])
    estimated = tolerance = None
    if run["mode"] != "off":
        companion = (companion_solver(answer["solver"]),
                     *companion_tolerances(answer["rtol"], answer["atol"]))
        if list(companion) != [run["companion"][k] for k in ("solver", "rtol", "atol")]:
            raise Fallback  # recorded by other rules
        theirs, _ = _outputs(library, run, *companion)
        scales, absolute, _rows = largest_differences(columns, theirs)
        allowed = allowed_errors(scales, run["asked"]["rtol"], run["asked"]["atol"])
        if not all(a <= t for a, t in zip(absolute, allowed)):
            raise Fallback  # the command line tightens or warns
        worst = worst_column(absolute, allowed)
        estimated, tolerance = absolute[worst], allowed[worst]
    text = io.StringIO()
    write_rows(text, run["names"], zip(run["grid"], *columns))
    csv = text.getvalue()
    if hashlib.sha256(csv.encode("utf-8")).hexdigest() != output["sha256"]:
        raise Fallback
    line = brief_line(run["model"], answer["solver"], run["auto"], steps, 0, estimated,
                      tolerance, answer["rtol"], time.perf_counter() - began)
    if line.rsplit(", ", 1)[0] != output["brief"]:
        raise Fallback
    return csv, line


def _outputs(library: Any, run: Mapping[str, Any], solver: str, rtol: float, atol: float
             ) -> tuple[list[Sequence[float]], int]:
    """The output columns (in the record's order, each over the grid) of one run of
    ``solver`` at ``rtol``, ``atol`` from the recorded start, and its accepted steps."""
    grid, p = array.array("d", run["grid"]), array.array("d", run["p"])
    states, accepted = _stretched(library, run, solver, rtol, atol, grid, p)
    failed, observed = library.observed(grid, states, p, array.array("d", run["z"]))
    if failed >= 0:
        raise Fallback
    n, m = library.n_states, library.n_observed
    columns = [states[index::n] if kind == "state" else observed[index::m]
               for kind, index in run["columns"]]
    for column in columns:
        if not all(map(math.isfinite, column)):
            raise Fallback  # the command line's check of the outputs words it
    return columns, accepted


def _stretched(library: Any, run: Mapping[str, Any], solver: str, rtol: float,
               atol: float, grid: array.array[float], p: array.array[float]
               ) -> tuple[array.array[float], int]:
    """The states on the grid (row-major) and the accepted steps of the run, in the
    stretches of the full path (:data:`springc.native.FIRST_STRETCH` steps, then
    :data:`~springc.native.STRETCH_GROWTH` times more each, within the recorded step
    limit), each resumed from where the one before stopped; radau and bdf in the
    recorded ordering of the states."""
    from .native import FIRST_STRETCH, MAX_STEPS, STRETCH_GROWTH

    order = run["order"] if solver in IMPLICIT_SOLVERS else None
    limit, n = int(run["max_steps"]), library.n_states
    times, x, z = grid, array.array("d", run["x0"]), array.array("d", run["z"])
    states, first, chunk, accepted = array.array("d"), 0.0, FIRST_STRETCH, 0
    while True:
        done = library.run(solver, times, x, p, z, rtol=rtol, atol=atol, order=order,
                           first_step=min(first, times[-1] - times[0]),
                           max_steps=max(min(chunk, limit - accepted), 1))
        accepted += done.accepted_steps
        states.extend(done.states[(n if states else 0):done.filled * n])  # row 0: its start
        if done.status != MAX_STEPS or accepted >= limit:
            break
        times = array.array("d", [done.failure_time]) + times[done.filled:]
        x, first, chunk = done.failure_state, done.next_step, chunk * STRETCH_GROWTH
    if not done.ok or len(states) != len(grid) * n:
        raise Fallback
    return states, accepted


def _write(csv: str, target: str | None, protected: Sequence[str]) -> None:
    """The CSV into the file ``target`` (the one writer's rules), or on stdout."""
    if target is None:
        sys.stdout.write(csv)
        sys.stdout.flush()
        return
    try:
        with atomic_write(target, "w", protected) as f:
            f.write(csv)
    except OutputError:
        raise Fallback from None  # changed since the check: the command line says why


def _silence_stdout() -> None:
    """After a closed pipe: send what is left in stdout's buffer nowhere."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    finally:
        os.close(devnull)
