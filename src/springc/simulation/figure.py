"""The figure of a result: a PlotLayout drawn as a matplotlib Figure that shows itself
inline in Jupyter.

Imported on first plot only (matplotlib is heavy). The figure is drawn on the Agg
canvas without pyplot, so the user's matplotlib backend is left alone; ``_repr_png_``
lets Jupyter show it inline whatever backend is configured. Which panels are drawn is
decided in :mod:`.plot_layout`; the choice is kept as ``figure.layout`` and its note
is written under the title.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .plot_layout import HEATMAP, Panel, PlotLayout

NOTE_WIDTH = 150
"""Characters per line of the note under the title."""
NOTE_LINE = 0.2
"""Inches per line of the note."""
AXES_WIDTH = 8.9
"""Inches of a panel's width (the legends go to its right, outside the curves)."""
LEGEND_CHAR = 0.065
"""Inches per character of a legend entry (8 points)."""


class ResultFigure(Figure):
    """A matplotlib Figure (on the Agg canvas) that Jupyter displays as a PNG;
    ``layout`` is the choice of panels it shows."""

    layout: PlotLayout | None = None

    def __init__(self, width: float, height: float) -> None:
        super().__init__(figsize=(width, height))
        FigureCanvasAgg(self)

    def _repr_png_(self) -> bytes:
        buffer = io.BytesIO()
        self.savefig(buffer, format="png", dpi=100)
        return buffer.getvalue()


def plain_text(text: str) -> str:
    """``text`` as matplotlib shows it literally: a ``$`` would start mathtext."""
    return text.replace("$", r"\$")


def draw_layout(model: str, time: np.ndarray, values: np.ndarray,
                layout: PlotLayout, names: Sequence[str]) -> ResultFigure:
    """``layout`` as a figure: one row per panel, the legends to the right of the
    curves, a colour bar beside each heat map, the note under the title. Names and
    units are shown literally."""
    panels = layout.panels
    note = textwrap.wrap(layout.note, NOTE_WIDTH)
    top = 0.55 + NOTE_LINE * len(note)
    height = 1.2 + 2.3 * max(1, len(panels)) + NOTE_LINE * len(note)
    longest = max((len(label) for panel in panels for label in panel.labels), default=0)
    legend = 0.6 + LEGEND_CHAR * min(longest, 60) if longest else 0.0
    bars = any(panel.kind == HEATMAP for panel in panels)
    side = max(legend, 0.9 if bars else 0.2)
    width = 0.9 + AXES_WIDTH + side
    fig = ResultFigure(width, height)
    # Fixed margins (in inches) instead of tight_layout, which costs a quarter second;
    # with heat maps, a narrow second column holds the colour bars, so that every time
    # axis lines up.
    grid = fig.add_gridspec(max(1, len(panels)), 2 if bars else 1,
                            width_ratios=(60, 1) if bars else None, wspace=0.02,
                            left=0.9 / width, right=1 - side / width, top=1 - top / height,
                            bottom=0.6 / height, hspace=0.45 if note or bars else 0.35)
    axes: list[Any] = []
    for row, panel in enumerate(panels):
        ax = fig.add_subplot(grid[row, 0], sharex=axes[0] if axes else None)
        axes.append(ax)
        ax.set_title(plain_text(panel.title), fontsize=10, loc="left", y=1.0)  # no search
        if panel.kind == HEATMAP:
            _heat_map(fig, ax, grid[row, 1], panel, time, values)
        else:
            _lines(ax, panel, time, values)
    if not axes:
        axes.append(fig.add_subplot(grid[0, 0]))
        axes[0].text(0.5, 0.5, "no variables selected", ha="center")
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(plain_text(model), fontsize=11, y=1 - 0.12 / height, va="top")
    if note:
        fig.text(0.5, 1 - 0.4 / height, plain_text("\n".join(note)), ha="center",
                 va="top", fontsize=8)
    fig.layout = layout
    return fig


def _lines(ax: Any, panel: Panel, time: np.ndarray, values: np.ndarray) -> None:
    """One line per column (steps for a discrete one), the legend outside at the right."""
    for column, label in zip(panel.columns, panel.labels):
        style = "steps-post" if column in panel.steps else "default"
        ax.plot(time, values[:, column], label=plain_text(label), linewidth=1.2,
                drawstyle=style)
    ax.set_ylabel(plain_text(panel.label))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              frameon=False)


def _heat_map(fig: Figure, ax: Any, bar_cell: Any, panel: Panel, time: np.ndarray,
              values: np.ndarray) -> None:
    """The columns as image rows, the first at the top (a cloth's first row hangs
    there), and the colour bar in ``bar_cell``. The image holds the values as float32:
    matplotlib keeps each map's data and resamples it in the data's precision when
    drawing (four maps of 2,500 x 501 values: half the memory of float64, the drawing
    of a 50x50 cloth's plot peaks over its result of 516 MB), and a colour is one of
    256 steps of the colour map, far coarser than float32's 7 digits. The map is
    resampled to the figure's pixels before it is coloured (``interpolation_stage``
    ``data``: the nearest value of each pixel, then its colour, the same pixels as
    colouring first); coloured first, matplotlib made an RGBA array of float64 for
    every value (the 50x50 cloth: 40 MB a map, 85 MB at most while saving the four)."""
    rows = len(panel.columns)
    data = np.asarray(values[:, list(panel.columns)].T, dtype=np.float32)
    image = ax.imshow(data, aspect="auto", origin="upper",
                      interpolation="nearest", interpolation_stage="data", cmap="viridis",
                      extent=(float(time[0]), float(time[-1]), rows + 0.5, 0.5))
    ax.set_ylabel("variable (model order)")
    bar = fig.colorbar(image, cax=fig.add_subplot(bar_cell))
    bar.set_label(plain_text(panel.label), fontsize=8)
