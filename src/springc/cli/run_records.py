"""After a ``simulate``: the run record that lets the next identical command replay the
run with the standard library only (:mod:`springc.run_record`, :mod:`springc.launcher`).

A record is written only for what the warm path replays exactly: a command started by
the ``springc`` entry point (the launcher hands its arguments over as the context's
``obj``); a trajectory as CSV (a file or stdout) and nothing else; the default verbosity
or ``-q``; a model in the cache, without events, delays, switching states, assertions
or unit warnings; an answer of a method of the model's C loop library (``dop853``,
``rk45``, ``radau``, ``bdf``: :data:`springc.native.METHODS`) that ran there, with no
warning (radau and bdf asked for by name: ``auto`` hands over to radau within a run,
which a replay from the start would not repeat; their band LU's ordering of the states
recorded); every output finite. Anything else keeps no record, and its next run takes
the command line again.
"""

from __future__ import annotations

import hashlib
import io
from collections.abc import Sequence
from typing import Any

import click

from .. import run_record
from ..native import METHODS

LOOP_SOLVERS = tuple(METHODS)
"""The methods of the C loop library (:mod:`springc.native.runner`)."""
MAX_VALUES = 1_000_000
"""Output values (rows x columns) beyond which no record is kept: the warm path's
arithmetic in plain Python would cost about what it saves."""


def launched_argv() -> tuple[str, ...] | None:
    """The arguments of the command line, where the ``springc`` entry point started it."""
    argv = getattr(click.get_current_context().find_root().obj, "argv", None)
    return tuple(argv) if isinstance(argv, tuple) else None


def remember_run(compiled: Any, settings: Any, result: Any, files: Sequence[str],
                 libraries: Sequence[str], output: str | None, quiet: bool) -> None:
    """Write the record of this run where the warm path can replay it (module text)."""
    argv = launched_argv()
    if argv is None:
        return
    content = record_content(compiled, settings, result, files, libraries, output, quiet)
    if content is not None:
        run_record.write(run_record.lookup_key(argv), content)


def record_content(compiled: Any, settings: Any, result: Any, files: Sequence[str],
                   libraries: Sequence[str], output: str | None, quiet: bool
                   ) -> dict[str, Any] | None:
    """The record of the run (``settings``: as the run was asked), or None."""
    from ..integrate import band_order
    from ..native import LIBRARY_FILE, cached_library
    from ..pipeline import ModuleKind
    from ..simulation import (
        IMPLICIT_SOLVERS,
        companion_solver,
        companion_tolerances,
        plan,
        write_csv,
    )

    stats, module = result.stats, compiled.module
    if (compiled.lookups is None or compiled.warnings or stats.warning or result.events
            or settings.event_rows or stats.solver not in LOOP_SOLVERS
            or not ran_on_c_loop(compiled, result)
            or (stats.solver in IMPLICIT_SOLVERS and stats.reason)
            or getattr(module, "KIND", None) != ModuleKind.CONTINUOUS
            or getattr(module, "ASSERTIONS", ()) or stats.rtol is None
            or len(result.time) * (1 + len(result.names)) > MAX_VALUES):
        return None
    entry = compiled.path.parent
    data = cached_library(entry)
    if data is None:
        return None
    asked = plan(compiled, settings)
    states, observed = list(compiled.states), list(compiled.observed)
    where = {**{n: ["observed", j] for j, n in enumerate(observed)},
             **{n: ["state", i] for i, n in enumerate(states)}}
    grid = asked.grid.tolist()
    if grid != result.time.tolist() or asked.x0 is None:
        return None
    text = io.StringIO()
    write_csv(result, text)
    return {
        "code": run_record.code_stamp(),
        "files": list(files), "libraries": list(libraries),
        "inputs": compiled.lookups,
        "library": {"path": str(entry / LIBRARY_FILE),
                    "sha256": hashlib.sha256(data).hexdigest()},
        "run": {"model": result.model, "grid": grid, "p": asked.p.tolist(),
                "x0": asked.x0.tolist(),
                "z": [float(v) for v in module.guesses(asked.p)],
                "answer": {"solver": stats.solver, "rtol": stats.rtol, "atol": stats.atol},
                "companion": None if settings.error_control == "off" else dict(zip(
                    ("solver", "rtol", "atol"),
                    (companion_solver(stats.solver),
                     *companion_tolerances(stats.rtol, stats.atol)))),
                "order": band_order(module.JAC_INDPTR, module.JAC_INDICES)
                if stats.solver in IMPLICIT_SOLVERS else None,
                "max_steps": asked.limits.max_steps,
                "asked": {"rtol": asked.rtol, "atol": asked.atol},
                "mode": settings.error_control, "auto": bool(stats.reason),
                "states": states, "observed": observed,
                "columns": [where[n] for n in result.names], "names": list(result.names)},
        "output": {"kind": "csv", "csv": output, "protected": list(files), "quiet": quiet,
                   "brief": stats.brief(result.model).rsplit(", ", 1)[0],
                   "sha256": hashlib.sha256(text.getvalue().encode("utf-8")).hexdigest()},
    }


def ran_on_c_loop(compiled: Any, result: Any) -> bool:
    """Whether the run's answer came from the model's C loop library: the compiled
    engine on a python module (numba's loop runs numba functions only)."""
    return bool(result.stats.engine == "compiled"
                and getattr(compiled.module, "BACKEND", "") == "python")
