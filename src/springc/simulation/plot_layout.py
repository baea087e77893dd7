"""Which plot a result gets: names, units and values -> PlotLayout (no matplotlib here).

Two layouts, chosen from the variables that are not copies of another:

- **Quantities** (small results): one panel per quantity (positions, velocities,
  forces...: by unit, else by the variable's last name), one line per variable with a
  legend, at most :data:`MAX_PANELS` panels. Chosen when no quantity has more than
  :data:`MAX_LEGEND` variables.
- **Families** (large results, e.g. a cloth of hundreds of masses): variables that
  differ only in their subscripts form a family (``p[1,1].pos[2]``, ``p[1,2].pos[2]``...
  -> ``p[:].pos[2]``; a last subscript of at most :data:`COMPONENTS` values, a vector's
  components, stays apart). The first :data:`LARGE_PANELS` families in model order
  (states come first) get a panel each: lines with a legend for a family of at most
  :data:`MAX_LEGEND` variables, else a heat map of every member over time with a
  colour bar. The others are named in the note.

**Copies.** A column equal to an earlier one, or to its negative, at every output time
(alias variables: ``flange.pos = pos``, ``b.f = -a.f``) is drawn once: its name is
added to the original's legend label (quantities layout) or counted in the note.
Copies are found by a weighted sum per column (accumulated row by row, so that equal
columns get bitwise equal sums, which a BLAS product does not promise) and then
confirmed exactly, so a result of 100,000 variables costs a fraction of a second.

**Steps and samples.** Discrete variables (Integer, Boolean, when-assigned) are drawn
as steps (``Panel.steps``). A grid that under-samples the motion (fewer than
:data:`SAMPLES_PER_PERIOD` rows per period of the fastest drawn curve, periods counted
from its local extrema) asks for a finer one (:func:`plot_points`): the figure is then
drawn from a run on that grid (:mod:`.figure`), the result's own grid unchanged.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np

from ..ir import dae

MAX_PANELS = 8
"""Panels of the quantities layout (further quantities are counted in the note)."""
MAX_LEGEND = 12
"""The most lines a panel draws with a legend; a larger group makes the result large."""
LARGE_PANELS = 4
"""Panels of the families layout."""
COMPONENTS = 3
"""A last subscript of at most this many values is a vector's component (x, y, z)."""
LINES, HEATMAP = "lines", "heatmap"
CHUNK = 512
"""Candidate copies compared at a time (bounds the memory of the comparison: 2 MB per
array for the 50x50 cloth's 501 rows)."""
MAX_ALIASES = 2
"""Copies named in a legend entry before ``(+N more)``."""
SAMPLES_PER_PERIOD = 16
"""Rows per period of the fastest curve below which the grid under-samples a plot."""
MAX_PLOT_POINTS = 8000
"""The most rows a plot asks for (8 per pixel of a 10-inch figure at 100 dpi)."""

_QUANTITY = {"m": "position", "m/s": "velocity", "m/s2": "acceleration", "N": "force",
             "kg": "mass", "N/m": "stiffness", "rad": "angle", "rad/s": "angular velocity",
             "J": "energy", "W": "power", "N.s/m": "damping"}
_WORDS = {"pos": "position", "s": "position", "r": "position",
          "v": "velocity", "vel": "velocity", "w": "angular velocity", "a": "acceleration",
          "f": "force", "len": "length", "dir": "direction", "phi": "angle"}
_SUBSCRIPT = re.compile(r"\[[^\[\]]*\]")
_LAST_SUBSCRIPT = re.compile(r"\[([^\[\]]*)\]\Z")


@dataclass(frozen=True)
class Panel:
    """One panel: ``kind`` lines (one per column, ``labels`` in the legend; the columns
    in ``steps`` drawn as steps) or heatmap (the columns as rows of an image, the first
    at the top, as a cloth's first row hangs at the top); ``label`` names the y axis
    (lines) or the colour bar (heat map)."""

    kind: str
    title: str
    label: str
    columns: tuple[int, ...]
    labels: tuple[str, ...] = ()
    steps: tuple[int, ...] = ()


