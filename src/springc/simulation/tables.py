"""Result variables as tables for notebooks: array variables, pandas, xarray, HTML.

Flat names ending in a subscript (``mass.pos[1]``, ``mass.pos[2]``) are the elements
of an array variable (``mass.pos``); :func:`array_variables` groups them when the
elements fill a whole box of indices and share a unit, so that ``result["mass.pos"]``
and ``to_xarray`` see one array. pandas and xarray are optional (``springc[analysis]``)
and imported on first use.
"""

from __future__ import annotations

import html
import itertools
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

_SUBSCRIPT = re.compile(r"(?P<base>.+)\[(?P<index>\s*\d+\s*(?:,\s*\d+\s*)*)\]\Z", re.DOTALL)
ANALYSIS_HINT = "pip install springc[analysis]"
"""How to install pandas and xarray, named when either is missing."""
HTML_ROWS = 20
"""Variables listed by ``_repr_html_`` before ``... N more``."""


@dataclass(frozen=True)
class ArrayVariable:
    """An array variable of a result: its element columns in index order, shape and unit
    (a scalar variable has shape ``()`` and one column)."""

    name: str
    columns: tuple[int, ...]
    shape: tuple[int, ...]
    unit: str


def array_variables(names: Sequence[str], units: Sequence[str]) -> list[ArrayVariable]:
    """The variables of ``names`` in order of first appearance, array elements grouped;
    elements that do not fill ``1..n`` in every dimension, or differ in unit, stay
    scalars under their own names."""
    groups: dict[str, list[tuple[tuple[int, ...], int]]] = {}
    for column, name in enumerate(names):
        match = _SUBSCRIPT.match(name)
        if match is not None:
            index = tuple(int(part) for part in match["index"].split(","))
            groups.setdefault(match["base"], []).append((index, column))
    known = set(names)
    arrays: dict[int, ArrayVariable] = {}  # first column -> array
    grouped: set[int] = set()
    for base, elements in groups.items():
        shape = tuple(max(index[d] for index, _ in elements) for d in range(len(elements[0][0])))
        by_index = dict(elements)
        boxes = list(itertools.product(*(range(1, n + 1) for n in shape)))
        columns = [by_index.get(index) for index in boxes]
        if (base in known or any(len(index) != len(shape) for index, _ in elements)
                or len(by_index) != len(elements) or None in columns
                or len(columns) != len(elements)
                or len({units[c] for _, c in elements}) != 1):
            continue
        found = tuple(c for c in columns if c is not None)
        arrays[min(found)] = ArrayVariable(base, found, shape, units[found[0]])
        grouped.update(found)
    out = []
    for column, name in enumerate(names):
        if column in arrays:
            out.append(arrays[column])
        elif column not in grouped:
            out.append(ArrayVariable(name, (column,), (), units[column]))
    return out


def array_values(values: np.ndarray, variable: ArrayVariable) -> np.ndarray:
    """The columns of ``variable`` as an array of shape ``(times, *shape)``."""
    if not variable.shape:
        return values[:, variable.columns[0]]
    return values[:, list(variable.columns)].reshape(len(values), *variable.shape)


def _require(module: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(f"{module} is needed for this (an optional dependency of "
                          f"springc): {ANALYSIS_HINT}") from None


def to_pandas(time: np.ndarray, names: Sequence[str], values: np.ndarray,
              units: Sequence[str], model: str) -> Any:
    """A ``pandas.DataFrame`` indexed by ``time``, one column per name; the units as
    ``attrs["units"]`` (name -> unit, ``""`` if none) and the model as ``attrs["model"]``."""
    pd = _require("pandas")
    frame = pd.DataFrame(np.array(values, dtype=float), columns=list(names),
                         index=pd.Index(np.array(time, dtype=float), name="time"))
    frame.attrs["units"] = dict(zip(names, units))
    frame.attrs["model"] = model
    return frame


def to_xarray(time: np.ndarray, names: Sequence[str], values: np.ndarray,
              units: Sequence[str], model: str) -> Any:
    """An ``xarray.Dataset`` over ``time`` (attribute ``units`` ``s``): one variable per
    array variable, with a dimension ``<name>_index`` (``_index1``, ``_index2``, ... for
    more dimensions) whose coordinate is the 1-based Modelica index; ``units``
    attributes where a unit is declared."""
    xr = _require("xarray")
    coords: dict[str, Any] = {"time": ("time", np.array(time, dtype=float), {"units": "s"})}
    data: dict[str, Any] = {}
    for variable in array_variables(names, units):
        dims = [f"{variable.name}_index"] if len(variable.shape) == 1 else [
            f"{variable.name}_index{d + 1}" for d in range(len(variable.shape))]
        for dim, size in zip(dims, variable.shape):
            coords[dim] = (dim, np.arange(1, size + 1))
        attrs = {"units": variable.unit} if variable.unit else {}
        data[variable.name] = (("time", *dims), np.array(array_values(values, variable),
                                                         dtype=float), attrs)
    return xr.Dataset(data, coords=coords, attrs={"model": model})


def html_table(rows: Sequence[tuple[str, str]], variables: Sequence[ArrayVariable]) -> str:
    """A small HTML table of ``(label, value)`` rows and the variables (name, size,
    unit); every text is escaped."""
    cells = "".join(f"<tr><th style=\"text-align:left\">{html.escape(label)}</th>"
                    f"<td style=\"text-align:left\">{html.escape(value)}</td></tr>"
                    for label, value in rows)
    listed = "".join(
        f"<tr><td style=\"text-align:left\">{html.escape(v.name)}</td>"
        f"<td>{html.escape('x'.join(map(str, v.shape)))}</td>"
        f"<td style=\"text-align:left\">{html.escape(v.unit)}</td></tr>"
        for v in variables[:HTML_ROWS])
    more = len(variables) - HTML_ROWS
    if more > 0:
        listed += f"<tr><td colspan=\"3\">... {more} more</td></tr>"
    return (f"<table>{cells}<tr><th style=\"text-align:left\" colspan=\"2\">variables"
            f"</th></tr><tr><td colspan=\"2\"><table><tr><th>name</th><th>size</th>"
            f"<th>unit</th></tr>{listed}</table></td></tr></table>")
