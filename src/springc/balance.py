"""Balance check of a flat model: flat.FlatModel -> Balance, or a BalanceError.

Counts scalar unknowns and equations and matches them (``der(x)`` counts as ``x``,
as before index reduction). When the counts differ or no complete matching exists,
the Dulmage-Mendelsohn decomposition names exactly the variables left undetermined
and the equations that over-determine others, each with its location and instance.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import expr as x
from . import flat
from .errors import BalanceError, Note
from .structure import dulmage_mendelsohn, maximum_matching

MAX_NOTES = 20


@dataclass(frozen=True)
class Balance:
    model: str
    unknowns: int
    equations: int
    parameters: int
    parameter_arrays: int

    def summary(self) -> str:
        arrays = (f", {self.parameter_arrays} parameter array"
                  f"{'s' if self.parameter_arrays != 1 else ''}") if self.parameter_arrays else ""
        return (f"{self.model}: {self.unknowns} unknowns, {self.equations} equations, "
                f"{self.parameters} parameters{arrays}: balanced")


def incidence(model: flat.FlatModel) -> list[list[int]]:
    """For each equation, the indices (into ``model.unknowns``) of the unknowns it uses."""
    index = {v.name: i for i, v in enumerate(model.unknowns)}
    rows = []
    for eq in model.equations:
        names = x.variables(eq.lhs) | x.variables(eq.rhs)
        rows.append(sorted(index[n] for n in names if n in index))
    return rows


def count_parameters(model: flat.FlatModel) -> tuple[int, int]:
    """Scalar parameters declared as scalars, and parameter arrays (counted once each)."""
    scalars, arrays = 0, set()
    for v in model.parameters:
        if v.name.endswith("]"):
            arrays.add(v.name[: v.name.rindex("[")])
        else:
            scalars += 1
    return scalars, len(arrays)


def check_balance(model: flat.FlatModel) -> Balance:
    unknowns = model.unknowns
    rows = incidence(model)
    matching = maximum_matching(rows, len(unknowns))
    n_eq, n_var = len(model.equations), len(unknowns)
    if n_eq == n_var and matching.is_perfect:
        return Balance(model.name, n_var, n_eq, *count_parameters(model))
    parts = dulmage_mendelsohn(rows, n_var, matching)
    notes: list[Note] = []
    for i in parts.under_variables:
        v = unknowns[i]
        where = f" (in {v.component})" if v.component else ""
        notes.append(Note(f"'{v.name}'{where} is not determined by any equation", v.span))
    over_names = ", ".join(f"'{unknowns[i].name}'" for i in parts.over_variables[:6])
    for i in parts.over_equations:
        eq = model.equations[i]
        where = f" in {eq.origin.component}" if eq.origin.component else ""
        text = f"{x.to_text(eq.lhs)} = {x.to_text(eq.rhs)}"
        notes.append(Note(f"equation{where} over-determines {over_names or 'nothing'}: {text}"
                          f" ({eq.origin.kind})", eq.span))
    if len(notes) > MAX_NOTES:
        notes = [*notes[:MAX_NOTES], Note(f"... and {len(notes) - MAX_NOTES} more")]
    raise BalanceError(_headline(model.name, n_var, n_eq, parts), model.span, notes,
                       _hint(parts))


def _headline(name: str, n_var: int, n_eq: int, parts: object) -> str:
    counts = f"{n_var} unknowns, {n_eq} equations"
    if n_var > n_eq:
        return f"model '{name}' is under-determined: {counts}"
    if n_eq > n_var:
        return f"model '{name}' is over-determined: {counts}"
    return f"model '{name}' is structurally singular: {counts}, but they do not match"


def _hint(parts: object) -> str:
    under = getattr(parts, "under_variables", ())
    over = getattr(parts, "over_equations", ())
    advice = []
    if under:
        advice.append("add an equation for each undetermined variable, or give it a "
                      "binding (`Real x = ...`) or make it a parameter")
    if over:
        advice.append("remove the redundant equations, or declare one of the "
                      "over-determined quantities as a variable they can determine")
    return "; ".join(advice)
