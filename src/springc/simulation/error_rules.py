"""The arithmetic of a run's error estimate and its rule, on plain floats (no numpy).

One owner for the numbers :mod:`.error_estimate` and :mod:`.error_control` compute and
for the warm path of the command line (:mod:`springc.launcher`), which replays a run
without numpy and must print what the full path prints: the companion's tolerances,
the largest difference of each output column from the companion's (and its row), the
scale and relative error of each column, the error each column may have (``FACTOR *
(rtol * scale + atol)``), the column furthest from it and the numbers of the summary.
:func:`.error_estimate.compare` computes :func:`largest_differences` on numpy arrays, a
pass of columns at a time (a large scene's result); ``tests/simulation/test_error_rules.py``
holds the two to the same values, row indices included.
"""

from __future__ import annotations

from collections.abc import Sequence

COMPANION_FACTOR = 1000.0
TIGHTEST_RTOL = 1e-13
"""The companion's rtol is never below this (DOP853's limit is about 100 eps)."""
FACTOR = 10.0
"""A variable's estimated error may be this many times its tolerance ``rtol*scale + atol``."""


def companion_tolerances(rtol: float, atol: float) -> tuple[float, float]:
    """The companion run's rtol and atol: :data:`COMPANION_FACTOR` times tighter."""
    tight_rtol = max(float(f"{rtol / COMPANION_FACTOR:.12g}"), TIGHTEST_RTOL)
    return tight_rtol, float(f"{atol * tight_rtol / rtol:.12g}")


def largest_differences(ours: Sequence[Sequence[float]], theirs: Sequence[Sequence[float]],
                        gain: float = 1.0) -> tuple[list[float], list[float], list[int]]:
    """Per column of one run's outputs ``ours`` (a sequence of columns, each over the
    output rows) against the same columns ``theirs`` of its companion (row for row):
    the column's largest magnitude (its scale), the largest
    ``|(ours - theirs) * gain|`` and the first row where it occurs."""
    scales, absolute, rows = [], [], []
    for mine, other in zip(ours, theirs):
        scales.append(max(map(abs, mine), default=0.0))
        errors = [abs((a - b) * gain) for a, b in zip(mine, other)]
        best = max(errors, default=0.0)
        absolute.append(best)
        rows.append(errors.index(best) if errors else 0)
    return scales, absolute, rows


def relative_errors(absolute: Sequence[float], scales: Sequence[float]) -> list[float]:
    """Each column's error over its scale (over 1 where the scale is 0)."""
    return [a / (s if s > 0 else 1.0) for a, s in zip(absolute, scales)]


def allowed_errors(scales: Sequence[float], rtol: float, atol: float) -> list[float]:
    """The error each column may have: ``FACTOR * (rtol * scale + atol)``."""
    return [FACTOR * (rtol * s + atol) for s in scales]


def worst_column(absolute: Sequence[float], tolerance: Sequence[float]) -> int:
    """The first column furthest from its tolerance (largest ``absolute / tolerance``);
    -1 without columns."""
    ratios = [a / t for a, t in zip(absolute, tolerance)]
    return ratios.index(max(ratios)) if ratios else -1


def short(x: float) -> str:
    """``1e-06`` -> ``1e-6``, ``2.9e-04`` -> ``2.9e-4``: numbers in the summary."""
    return f"{x:.2g}".replace("e-0", "e-").replace("e+0", "e+")
