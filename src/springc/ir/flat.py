"""The flat model: scalar variables, parameters and equations, produced by flattening.

Names are Modelica's flat names (``mass.pos[1]``). Every variable and equation keeps
the span it came from and the component instance it belongs to; every equation records
its origin (a component equation, a binding, a connection set, a flow sum).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import Span
from . import latex
from .expr import Expr, format_number, to_text
from .records import quick_init
from .when import When, format_when


@quick_init
@dataclass(frozen=True, slots=True)
class Origin:
    """Why an equation exists.

    ``kind`` is ``equation`` (written in a class), ``binding`` (``Real x = e``),
    ``connect`` (potentials equal in a connection set), ``flow`` (flows sum to zero),
    ``unconnected`` (a flow variable of an unconnected connector is zero) or
    ``initial`` (an ``initial equation``). ``component`` is the instance path
    (``""`` for the simulated model itself); ``detail`` says more, e.g. the set.
    """

    kind: str
    component: str
    detail: str = ""

    def describe(self) -> str:
        where = f" in {self.component}" if self.component else ""
        extra = f": {self.detail}" if self.detail else ""
        return f"{self.kind}{where}{extra}"


@quick_init
@dataclass(frozen=True, slots=True)
class Attributes:
    """The attributes of a scalar variable, as expressions of parameters or ``None``."""

    start: Expr | None = None
    fixed: bool | None = None
    nominal: Expr | None = None
    min: Expr | None = None
    max: Expr | None = None
    unit: str | None = None
    display_unit: str | None = None
    state_select: str | None = None


@quick_init
@dataclass(frozen=True, slots=True)
class Variable:
    """A scalar variable, parameter or constant of the flat model.

    ``variability`` is ``continuous``, ``discrete``, ``parameter`` or ``constant``;
    ``causality`` is ``""``, ``input`` or ``output``; ``type`` is ``Real``,
    ``Integer`` or ``Boolean``. ``binding`` is the declaration equation's right-hand
    side (always set for parameters with a value).
    """

    name: str
    type: str
    variability: str
    causality: str
    flow: bool
    binding: Expr | None
    attributes: Attributes
    description: str
    component: str
    span: Span

    @property
    def is_unknown(self) -> bool:
        return self.variability in ("continuous", "discrete")


@quick_init
@dataclass(frozen=True, slots=True)
class Equation:
    """``lhs = rhs`` between scalar expressions."""

    lhs: Expr
    rhs: Expr
    span: Span
    origin: Origin


@quick_init
@dataclass(frozen=True, slots=True)
class Assertion:
    """``assert(condition, message, level)`` (section 8.3.7): ``condition`` must hold
    whenever the model is evaluated; ``level`` is ``error`` or ``warning``."""

    condition: Expr
    message: str
    level: str
    span: Span
    origin: Origin


@quick_init
@dataclass(frozen=True, slots=True)
class Experiment:
    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    tolerance: float | None = None


@dataclass(frozen=True)
class FlatModel:
    name: str
    variables: tuple[Variable, ...]
    equations: tuple[Equation, ...]
    initial_equations: tuple[Equation, ...]
    experiment: Experiment
    span: Span
    notes: tuple[str, ...] = field(default=())
    whens: tuple[When, ...] = field(default=())  # when-clauses (ir/when.py)
    assertions: tuple[Assertion, ...] = field(default=())
    # parameters whose values the flattener computed with (a call evaluated for them,
    # flatten/calls/parameter_calls.py): structural, as with ``Evaluate = true``
    evaluated: tuple[str, ...] = field(default=())

    @property
    def unknowns(self) -> tuple[Variable, ...]:
        return tuple(v for v in self.variables if v.is_unknown)

    @property
    def parameters(self) -> tuple[Variable, ...]:
        return tuple(v for v in self.variables if v.variability == "parameter")

    def variable(self, name: str) -> Variable:
        for v in self.variables:
            if v.name == name:
                return v
        raise KeyError(name)

    def _repr_latex_(self) -> str | None:
        """The equations as LaTeX in a notebook (:func:`springc.ir.latex.notebook`)."""
        return latex.notebook(latex_rows(self))


# ------------------------------------------------------------------ printing

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


_Q_ESCAPES = {"\\": "\\\\", "'": "\\'", "\n": "\\n", "\r": "\\r", "\t": "\\t",
              "\a": "\\a", "\b": "\\b", "\f": "\\f", "\v": "\\v"}


def quote(name: str) -> str:
    """A flat name as a Modelica identifier: ``mass.pos[1]`` becomes ``'mass.pos[1]'``;
    ``\\``, ``'`` and control characters are escaped as Q-IDENT's S-ESCAPE says."""
    if _IDENT.match(name):
        return name
    return "'" + "".join(_Q_ESCAPES.get(c, c) for c in name) + "'"


def _expr(e: Expr) -> str:
    return to_text(e, quote)


def _string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def format_attributes(a: Attributes) -> str:
    """``(start = 1.0, fixed = true, unit = "m")`` or ``""`` when there is none."""
    parts = []
    for key, value in (("start", a.start), ("nominal", a.nominal), ("min", a.min),
                       ("max", a.max)):
        if value is not None:
            parts.append(f"{key} = {_expr(value)}")
    if a.fixed is not None:
        parts.append(f"fixed = {format_number(a.fixed)}")
    if a.unit is not None:
        parts.append(f"unit = {_string(a.unit)}")
    if a.display_unit is not None:
        parts.append(f"displayUnit = {_string(a.display_unit)}")
    if a.state_select is not None:
        parts.append(f"stateSelect = StateSelect.{a.state_select}")
    return f"({', '.join(parts)})" if parts else ""


def format_variable(v: Variable) -> str:
    prefix = "" if v.variability == "continuous" else v.variability + " "
    prefix += "flow " if v.flow else ""
    prefix += f"{v.causality} " if v.causality else ""
    text = f"{prefix}{v.type} {quote(v.name)}{format_attributes(v.attributes)}"
    if v.binding is not None:
        text += f" = {_expr(v.binding)}"
    if v.description:
        text += " " + _string(v.description)
    return text + ";"


def format_equation(eq: Equation, origins: bool = False) -> str:
    text = f"{_expr(eq.lhs)} = {_expr(eq.rhs)};"
    if origins:
        text += f"  // {eq.origin.describe()} ({eq.span})"
    return text


def format_assertion(a: Assertion, origins: bool = False) -> str:
    level = ", AssertionLevel.warning" if a.level == "warning" else ""
    text = f"assert({_expr(a.condition)}, {_string(a.message)}{level});"
    if origins:
        text += f"  // {a.origin.describe()} ({a.span})"
    return text


def format_flat(model: FlatModel, origins: bool = False) -> str:
    """The flat model as Modelica text that springc parses back to the same model."""
    lines = [f"model {quote(model.name)}"]
    lines += ["  " + format_variable(v) for v in model.variables]
    if model.initial_equations:
        lines.append("initial equation")
        lines += ["  " + format_equation(e, origins) for e in model.initial_equations]
    lines.append("equation")
    lines += ["  " + format_equation(e, origins) for e in model.equations]
    for w in model.whens:
        lines += format_when(w, quote)
    lines += ["  " + format_assertion(a, origins) for a in model.assertions]
    ex = model.experiment
    pairs = [(k, v) for k, v in (("StartTime", ex.start), ("StopTime", ex.stop),
                                 ("Interval", ex.interval), ("Tolerance", ex.tolerance))
             if v is not None]
    if pairs:
        args = ", ".join(f"{k} = {format_number(v)}" for k, v in pairs)
        lines.append(f"  annotation(experiment({args}));")
    lines.append(f"end {quote(model.name)};")
    return "\n".join(lines) + "\n"


def latex_rows(model: FlatModel) -> list[tuple[Expr, Expr, str]]:
    """``(lhs, rhs, note)`` of every equation, initial ones noted ``initial``."""
    return ([(e.lhs, e.rhs, "") for e in model.equations]
            + [(e.lhs, e.rhs, "initial") for e in model.initial_equations])


def format_flat_latex(model: FlatModel) -> str:
    """``springc flatten --latex``: the equations in a LaTeX ``align`` environment."""
    return latex.align(latex_rows(model))


# ---------------------------------------------------------------------- JSON


def _span_dict(span: Span) -> dict[str, object]:
    return {"file": span.file, "line": span.line, "column": span.column}


def _equation_dict(eq: Equation) -> dict[str, object]:
    return {"lhs": to_text(eq.lhs), "rhs": to_text(eq.rhs),
            "origin": {"kind": eq.origin.kind, "component": eq.origin.component,
                       "detail": eq.origin.detail},
            "location": _span_dict(eq.span)}


def to_json_dict(model: FlatModel) -> dict[str, object]:
    """The machine-readable form of ``springc flatten --json`` (docs/commands.md, "JSON output")."""
    def attrs(a: Attributes) -> dict[str, object]:
        out: dict[str, object] = {}
        for key in ("start", "nominal", "min", "max"):
            value = getattr(a, key)
            if value is not None:
                out[key] = to_text(value)
        for key, value in (("fixed", a.fixed), ("unit", a.unit),
                           ("displayUnit", a.display_unit), ("stateSelect", a.state_select)):
            if value is not None:
                out[key] = value
        return out

    ex = model.experiment
    return {
        "model": model.name,
        "variables": [
            {"name": v.name, "type": v.type, "variability": v.variability,
             "causality": v.causality, "flow": v.flow,
             "binding": to_text(v.binding) if v.binding is not None else None,
             "attributes": attrs(v.attributes), "description": v.description,
             "component": v.component, "location": _span_dict(v.span)}
            for v in model.variables],
        "equations": [_equation_dict(e) for e in model.equations],
        "initial_equations": [_equation_dict(e) for e in model.initial_equations],
        **({"whens": [format_when(w, str, "") for w in model.whens]} if model.whens else {}),
        "assertions": [{"condition": to_text(a.condition), "message": a.message,
                        "level": a.level, "location": _span_dict(a.span)}
                       for a in model.assertions],
        "experiment": {k: getattr(ex, k) for k in ("start", "stop", "interval", "tolerance")
                       if getattr(ex, k) is not None},
    }
