"""The ``experiment`` annotation of the simulated model: simulation defaults."""

from __future__ import annotations

import math

from ..errors import FlattenError
from ..ir import flat
from ..ir import syntax as s
from ..parse import ClassEntry
from .scopes import ClassScope, FlattenContext

_FIELDS = {"StartTime": "start", "StopTime": "stop", "Interval": "interval",
           "Tolerance": "tolerance"}


def experiment_of(flattener: FlattenContext, entry: ClassEntry, top: ClassScope) -> flat.Experiment:
    """Read ``annotation(experiment(StartTime, StopTime, Interval, Tolerance))``."""
    annotation = entry.defn.annotation
    if annotation is None:
        return flat.Experiment()
    values: dict[str, float] = {}
    for arg in annotation.arguments:
        if arg.path != ("experiment",) or arg.modification is None:
            continue
        for item in arg.modification.arguments:
            key = _FIELDS.get(".".join(item.path))
            if key is None or item.modification is None or item.modification.value is None:
                continue
            value = _number(flattener, item.modification.value, top)
            values[key] = value
    return flat.Experiment(**values)


def _number(flattener: FlattenContext, e: s.Expr, top: ClassScope) -> float:
    value = flattener.evaluator.constant(e, top, "an experiment setting")
    if not isinstance(value, (int, float)) or isinstance(value, bool) \
            or not math.isfinite(value):
        shown = "an array" if hasattr(value, "shape") else repr(value)
        raise FlattenError(f"experiment settings must be finite numbers, found {shown}",
                           e.span)
    return float(value)
