"""Simulation results: SimulationResult -> CSV or MAT file, PNG/SVG/PDF plot, summary.

The CSV has a header ``time`` then the flat names (quoted as RFC 4180 says when they
hold a comma, a quote or a line break), one row per output time, every number written
with ``repr`` (the shortest text that reads back as the same float). The MAT file is
the MATLAB v4 result layout of OpenModelica and Dymola (see :func:`write_mat`).

The writer is chosen by the file's suffix (:data:`RESULT_FORMATS`, :data:`PLOT_FORMATS`);
:func:`save_outputs` renders every requested file before any is renamed into place
(:class:`springc.fileio.OutputSet`), so a failed plot never leaves a new CSV behind.
"""

from __future__ import annotations

import csv
import difflib
import io
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Protocol

import numpy as np

from ..errors import OutputError, SpringcError, UnknownNameError, UsageError, printable
from ..fileio import OutputSet, PathLike, atomic_write
from .csv_rows import write_header, write_lines
from .plot_layout import HEATMAP, PlotLayout, choose_layout, plot_points
from .summary import brief_line
from .tables import array_values, array_variables, html_table, to_pandas, to_xarray

if TYPE_CHECKING:
    from .error_estimate import ErrorEstimate

RESULT_FORMATS = {".csv": "csv", ".mat": "mat"}
"""Suffix -> trajectory format of ``simulate -o``."""
PLOT_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""Suffix -> plot format of ``--plot``."""
REPR_VARIABLES = 4
"""Variables named by a result's ``repr`` before ``... N more``."""


def file_format(path: PathLike, formats: dict[str, str], option: str) -> str:
    """The format of ``path`` from its suffix; a UsageError naming ``option`` if unknown."""
    suffix = Path(os.fspath(path)).suffix.lower()
    if suffix not in formats:
        raise UsageError(f"{option} {os.fspath(path)}: the suffix must be one of "
                         f"{', '.join(formats)} (it chooses the format)", option=option)
    return formats[suffix]


@dataclass(frozen=True)
class SimulationStats:
    solver: str
    steps: int
    rhs_evaluations: int
    jacobian_evaluations: int
    wall_time: float
    model_time: float  # seconds spent in the generated code
    compile_time: float
    cached: bool
    reason: str = ""  # why --solver auto chose ``solver`` (empty: the user chose it)
    note: str = ""  # what the run did differently from what was asked (e.g. the step)
    engine: str = "scipy"  # the step loop: "compiled" (springc.integrate) or "scipy"
    loop_time: float = 0.0  # seconds in the compiled loop (model code included)
    state_events: int = 0  # events of hybrid models (simulation/events.py)
    time_events: int = 0
    error: str = ""  # the error estimate and its verdict in words (empty: not estimated)
    engine_reason: str = ""  # why auto's run (or a fallback to scipy) used this engine
    # --error-control (error_control.py): the tolerances of the run returned (tighter
    # than asked where tightened), the estimated error of the variable furthest from its
    # tolerance and that tolerance (None: not estimated, or no rule), a broken rule
    rtol: float | None = None
    atol: float | None = None
    estimated_error: float | None = None
    error_tolerance: float | None = None
    warning: str = ""

    def brief(self, model: str) -> str:
        """The short summary line (about 100 characters): model, solver, steps, events,
        the estimated error against its tolerance and the rtol it was reached at, wall
        time (``SpringMass: dop853 (auto), 2,268 steps, est. error 4e-06 <= 0.0003 at
        rtol 1e-09, 3.41 s``; :func:`.summary.brief_line`); :meth:`summary` has the full
        detail (``-v``)."""
        return brief_line(model, self.solver, bool(self.reason), self.steps,
                          self.state_events + self.time_events, self.estimated_error,
                          self.error_tolerance, self.rtol, self.wall_time)

    def summary(self, model: str) -> str:
        """One line with the full detail (``-v``): solver and engine (``auto -> dop853
        (compiled) (why)``), steps, evaluations, wall time, the error estimate, notes."""
        solver = f"{self.solver} ({self.engine})"
        why = f"{self.reason}; {self.engine_reason}" if self.engine_reason else self.reason
        if self.reason:
            solver = f"auto -> {solver} ({why})"
        elif self.engine_reason:  # the default engine fell back to scipy's loop
            solver = f"{solver} ({self.engine_reason})"
        inside = f"compiled loop {self.loop_time:.3f} s, " if self.loop_time else ""
        return (f"{printable(model)}: {solver}, {self.steps} steps, {self.rhs_evaluations} RHS "
                f"and {self.jacobian_evaluations} Jacobian evaluations, "
                f"{self.wall_time:.3f} s ({inside}model code {self.model_time:.3f} s; "
                f"{'cached' if self.cached else 'compiled'} in {self.compile_time:.3f} s)"
                + (f", {self.state_events} state and {self.time_events} time events"
                   if self.state_events or self.time_events else "")
                + (f"; {self.error}" if self.error else "")
                + (f"; note: {self.note}" if self.note else ""))


