"""Balance check of a flat model: flat.FlatModel -> Balance, or a BalanceError.

Counts scalar unknowns and equations and matches them (``der(x)`` counts as ``x``,
as before index reduction). When the counts differ or no complete matching exists,
the Dulmage-Mendelsohn decomposition names exactly the variables left undetermined
and the equations that over-determine others, each with its location and instance.

``springc check`` runs it on the flat model; :func:`springc.simplify.simplify` runs it
first too (on the incidence that lowering computed anyway, :func:`dae_incidence`), so
that ``simulate``, ``compile`` and the Python API report the same errors.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import BalanceError, Note
from ..ir import dae, flat
from ..ir import expr as x
from ..structure import dulmage_mendelsohn, maximum_matching, perfectly_matchable
from .events import continuous_part

MAX_NOTES = 20


@dataclass(frozen=True)
class Balance:
    model: str
    unknowns: int
    equations: int
    parameters: int
    parameter_arrays: int
    discrete: int = 0  # of the unknowns: discrete ones (Integer, Boolean, when-assigned)
    when_equations: int = 0  # of the equations: the when-equations (one per variable)

    def summary(self) -> str:
        arrays = (f", {self.parameter_arrays} parameter array"
                  f"{'s' if self.parameter_arrays != 1 else ''}") if self.parameter_arrays else ""
        # a quoted name with a line break or other control character is shown escaped
        name = self.model if self.model.isprintable() else flat.quote(self.model)
        discrete = f" ({self.discrete} discrete)" if self.discrete else ""
        whens = f" ({self.when_equations} in when-clauses)" if self.when_equations else ""
        return (f"{name}: {_count(self.unknowns, 'unknown')}{discrete}, "
                f"{_count(self.equations, 'equation')}{whens}, "
                f"{_count(self.parameters, 'parameter')}{arrays}: balanced")


def incidence(model: flat.FlatModel) -> list[list[int]]:
    """For each equation, the indices (into ``model.unknowns``) of the unknowns it uses."""
    index = {v.name: i for i, v in enumerate(model.unknowns)}
    rows = []
    for eq in model.equations:
        names = x.variables(eq.lhs) | x.variables(eq.rhs)
        rows.append(sorted(index[n] for n in names if n in index))
    return rows


def dae_incidence(system: dae.DAE) -> list[list[int]]:
    """:func:`incidence` from the lowered equations (the same rows: ``der(x)`` counts
    as ``x``), which carry their variable names already."""
    index = {u.name: i for i, u in enumerate(system.unknowns)}
    index.update({dae.derivative_name(u.name): i for i, u in enumerate(system.unknowns)})
    return [sorted({index[n] for n in r.variables if n in index}) for r in system.equations]


def count_parameters(model: flat.FlatModel) -> tuple[int, int]:
    """Scalar parameters declared as scalars, and parameter arrays (counted once each)."""
    scalars, arrays = 0, set()
    for v in model.parameters:
        if v.name.endswith("]"):
            arrays.add(v.name[: v.name.rindex("[")])
        else:
            scalars += 1
    return scalars, len(arrays)


def check_balance(model: flat.FlatModel, rows: Sequence[Sequence[int]] | None = None
                  ) -> Balance:
    """The counts of a balanced ``model``; otherwise a :class:`BalanceError` naming the
    undetermined variables and the surplus equations. ``rows``: the model's
    :func:`incidence`, when already known. Variables assigned in when-clauses are
    matched with their when-equations, and only counted with them (as discrete
    unknowns and when-equations) in the :class:`Balance`."""
    full = model
    model = continuous_part(model)
    unknowns = model.unknowns
    rows = [list(r) for r in rows] if rows is not None else incidence(model)
    n_eq, n_var = len(model.equations), len(unknowns)
    if n_eq == n_var and perfectly_matchable(rows, n_var):
        held = len(full.unknowns) - n_var
        discrete = sum(1 for v in full.unknowns if v.variability == "discrete")
        return Balance(model.name, n_var + held, n_eq + held, *count_parameters(model),
                       discrete=max(discrete, held), when_equations=held)
    parts = dulmage_mendelsohn(rows, n_var, maximum_matching(rows, n_var))
    notes: list[Note] = []
    for eqs, var_ids in _blocks(rows, parts.under_equations, parts.under_variables):
        names = _names(unknowns, var_ids)
        for i in var_ids:
            v = unknowns[i]
            where = f" (in {v.component})" if v.component else ""
            text = (f"'{v.name}'{where} appears in no equation" if not eqs else
                    f"'{v.name}'{where} is left undetermined: {_count(len(eqs), 'equation')}"
                    f" for the {_count(len(var_ids), 'unknown')} {names}")
            notes.append(Note(text, v.span))
    for eqs, var_ids in _blocks(rows, parts.over_equations, parts.over_variables):
        names = _names(unknowns, var_ids)
        for i in eqs:
            eq = model.equations[i]
            where = f" in {eq.origin.component}" if eq.origin.component else ""
            text = f"{x.to_text(eq.lhs)} = {x.to_text(eq.rhs)}"
            kind = _KINDS.get(eq.origin.kind, eq.origin.kind)
            notes.append(Note(f"{kind}{where} `{text}` " + (
                f"is one of {len(eqs)} equations for only "
                f"{_count(len(var_ids), 'unknown')} {names}" if var_ids else
                "involves no unknown"), eq.span))
    if len(notes) > MAX_NOTES:
        notes = [*notes[:MAX_NOTES], Note(f"... and {len(notes) - MAX_NOTES} more")]
    raise BalanceError(_headline(model.name, n_var, n_eq, parts), model.span, notes,
                       _hint(parts))


def _blocks(rows: list[list[int]], eqs: tuple[int, ...], var_ids: tuple[int, ...]
            ) -> list[tuple[list[int], list[int]]]:
    """Split a part of the Dulmage-Mendelsohn decomposition into its connected pieces
    (equations, variables), so that each note counts only what is related to it."""
    parent: dict[tuple[str, int], tuple[str, int]] = {}

    def find(k: tuple[str, int]) -> tuple[str, int]:
        while parent.setdefault(k, k) != k:
            k = parent[k]
        return k

    in_part = set(var_ids)
    for i in eqs:
        for j in rows[i]:
            if j in in_part:
                parent[find(("e", i))] = find(("v", j))
    pieces: dict[tuple[str, int], tuple[list[int], list[int]]] = {}
    for i in eqs:
        pieces.setdefault(find(("e", i)), ([], []))[0].append(i)
    for j in var_ids:
        pieces.setdefault(find(("v", j)), ([], []))[1].append(j)
    return sorted(pieces.values(), key=lambda p: (min(p[1], default=-1), min(p[0], default=-1)))


_KINDS = {"binding": "binding equation", "connect": "connection equation",
          "flow": "flow-sum equation", "unconnected": "unconnected-flow equation",
          "initial": "initial equation"}


def _count(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def _names(unknowns: tuple[flat.Variable, ...], indices: list[int]) -> str:
    """``'x', 'y'`` (the first six, then ``...``)."""
    names = ", ".join(f"'{unknowns[i].name}'" for i in indices[:6])
    return names + (", ..." if len(indices) > 6 else "")


def _headline(name: str, n_var: int, n_eq: int, parts: object) -> str:
    counts = f"{_count(n_var, 'unknown')}, {_count(n_eq, 'equation')}"
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
        advice.append("remove the redundant equations (as many as there are surplus "
                      "equations), or turn a parameter they constrain into an unknown")
    return "; ".join(advice)