@dataclass(frozen=True)
class PlotLayout:
    """The panels, the copies left out (``copy column -> (original column, sign)``) and
    a note saying what was chosen (empty when every variable is drawn with a legend)."""

    panels: tuple[Panel, ...]
    copies: dict[int, tuple[int, int]]
    note: str


def quantity(name: str, unit: str) -> tuple[str, str]:
    """(panel title, y label) of a variable: by unit if declared, else by its last name."""
    if unit:
        word = _QUANTITY.get(unit, unit)
        return word, f"{word} [{unit}]"
    while (base := dae.derivative_base(name)) is not None:
        name = base
    last = re.sub(r"\[.*?\]", "", name.rsplit(".", 1)[-1])
    word = _WORDS.get(last, last)
    return word, word


def copies_of(values: np.ndarray) -> dict[int, tuple[int, int]]:
    """Columns equal to an earlier column (sign 1) or to its negative (sign -1) at every
    row: ``column -> (first such column, sign)``. Candidates share a weighted sum with
    the earlier column (or its negation); they are then compared exactly, many columns
    at a time."""
    if values.ndim != 2 or values.shape[1] < 2 or values.shape[0] == 0:
        return {}
    weights = np.sqrt(np.arange(2.0, values.shape[0] + 2.0))
    sums = np.zeros(values.shape[1])
    with np.errstate(all="ignore"):
        for weight, row in zip(weights, values):  # the same operations for every column
            sums += weight * row
        keys = (sums + 0.0).tolist()  # one weighted sum per column; -0.0 -> 0.0
    first: dict[float, int] = {}
    candidates: list[tuple[int, int, int]] = []
    for column, key in enumerate(keys):
        if key != key:  # NaN: never a copy
            continue
        original = first.get(key)
        if original is not None:
            candidates.append((column, original, 1))
            continue
        original = first.get(-key + 0.0)
        if original is not None:
            candidates.append((column, original, -1))
            continue
        first[key] = column
    out: dict[int, tuple[int, int]] = {}
    for begin in range(0, len(candidates), CHUNK):
        part = np.array(candidates[begin:begin + CHUNK], dtype=np.int64)
        same = np.all(values[:, part[:, 0]] == values[:, part[:, 1]] * part[:, 2], axis=0)
        out.update((int(c), (int(o), int(g))) for (c, o, g), ok in zip(part, same) if ok)
    return out


def families(names: Sequence[str], units: Sequence[str], columns: Sequence[int]
             ) -> list[tuple[str, list[int]]]:
    """``columns`` grouped by family name (subscripts replaced by ``[:]``; see the module
    text) and unit, in order of first appearance."""
    groups: dict[tuple[str, str], list[int]] = {}
    for column in columns:
        groups.setdefault((_SUBSCRIPT.sub("[:]", names[column]), units[column]),
                          []).append(column)
    out: list[tuple[str, list[int]]] = []
    for (family, _), members in groups.items():
        lasts = [_LAST_SUBSCRIPT.search(names[c]) for c in members]
        values = {m[1] for m in lasts if m is not None}
        if None in lasts or not 1 < len(values) <= COMPONENTS or len(members) == len(values):
            out.append((family, members))
            continue
        parts: dict[str, list[int]] = {}
        for column, match in zip(members, lasts):
            assert match is not None
            parts.setdefault(match[1], []).append(column)
        out.extend((f"{family[:-3]}[{last}]", part) for last, part in parts.items())
    order = {column: i for i, column in enumerate(columns)}
    return sorted(out, key=lambda item: order[item[1][0]])


def plot_points(values: np.ndarray, columns: Sequence[int]) -> int:
    """The rows a plot of ``columns`` needs: 0 where the grid holds at least
    :data:`SAMPLES_PER_PERIOD` rows per period of each (a period: two local extrema),
    else that many for the fastest one seen, at least twice the rows (a grid that
    aliases shows fewer periods than there are), at most :data:`MAX_PLOT_POINTS`."""
    rows = int(values.shape[0])
    if rows < 3 or not len(columns):
        return 0
    with np.errstate(all="ignore"):
        slopes = np.sign(np.diff(values[:, list(columns)], axis=0))
    turns = 0
    for column in slopes.T:
        moving = column[np.isfinite(column) & (column != 0)]
        turns = max(turns, int(np.count_nonzero(moving[1:] != moving[:-1])))
    wanted = SAMPLES_PER_PERIOD * turns // 2
    if rows >= wanted or rows >= MAX_PLOT_POINTS:
        return 0
    return min(MAX_PLOT_POINTS, max(wanted, 2 * rows))


