"""Work-precision plot: Tradeoff -> PNG, SVG or PDF (max error against wall time and
against RHS evaluations, log-log, one line per solver, scipy's default call as a star)."""

from __future__ import annotations

import io
import math
from pathlib import Path

from ..fileio import atomic_write
from .model import SCIPY_DEFAULT, SCIPY_RK45, Run, Tradeoff

PLOT_KINDS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""Suffix -> format of the plot file."""
ERROR_FLOOR = 1e-16
"""Errors of exactly zero are drawn here (a log axis has no zero)."""


def _points(runs: list[Run], x: str) -> tuple[list[float], list[float]]:
    ok = [r for r in runs if r.ok and math.isfinite(r.max_error)]
    xs = [r.wall_time if x == "time" else float(r.rhs_evaluations) for r in ok]
    return xs, [max(r.max_error, ERROR_FLOOR) for r in ok]


def write_work_precision(tradeoff: Tradeoff, path: str | Path) -> None:
    """The plot of :func:`render_work_precision` in the format of ``path``'s suffix
    (PNG for an unknown one), written atomically."""
    picture = render_work_precision(tradeoff, PLOT_KINDS.get(Path(path).suffix.lower(),
                                                             "png"))
    with atomic_write(path, "wb") as f:
        f.write(picture)


def render_work_precision(tradeoff: Tradeoff, kind: str = "png") -> bytes:
    """Two panels, max error vs wall time and vs RHS evaluations, as ``kind`` bytes
    (png, svg, pdf). The model's name is shown literally (a ``$`` is no mathtext)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.8))
    fig.subplots_adjust(left=0.07, right=0.98, top=0.88, bottom=0.12, wspace=0.22)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2)
    solvers = list(dict.fromkeys(r.solver for r in tradeoff.runs))
    default = [b for b in tradeoff.baselines if b.solver == SCIPY_DEFAULT]
    tightened = [b for b in tradeoff.baselines if b.solver == SCIPY_RK45]
    for ax, x in zip(axes, ("time", "rhs")):
        for solver in solvers:
            runs = [r for r in tradeoff.runs if r.solver == solver]
            xs, ys = _points(runs, x)
            if xs:
                (line,) = ax.plot(xs, ys, marker="o", markersize=4, label=solver)
                first = next(r for r in runs if r.ok)
                ax.annotate(first.label(), (xs[0], ys[0]), fontsize=6,
                            color=line.get_color(), xytext=(3, 3),
                            textcoords="offset points")
        xs, ys = _points(tightened, x)
        if xs:
            ax.plot(xs, ys, marker="x", linestyle=":", color="0.45",
                    label="scipy solve_ivp RK45, tightened")
        xs, ys = _points(default, x)
        if xs:
            ax.plot(xs, ys, marker="*", markersize=13, linestyle="none", color="black",
                    label="scipy solve_ivp default (RK45, rtol 1e-3)")
        for target in tradeoff.targets:
            ax.axhline(target, color="tab:red", linestyle="--", linewidth=0.8)
        if math.isfinite(tradeoff.reference.agreement):
            ax.axhline(max(tradeoff.reference.agreement, ERROR_FLOOR), color="0.6",
                       linestyle=":", linewidth=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlabel("wall time [s]" if x == "time" else "RHS evaluations")
    axes[0].set_ylabel("max relative error on the output grid")
    axes[0].legend(fontsize=7, loc="lower left")
    targets = ", ".join(f"{t:.0e}" for t in tradeoff.targets)
    model = tradeoff.model.replace("$", r"\$")  # shown literally, not as mathtext
    fig.suptitle(f"{model}: work-precision ({tradeoff.states} states; dashed: "
                 f"target {targets}; dotted: reference agreement)", fontsize=10)
    buffer = io.BytesIO()
    fig.savefig(buffer, format=kind, dpi=100)
    return buffer.getvalue()
