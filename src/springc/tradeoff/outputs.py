"""The files of a study: Tradeoff -> table CSV, work-precision plot, reference CSV.

Every requested file is rendered first and renamed into place only when all are
complete (:class:`springc.fileio.OutputSet`): a failure leaves none of them behind.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from ..fileio import OutputSet, PathLike
from .model import Tradeoff
from .plot import PLOT_KINDS, render_work_precision
from .reference import write_reference_csv
from .report import write_table


def save_study(study: Tradeoff, *, table: PathLike | None = None,
               plot: PathLike | None = None, reference: PathLike | None = None,
               protected: Iterable[PathLike] = ()) -> None:
    """Write the requested files of ``study``; files in ``protected`` are never replaced.
    The plot's format follows its suffix (PNG, SVG or PDF; PNG for another suffix)."""
    picture = None
    if plot is not None:
        picture = render_work_precision(
            study, PLOT_KINDS.get(Path(plot).suffix.lower(), "png"))
    with OutputSet(protected) as outputs:
        if table is not None:
            with outputs.open(table, "w") as f:
                write_table(study, f)
        if reference is not None:
            with outputs.open(reference, "w") as f:
                write_reference_csv(study.reference, f)
        if plot is not None and picture is not None:
            with outputs.open(plot, "wb") as f:
                f.write(picture)
