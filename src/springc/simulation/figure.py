"""The figure of a result for notebooks: a matplotlib Figure that shows itself inline.

Imported on first plot only (matplotlib is heavy). The figure is drawn on the Agg
canvas without pyplot, so the user's matplotlib backend is left alone; ``_repr_png_``
lets Jupyter show it inline whatever backend is configured.
"""

from __future__ import annotations

import io

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


class ResultFigure(Figure):
    """A matplotlib Figure (on the Agg canvas) that Jupyter displays as a PNG."""

    def __init__(self, width: float, height: float) -> None:
        super().__init__(figsize=(width, height))
        FigureCanvasAgg(self)

    def _repr_png_(self) -> bytes:
        buffer = io.BytesIO()
        self.savefig(buffer, format="png", dpi=100)
        return buffer.getvalue()
