"""The plot of a study: one variable across the runs (``springc sweep --plot``).

Up to :data:`MAX_LINES` successful runs are drawn as lines, each labelled with its
swept values; more runs make a fan chart: the median over the runs at each output time,
and bands from the 25th to the 75th percentile, the 5th to the 95th, and the minimum to
the maximum. Failed runs have no trajectory and are counted in the note. matplotlib
is imported on the first plot only.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import UsageError
from .store import column_name
from .study import Study

MAX_LINES = 12
"""The most runs drawn as lines with a legend; more make a fan chart."""
BANDS = ((0.0, 100.0, 0.15), (5.0, 95.0, 0.3), (25.0, 75.0, 0.5))
"""(lower percentile, upper percentile, opacity) of the fan's bands, widest first."""


def plot_variable(variables: Sequence[str], name: str | None) -> str:
    """``name``, else the first of a study's ``variables``; a UsageError naming
    ``--plot-var`` if there is no such variable."""
    if name is None:
        if not variables:
            raise UsageError("--plot: the study has no variables to plot",
                             option="--plot-var")
        return variables[0]
    if name not in variables:
        shown = ", ".join(variables[:8]) + (" ..." if len(variables) > 8 else "")
        raise UsageError(f"--plot-var {name}: not among the study's variables ({shown})",
                         option="--plot-var", hint="select it with --vars")
    return name


def trajectories(study: Study, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(values of ``name`` over run x time for the successful runs, their run numbers)."""
    runs, times = len(study.values), len(study.layout.time)
    column = study.table.column(column_name(name)).to_numpy(zero_copy_only=False)
    values = np.asarray(column, dtype=float).reshape(runs, times)
    ok = np.array([s == "ok" for s in study.summary.column("status").to_pylist()],
                  dtype=bool)
    return values[ok], np.flatnonzero(ok)


def fan_figure(study: Study, name: str) -> tuple[Any, str]:
    """The figure of ``name`` across the runs, and a note saying what it shows."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    values, runs = trajectories(study, name)
    time = study.layout.time
    unit = dict(zip(study.layout.variables, study.layout.units)).get(name, "")
    failed = len(study.values) - len(runs)
    fig = Figure(figsize=(10, 4.6))
    FigureCanvasAgg(fig)
    fig.subplots_adjust(left=0.09, right=0.98, top=0.86, bottom=0.12)
    ax = fig.add_subplot()
    if len(runs) <= MAX_LINES:
        kind = f"{len(runs)} runs as lines"
        for row, run in zip(values, runs):
            label = ", ".join(f"{p}={v:g}" for p, v in zip(study.layout.parameters,
                                                          study.values[run]))
            ax.plot(time, row, linewidth=1.2, label=_plain(label))
    else:
        kind = f"median and percentile bands of {len(runs)} runs"
        for low, high, alpha in BANDS:
            ax.fill_between(time, np.percentile(values, low, axis=0),
                            np.percentile(values, high, axis=0), color="tab:blue",
                            alpha=alpha, linewidth=0,
                            label="min - max" if low == 0 else f"{low:g}-{high:g} %")
        ax.plot(time, np.median(values, axis=0), color="black", linewidth=1.4,
                label="median")
    if len(runs):
        ax.legend(fontsize=8, loc="upper right", ncol=min(3, max(1, len(runs))))
    ax.set_xlabel("time [s]")
    ax.set_ylabel(_plain(f"{name} [{unit}]" if unit else name))
    ax.grid(True, alpha=0.3)
    note = f"{name}: {kind}" + (f"; {failed} failed runs left out" if failed else "")
    fig.suptitle(_plain(f"{study.model}: {name} across {len(study.values)} runs"),
                 fontsize=11)
    fig.text(0.5, 0.905, _plain(note), ha="center", fontsize=8)
    return fig, note


def render_fan(study: Study, name: str, kind: str) -> tuple[bytes, str]:
    """The fan chart as the bytes of a ``kind`` (png, svg, pdf) file, and its note."""
    fig, note = fan_figure(study, name)
    buffer = io.BytesIO()
    fig.savefig(buffer, format=kind, dpi=100)
    return buffer.getvalue(), note


def _plain(text: str) -> str:
    return text.replace("$", r"\$")
