"""The DAE: residual equations over unknowns and their derivatives.

Produced by :mod:`springc.simplify.lower` from the flat model. Derivatives are ordinary
variables named ``der(x)`` (and ``der(der(x))`` after index reduction), so every
structural algorithm sees one kind of unknown. :func:`derivative_name` and
:func:`derivative_base` are the one way to build and read such names.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import Span
from . import flat
from .expr import Expr, to_text
from .records import quick_init

DERIVATIVE_PREFIX = "der("


def derivative_name(name: str) -> str:
    """The name of the derivative variable of ``name``: ``der(x)``."""
    return f"{DERIVATIVE_PREFIX}{name})"


def derivative_base(name: str) -> str | None:
    """``x`` for the derivative variable ``der(x)`` (``der(x)`` for ``der(der(x))``);
    None when ``name`` is not a derivative variable."""
    if name.startswith(DERIVATIVE_PREFIX) and name.endswith(")"):
        return name[len(DERIVATIVE_PREFIX):-1]
    return None


def is_derivative(name: str) -> bool:
    """Is ``name`` a derivative variable (``der(x)``)? (:func:`derivative_base`'s test,
    without its slice: asked of every name of every equation.)"""
    return name.startswith(DERIVATIVE_PREFIX) and name.endswith(")")


@quick_init
@dataclass(frozen=True, slots=True)
class Unknown:
    """A continuous unknown of the DAE (never a derivative variable)."""

    name: str
    start: Expr | None
    fixed: bool
    nominal: Expr | None
    state_select: str
    unit: str | None
    component: str
    span: Span


@quick_init
@dataclass(frozen=True, slots=True)
class Parameter:
    name: str
    binding: Expr | None
    start: Expr | None
    span: Span


@quick_init
@dataclass(frozen=True, slots=True)
class Residual:
    """``expr = 0``, with the flat equation it came from."""

    expr: Expr
    span: Span
    origin: flat.Origin
    source: flat.Equation | None = None
    # The names in ``expr`` (derivative variables included), computed once.
    variables: frozenset[str] = frozenset()
    # Those of ``variables`` that ``expr`` reads only through ``pre``: the value held
    # from before the event, no unknown of this equation (the structure leaves them
    # out; a subset is safe: an extra name only adds an edge).
    pre_only: frozenset[str] = frozenset()

    @property
    def incident(self) -> frozenset[str]:
        """The names the equation's structure counts: ``variables`` less ``pre_only``."""
        return self.variables - self.pre_only if self.pre_only else self.variables

    def describe(self) -> str:
        """The equation as the user wrote it (flattened): ``lhs = rhs``."""
        if self.source is not None:
            return f"{to_text(self.source.lhs)} = {to_text(self.source.rhs)}"
        return f"{to_text(self.expr)} = 0"


@dataclass(frozen=True)
class DAE:
    name: str
    unknowns: tuple[Unknown, ...]
    parameters: tuple[Parameter, ...]
    equations: tuple[Residual, ...]
    initial_equations: tuple[Residual, ...]
    experiment: flat.Experiment
    span: Span
    # Names of unknowns whose derivative appears in the equations.
    differentiated: frozenset[str] = frozenset()

    def unknown(self, name: str) -> Unknown:
        for u in self.unknowns:
            if u.name == name:
                return u
        raise KeyError(name)


def format_dae(dae: DAE) -> str:
    """A readable listing of the DAE: unknowns, parameters and residuals."""
    lines = [f"DAE {dae.name}: {len(dae.unknowns)} unknowns, {len(dae.equations)} equations"]
    lines += [f"  unknown {u.name}" for u in dae.unknowns]
    lines += [f"  parameter {p.name}" + (f" = {to_text(p.binding)}" if p.binding else "")
              for p in dae.parameters]
    lines += [f"  0 = {to_text(r.expr)}" for r in dae.equations]
    return "\n".join(lines) + "\n"
