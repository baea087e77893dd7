"""The engine of a hybrid model: the scipy engine locates events; the compiled loops
of ``springc.integrate`` do not yet, so they never run a model with events."""

from __future__ import annotations

from ..errors import UsageError
from .compiled import COMPILED, SCIPY


def events_engine(model: str, engine: str) -> str:
    """:data:`SCIPY` for a model with events; ``--engine compiled`` is a usage error
    (``auto`` falls back to scipy)."""
    if engine.lower() == COMPILED:
        raise UsageError(f"{model} has events (when-clauses, relations or sample), which "
                         "the compiled engine does not locate yet", option="--engine",
                         hint="use --engine scipy (or auto, which runs hybrid models on "
                              "scipy)")
    return SCIPY