def choose_layout(names: Sequence[str], units: Sequence[str], values: np.ndarray,
                  discrete: Collection[str] = ()) -> PlotLayout:
    """The plot of a result (see the module text); the variables named in ``discrete``
    are drawn as steps."""
    copies = copies_of(values)
    drawn = [c for c in range(len(names)) if c not in copies]
    groups: dict[str, tuple[str, list[int]]] = {}
    for column in drawn:
        title, label = quantity(names[column], units[column])
        groups.setdefault(title, (label, []))[1].append(column)
    if all(len(columns) <= MAX_LEGEND for _, columns in groups.values()):
        return _quantities(names, groups, copies, set(discrete))
    return _families(names, units, drawn, copies, set(discrete))


def _copy_text(names: Sequence[str], copy: int, sign: int) -> str:
    return f"{'-' if sign < 0 else ''}{names[copy]}"


def _quantities(names: Sequence[str], groups: dict[str, tuple[str, list[int]]],
                copies: dict[int, tuple[int, int]], discrete: set[str]) -> PlotLayout:
    same: dict[int, list[str]] = {}
    for copy, (original, sign) in copies.items():
        same.setdefault(original, []).append(_copy_text(names, copy, sign))
    panels = []
    for title, (label, columns) in list(groups.items())[:MAX_PANELS]:
        labels = tuple(_label(names[c], same.get(c, [])) for c in columns)
        steps = tuple(c for c in columns if names[c] in discrete)
        panels.append(Panel(LINES, title, label, tuple(columns), labels, steps))
    notes = []
    if len(groups) > MAX_PANELS:
        notes.append(f"{len(groups) - MAX_PANELS} more quantities not shown")
    if copies:
        notes.append(f"{_count(len(copies), 'copy', 'copies')} (equal to another variable "
                     "or its negative) drawn once")
    return PlotLayout(tuple(panels), copies, "; ".join(notes))


def _label(name: str, copies: list[str]) -> str:
    """A legend entry: the name and its copies (``x = -y``), at most
    :data:`MAX_ALIASES` of them named."""
    more = len(copies) - MAX_ALIASES
    text = " = ".join([name, *copies[:MAX_ALIASES]])
    return text + (f" (+{more} more)" if more > 0 else "")


def _count(n: int, one: str, many: str) -> str:
    return f"{n:,} {one if n == 1 else many}"


def _families(names: Sequence[str], units: Sequence[str], drawn: list[int],
              copies: dict[int, tuple[int, int]], discrete: set[str]) -> PlotLayout:
    found = families(names, units, drawn)
    panels, shown = [], []
    for family, members in found[:LARGE_PANELS]:
        word, label = quantity(names[members[0]], units[members[0]])
        if len(members) <= MAX_LEGEND:
            panels.append(Panel(LINES, f"{family} ({word})", label, tuple(members),
                                tuple(names[c] for c in members),
                                tuple(c for c in members if names[c] in discrete)))
        else:
            title = (f"{family}: {len(members):,} variables, {names[members[0]]} (top) "
                     f"to {names[members[-1]]} (bottom)")
            panels.append(Panel(HEATMAP, title, label, tuple(members)))
        shown.append(f"{family} ({'heat map' if panels[-1].kind == HEATMAP else 'lines'})")
    rest = found[LARGE_PANELS:]
    note = (f"{_count(len(names), 'variable', 'variables')} in "
            f"{_count(len(found), 'family', 'families')}; drawn: {', '.join(shown)}")
    if rest:
        hidden = sum(len(m) for _, m in rest)
        note += (f"; not drawn: {_count(len(rest), 'family', 'families')} "
                 f"({_count(hidden, 'variable', 'variables')}), select them with --vars")
    if copies:
        note += f"; {_count(len(copies), 'copy', 'copies')} of another variable left out"
    return PlotLayout(tuple(panels), copies, note)
