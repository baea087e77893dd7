"""When-clauses of the flat model (Modelica 3.6, 8.3.5 and 8.3.6).

A ``when`` equation flattens to a :class:`When`: its branches in order (``when``,
then each ``elsewhen``), each with the scalar elements of its condition (a vector
condition fires when any element becomes true), the equations it activates (always
``variable = expression``: a when-equation is solved for its left-hand side), its
``reinit``s and its ``terminate``s. Variables assigned in a when-clause are
discrete: they keep their value between the events that activate it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import Span
from .expr import Expr, to_text


@dataclass(frozen=True, slots=True)
class Assignment:
    """``name = value`` inside a when-clause."""

    name: str
    value: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Reinit:
    """``reinit(name, value)``: the state ``name`` restarts at ``value``."""

    name: str
    value: Expr
    span: Span


@dataclass(frozen=True, slots=True)
class Terminate:
    """``terminate(message)``: the simulation ends successfully at this event."""

    message: str
    span: Span


@dataclass(frozen=True, slots=True)
class WhenBranch:
    conditions: tuple[Expr, ...]
    assignments: tuple[Assignment, ...]
    reinits: tuple[Reinit, ...]
    terminates: tuple[Terminate, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class When:
    branches: tuple[WhenBranch, ...]
    span: Span
    component: str = ""


def assigned(whens: tuple[When, ...]) -> list[str]:
    """Names assigned in any branch of ``whens``, first assignment first."""
    out: dict[str, None] = {}
    for w in whens:
        for b in w.branches:
            for a in b.assignments:
                out.setdefault(a.name, None)
    return list(out)


def format_when(w: When, name: Callable[[str], str], indent: str = "  ") -> list[str]:
    """Modelica text of ``w`` (springc parses it back to the same clause)."""
    lines = []
    for i, b in enumerate(w.branches):
        conds = [to_text(c, name) for c in b.conditions]
        cond = conds[0] if len(conds) == 1 else "{" + ", ".join(conds) + "}"
        lines.append(f"{indent}{'when' if i == 0 else 'elsewhen'} {cond} then")
        lines += [f"{indent}  {name(a.name)} = {to_text(a.value, name)};"
                  for a in b.assignments]
        lines += [f"{indent}  reinit({name(r.name)}, {to_text(r.value, name)});"
                  for r in b.reinits]
        lines += [f"{indent}  terminate({_string(t.message)});" for t in b.terminates]
    lines.append(f"{indent}end when;")
    return lines


def _string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'
