"""The values a run is checked against before any work: times, tolerances, steps and
parameter values, named as the caller spells them (keywords or command-line options).

One owner for these checks: the API, the command line and ``TradeoffOptions`` call
:func:`check_run_values`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from ..errors import UsageError

API_NAMES = {"start": "start", "stop": "stop", "interval": "interval", "rtol": "rtol",
             "atol": "atol", "step": "step", "parameters": "parameters"}
"""How :func:`check_run_values` names each value: the keywords of :func:`simulate`."""


MAX_INTERVALS = 10_000_000
"""The most output intervals a run may have."""


def as_number(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise UsageError(f"{name} must be a number, not {value!r}", option=name)
    return float(value)


def check_run_values(start: float | None = None, stop: float | None = None,
                     interval: float | None = None, rtol: float | None = None,
                     atol: float | None = None, step: float | None = None,
                     parameters: Mapping[str, float] | None = None,
                     names: Mapping[str, str] = API_NAMES) -> None:
    """Refuse values no run can use, before any work, with a :class:`UsageError` naming
    the value as ``names`` spells it (the command line passes its option names).

    Times must be finite, ``stop`` after ``start``; ``interval`` and ``step`` finite and
    positive; ``rtol`` in (0, 1); ``atol`` finite and positive; parameter values finite.
    """
    def finite(value: float | None, key: str) -> float | None:
        if value is None:
            return None
        number = as_number(value, names[key])
        if not math.isfinite(number):
            raise UsageError(f"{names[key]} must be a finite number, not {number!r}",
                             option=names[key])
        return number

    first, last = finite(start, "start"), finite(stop, "stop")
    if first is not None and last is not None and not last > first:
        raise UsageError(f"{names['stop']} ({last:g}) must be after {names['start']} "
                         f"({first:g})", option=names["stop"])
    if first is not None and last is not None and not math.isfinite(last - first):
        raise UsageError(f"{names['start']} {first:g} to {names['stop']} {last:g}: the "
                         "span is too large for a floating-point number",
                         option=names["stop"])
    for key, value in (("interval", interval), ("step", step), ("atol", atol)):
        number = finite(value, key)
        if number is not None and not number > 0:
            raise UsageError(f"{names[key]} must be a finite number > 0, not {number!r}",
                             option=names[key])
    if interval is not None and last is not None:
        span = last - (first if first is not None else 0.0)
        if span / float(interval) > MAX_INTERVALS:
            raise UsageError(f"{names['interval']} {interval:g}: {span / interval:.3g} "
                             f"output intervals are too many (at most {MAX_INTERVALS:,})",
                             option=names["interval"], hint=f"use a larger "
                             f"{names['interval']}")
    if rtol is not None:
        number = as_number(rtol, names["rtol"])
        if not 0 < number < 1:
            raise UsageError(f"{names['rtol']} must be a finite number in (0, 1), not "
                             f"{number!r}", option=names["rtol"])
    for name, value in (parameters or {}).items():
        number = as_number(value, f"the value of {name}")
        if not math.isfinite(number):
            raise UsageError(f"{names['parameters']}: the value of '{name}' must be a "
                             f"finite number, not {number!r}", option=names["parameters"])
