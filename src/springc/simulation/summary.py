"""The short summary line of a run (no numpy): ``SpringMass: dop853 (auto), 2,268 steps,
est. error 4e-06 <= 0.0003 at rtol 1e-09, 3.41 s``.

:meth:`.results.SimulationStats.brief` and the command line's warm path
(:mod:`springc.launcher`) both print it through :func:`brief_line`.
"""

from __future__ import annotations

from ..errors import printable


def one_digit(value: float) -> str:
    """One significant digit, the exponent without a leading zero (``4e-6``)."""
    return f"{value:.1g}".replace("e-0", "e-").replace("e+0", "e+")


def brief_line(model: str, solver: str, auto: bool, steps: int, events: int,
               estimated_error: float | None, error_tolerance: float | None,
               rtol: float | None, wall_time: float) -> str:
    """Model, solver (``(auto)``: auto's choice), steps, events, the estimated error
    against its tolerance and the rtol it was reached at, wall time."""
    parts = [f"{printable(model)}: {solver}{' (auto)' if auto else ''}", f"{steps:,} steps"]
    if events:
        parts.append(f"{events:,} event{'s' if events != 1 else ''}")
    if estimated_error is not None:
        text = f"est. error {one_digit(estimated_error)}"
        if error_tolerance is not None:
            within = estimated_error <= error_tolerance
            text += f" {'<=' if within else '>'} {one_digit(error_tolerance)}"
        parts.append(text + (f" at rtol {one_digit(rtol)}" if rtol else ""))
    parts.append(f"{wall_time:.2f} s")
    return ", ".join(parts)