class Deferred(Protocol):
    """Outputs computed when read (``continuous.DeferredOutputs``)."""

    def values(self) -> np.ndarray:
        """Every output row."""

    def blocks(self) -> Iterator[np.ndarray]:
        """The output rows in order, a few at a time."""


@dataclass
class SimulationResult:
    """Outputs on the output grid: ``values[i, j]`` is ``names[j]`` at ``time[i]``."""

    model: str
    time: np.ndarray
    names: tuple[str, ...]
    values: np.ndarray
    units: tuple[str, ...]
    stats: SimulationStats
    parameters: dict[str, float] = field(default_factory=dict)
    # hybrid models: the events (simulation/events.py Event) and accepted step times
    events: tuple[Any, ...] = ()
    step_times: tuple[float, ...] = ()
    #: the estimated global error on the grid (``--error-control``; None: not estimated)
    error_estimate: ErrorEstimate | None = None
    #: the description strings of the model's variables and parameters, by flat name
    descriptions: dict[str, str] = field(default_factory=dict)
    #: the discrete variables (drawn as steps)
    discrete: tuple[str, ...] = ()
    #: the same run on another grid (``runner.Rerun``: a plot's finer grid); None: none
    rerun: Callable[[int], SimulationResult] | None = field(default=None, repr=False,
                                                            compare=False)
    #: error control's companion run (``RunSettings.deferred_outputs``): its outputs
    #: not yet computed (``continuous.DeferredOutputs``), ``values`` then has no columns
    deferred: Deferred | None = field(default=None, repr=False, compare=False)

    def __getitem__(self, name: str) -> np.ndarray:
        """The column of a flat name (``mass.pos[1]``: one value per time), or an array
        variable (``mass.pos``: ``(times, size)``, elements in index order)."""
        try:
            return self.values[:, self.names.index(name)]
        except ValueError:
            pass
        variables = array_variables(self.names, self.units)
        for variable in variables:
            if variable.name == name and variable.shape:
                return array_values(self.values, variable)
        candidates = [*self.names, *(v.name for v in variables if v.shape)]
        close = difflib.get_close_matches(str(name), candidates, 3)
        raise UnknownNameError(
            f"{name!r} matches no state or observed variable of this result",
            option="name", hint=(f"did you mean {', '.join(repr(c) for c in close)}?"
                                 if close else "the result holds " + ", ".join(
                                     repr(n) for n in self.names[:5])
                                 + (", ..." if len(self.names) > 5 else "")))

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def to_dict(self) -> dict[str, np.ndarray]:
        """``{"time": ..., name: column, ...}`` (e.g. for ``pandas.DataFrame``)."""
        out = {"time": self.time}
        out.update({n: self.values[:, i] for i, n in enumerate(self.names)})
        return out

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write the trajectory as CSV (whatever the suffix)."""
        with atomic_write(path, "w") as f:
            write_csv(self, f)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the trajectory as CSV or MAT, by the suffix of ``path``."""
        save_outputs(self, path, None)

    def plot(self, path: str | os.PathLike[str] | None = None) -> Any:
        """Plot the outputs: to a PNG, SVG or PDF file by the suffix of ``path``; without
        ``path``, return the matplotlib Figure (shown inline in Jupyter), nothing written."""
        if path is None:
            return draw_figure(self)
        save_outputs(self, None, path)
        return None

    def to_pandas(self) -> Any:
        """A ``pandas.DataFrame`` indexed by time, one column per output; units in
        ``attrs["units"]`` (name -> unit, ``""`` if none). Needs ``springc[analysis]``."""
        return to_pandas(self.time, self.names, self.values, self.units, self.model)

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset`` over ``time``; array elements (``mass.pos[1]``,
        ``mass.pos[2]``) form one variable (``mass.pos``) with a dimension
        ``mass.pos_index``; units as ``units`` attributes. Needs ``springc[analysis]``."""
        return to_xarray(self.time, self.names, self.values, self.units, self.model)

    def _summary_rows(self) -> list[tuple[str, str]]:
        stats = self.stats
        span = (f"{len(self.time)} times from {self.time[0]:g} to {self.time[-1]:g} s"
                if len(self.time) else "no times")
        return [("model", self.model), ("solver", f"{stats.solver} ({stats.engine})"),
                ("steps", str(stats.steps)), ("times", span)]

    def __repr__(self) -> str:
        variables = array_variables(self.names, self.units)
        shown = [v.name + (f"[{'x'.join(map(str, v.shape))}]" if v.shape else "")
                 for v in variables[:REPR_VARIABLES]]
        if len(variables) > REPR_VARIABLES:
            shown.append(f"... {len(variables) - REPR_VARIABLES} more")
        rows = dict(self._summary_rows())
        return (f"<SimulationResult {self.model}: {rows['solver']}, {rows['steps']} steps, "
                f"{rows['times']}, variables {', '.join(shown) or 'none'}>")

    def _repr_html_(self) -> str:
        return html_table(self._summary_rows(), array_variables(self.names, self.units))


def write_csv(result: SimulationResult, f: IO[str]) -> None:
    """Header ``time,<names>`` then one row per output time, full precision."""
    write_header(f, result.names)
    for begin in range(0, len(result.time), CSV_ROWS):  # no copy of every row at once
        end = begin + CSV_ROWS
        write_lines(f, np.column_stack([result.time[begin:end],
                                        result.values[begin:end]]).tolist())


CSV_ROWS = 64
"""Rows of a result turned into text at a time by :func:`write_csv`."""


def _char_matrix(texts: list[str]) -> np.ndarray:
    """Strings as the columns of a character matrix (the ``binTrans`` orientation)."""
    width = max(1, *map(len, texts))
    return np.ascontiguousarray(np.array([list(t.ljust(width)) for t in texts]).T)


def write_mat(result: SimulationResult, f: IO[bytes]) -> None:
    """The MATLAB v4 result file of OpenModelica and Dymola (``Aclass`` = Atrajectory,
    1.1, binTrans), as DyMat, OMPython and Dymola read it:

    - ``name``, ``description``: one column of characters per variable, ``time`` first;
      the description is the model's description string and the unit in brackets
      (``Position of the mass [m]``), as Dymola writes it;
    - ``dataInfo`` (4 x variables, int32): data block, 1-based row in that block
      (negative: negated), interpolation 0, extrapolation -1 (0 for parameters);
    - ``data_1``: the parameters, one row each (``time`` first), at start and stop;
    - ``data_2``: the trajectories, one row each (``time`` first), one column per time;
    - with an error estimate (which readers of the layout ignore): ``errorEstimate``
      (3 x states: largest absolute error, relative error, its time) and
      ``errorEstimateName`` (the states, one column of characters each).
    """
    from scipy.io import savemat

    params = sorted(result.parameters.items())
    names = ["time", *(n for n, _ in params), *result.names]
    units = dict(zip(result.names, result.units))
    # a description is prose: a character Latin-1 lacks becomes "?" (names and units
    # must be exact, and are refused below)
    texts = {n: t.encode("latin-1", "replace").decode("latin-1")
             for n, t in result.descriptions.items()}
    descriptions = ["Time in [s]", *(texts.get(n, "") for n, _ in params),
                    *(f"{texts.get(n, '')} [{units[n]}]".lstrip() if units.get(n)
                      else texts.get(n, "") for n in result.names)]
    info = [(0, 1, 0, -1)]
    info += [(1, i + 2, 0, 0) for i in range(len(params))]
    info += [(2, i + 2, 0, -1) for i in range(len(result.names))]
    span = [float(result.time[0]), float(result.time[-1])] if len(result.time) else [0, 0]
    data_1 = np.array([span, *([v, v] for _, v in params)], dtype=float)
    data_2 = np.vstack([result.time, np.asarray(result.values, dtype=float).T])
    try:
        matrices = {"Aclass": np.array(["Atrajectory", "1.1", "", "binTrans"]),
                    "name": _char_matrix(names),
                    "description": _char_matrix(descriptions)}
        for text in (*names, *descriptions):
            text.encode("latin-1")
    except UnicodeEncodeError:
        raise OutputError(f"{result.model}: a name or unit is not Latin-1 text, which the "
                          "MAT v4 format cannot store",
                          hint="write the trajectory as .csv (UTF-8) instead") from None
    matrices.update({"dataInfo": np.ascontiguousarray(np.array(info, dtype=np.int32).T),
                     "data_1": data_1, "data_2": np.ascontiguousarray(data_2)})
    estimate = result.error_estimate
    if estimate is not None and estimate.names:
        matrices["errorEstimate"] = np.array(
            [estimate.absolute, estimate.relative, estimate.times], dtype=float)
        matrices["errorEstimateName"] = _char_matrix(list(estimate.names))
    savemat(f, matrices, format="4")


def save_outputs(result: SimulationResult, output: PathLike | None, plot: PathLike | None,
                 protected: Iterable[PathLike] = (), error_output: PathLike | None = None
                 ) -> str:
    """Write the trajectory to ``output`` (CSV or MAT by suffix; a MAT file keeps the
    error estimate too), the plot to ``plot`` (PNG, SVG or PDF) and the error estimate's
    table to ``error_output`` (CSV; nothing without an estimate): only the files named,
    all rendered before any is put in place, and files in ``protected`` (the inputs)
    are never replaced. Returns the plot's note (which variables it shows, see
    :mod:`.plot_layout`; empty: all of them)."""
    kind = file_format(output, RESULT_FORMATS, "output") if output is not None else None
    plot_kind = file_format(plot, PLOT_FORMATS, "plot") if plot is not None else None
    picture, note = render_plot(result, plot_kind) if plot_kind is not None else (None, "")
    with OutputSet(protected) as outputs:
        if output is not None:
            with outputs.open(output, "w" if kind == "csv" else "wb") as f:
                if kind == "csv":
                    write_csv(result, f)
                else:
                    write_mat(result, f)
        if error_output is not None and result.error_estimate is not None:
            with outputs.open(error_output, "w") as f:
                csv.writer(f, lineterminator="\n").writerows(result.error_estimate.rows())
        if plot is not None and picture is not None:
            with outputs.open(plot, "wb") as f:
                f.write(picture)
    return note


# ------------------------------------------------------------------ plotting


def draw_figure(result: SimulationResult) -> Any:
    """The plot of the outputs as a matplotlib Figure: the panels that
    :func:`springc.simulation.plot_layout.choose_layout` picks (per quantity with a
    legend; per family with heat maps for a large result), its note under the title."""
    from .figure import draw_layout  # matplotlib loads with the first plot

    layout = choose_layout(result.names, result.units, result.values, result.discrete)
    drawn = _finer(result, layout)
    if drawn is not result:
        layout = replace(layout, note="; ".join(filter(None, (
            f"drawn on {len(drawn.time):,} times (the output grid has {len(result.time):,})",
            layout.note))))
    return draw_layout(result.model, drawn.time, drawn.values, layout, result.names)


def _finer(result: SimulationResult, layout: PlotLayout) -> SimulationResult:
    """``result``, or its run again on the finer grid its curves need
    (:func:`.plot_layout.plot_points`) and, with events, with rows at both sides of
    each event (a jump drawn upright); heat maps are drawn from the output grid, and a
    run that fails leaves it."""
    if result.rerun is None or any(p.kind == HEATMAP for p in layout.panels):
        return result
    smooth = [c for p in layout.panels for c in p.columns if c not in p.steps]
    points = plot_points(result.values, smooth)
    if not points and not result.events:
        return result
    points = max(points, len(result.time))  # events: their left and right limits too
    try:
        fine = result.rerun(points)
    except SpringcError:
        return result
    return fine if fine.names == result.names else result


def render_plot(result: SimulationResult, kind: str = "png") -> tuple[bytes, str]:
    """The plot of :func:`draw_figure` as the bytes of a ``kind`` (png, svg, pdf) file,
    and the note saying which variables it shows (empty: all of them)."""
    fig = draw_figure(result)
    buffer = io.BytesIO()
    # zlib level 1: a third of the save time of the default 6, for a slightly larger file
    if kind == "png":
        fig.savefig(buffer, format=kind, dpi=100, pil_kwargs={"compress_level": 1})
    else:
        fig.savefig(buffer, format=kind, dpi=100)
    return buffer.getvalue(), fig.layout.note
