"""Simulation results: SimulationResult -> CSV text file, PNG plot, summary line.

The CSV has a header ``time`` then the flat names, one row per output time, every
number written with ``repr`` (the shortest text that reads back as the same float).
Files are written to a temporary file in the target folder and renamed only when
complete, so a failed run never leaves a CSV or PNG that looks complete.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import numpy as np

from ..fileio import atomic_write
from ..ir import dae


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

    def summary(self, model: str) -> str:
        """One line: solver (``auto -> radau (why)``), steps, evaluations, wall time."""
        solver = f"auto -> {self.solver} ({self.reason})" if self.reason else self.solver
        return (f"{model}: {solver}, {self.steps} steps, {self.rhs_evaluations} RHS "
                f"and {self.jacobian_evaluations} Jacobian evaluations, "
                f"{self.wall_time:.3f} s (model code {self.model_time:.3f} s; "
                f"{'cached' if self.cached else 'compiled'} in {self.compile_time:.3f} s)"
                + (f"; note: {self.note}" if self.note else ""))


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

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.values[:, self.names.index(name)]
        except ValueError:
            raise KeyError(name) from None

    def __contains__(self, name: object) -> bool:
        return name in self.names

    def to_dict(self) -> dict[str, np.ndarray]:
        """``{"time": ..., name: column, ...}`` (e.g. for ``pandas.DataFrame``)."""
        out = {"time": self.time}
        out.update({n: self.values[:, i] for i, n in enumerate(self.names)})
        return out

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        with atomic_write(Path(path), "w") as f:
            write_csv(self, f)

    def plot(self, path: str | os.PathLike[str]) -> None:
        write_png(self, Path(path))

    def __repr__(self) -> str:
        return (f"<SimulationResult {self.model}: {len(self.time)} times x "
                f"{len(self.names)} variables, {self.stats.solver}>")


def write_csv(result: SimulationResult, f: IO[str]) -> None:
    """Header ``time,<names>`` then one row per output time, full precision."""
    f.write(",".join(["time", *(_csv_field(n) for n in result.names)]) + "\n")
    table = np.column_stack([result.time, result.values]).tolist()
    f.writelines(",".join(map(repr, row)) + "\n" for row in table)


def _csv_field(name: str) -> str:
    return f'"{name}"' if any(c in name for c in ',"\n') else name


# ------------------------------------------------------------------ plotting

_QUANTITY = {"m": "position", "m/s": "velocity", "m/s2": "acceleration", "N": "force",
             "kg": "mass", "N/m": "stiffness", "rad": "angle", "rad/s": "angular velocity",
             "J": "energy", "W": "power", "N.s/m": "damping"}
_WORDS = {"pos": "position", "s": "position", "r": "position",
          "v": "velocity", "vel": "velocity", "w": "angular velocity", "a": "acceleration",
          "f": "force", "len": "length", "dir": "direction", "phi": "angle"}
MAX_PANELS = 8
MAX_LEGEND = 12


def _group(name: str, unit: str) -> tuple[str, str]:
    """(panel title, y label) of a variable: by unit if declared, else by its last name."""
    if unit:
        quantity = _QUANTITY.get(unit, unit)
        return quantity, f"{quantity} [{unit}]"
    while (base := dae.derivative_base(name)) is not None:
        name = base
    last = re.sub(r"\[.*?\]", "", name.rsplit(".", 1)[-1])
    word = _WORDS.get(last, last)
    return word, word


def write_png(result: SimulationResult, path: Path) -> None:
    """Plot the outputs, one panel per quantity (positions, velocities, forces, ...)."""
    # A Figure with the Agg canvas directly: no pyplot, so the user's matplotlib
    # backend (a notebook's, say) is left alone.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    groups: dict[str, tuple[str, list[int]]] = {}
    for i, (name, unit) in enumerate(zip(result.names, result.units)):
        title, label = _group(name, unit)
        groups.setdefault(title, (label, []))[1].append(i)
    panels = list(groups.items())[:MAX_PANELS]
    height = 1.2 + 2.3 * max(1, len(panels))
    fig = Figure(figsize=(10, height))
    # Fixed margins (in inches) instead of tight_layout, which costs a quarter second.
    fig.subplots_adjust(left=0.09, right=0.98, top=1 - 0.55 / height,
                        bottom=0.6 / height, hspace=0.35)
    FigureCanvasAgg(fig)
    axes = fig.subplots(max(1, len(panels)), 1, sharex=True, squeeze=False)
    for ax, (title, (label, columns)) in zip(axes[:, 0], panels):
        many = len(columns) > MAX_LEGEND
        for i in columns:
            ax.plot(result.time, result.values[:, i], label=result.names[i],
                    linewidth=0.6 if many else 1.2, alpha=0.6 if many else 1.0)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        shown = f"{title}: {len(columns)} variables" if many else title
        ax.set_title(shown, fontsize=10, loc="left", y=1.0)  # a fixed y: no bbox search
        if not many:
            ax.legend(fontsize=8, loc="upper right", ncol=min(3, len(columns)))
    if not panels:
        axes[0, 0].text(0.5, 0.5, "no variables selected", ha="center")
    omitted = len(groups) - len(panels)
    note = f" ({omitted} more groups not shown)" if omitted > 0 else ""
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(f"{result.model}{note}", fontsize=11)
    with atomic_write(path, "wb") as f:
        # zlib level 1: a third of the save time of the default 6, for a slightly larger file
        fig.savefig(f, format="png", dpi=100, pil_kwargs={"compress_level": 1})
