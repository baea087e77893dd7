"""The simplified system: states, the steps that compute their derivatives, observed.

Produced by :mod:`springc.simplify`. ``steps`` run in order and compute every
algebraic variable and every state derivative (named ``der(x)``) from the states,
the parameters and ``time``: explicit assignments, linear systems, and torn nonlinear
systems solved by Newton's method with an analytic Jacobian.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import Span
from . import dae, flat, latex
from .expr import ZERO, Expr, Var, add, mul, to_text
from .hybrid import EventSystem
from .records import quick_init


@quick_init
@dataclass(frozen=True, slots=True)
class Assign:
    """``name := expr``, solved from the equation at ``span``."""

    name: str
    expr: Expr
    span: Span


@quick_init
@dataclass(frozen=True, slots=True)
class LinearBlock:
    """Solve ``matrix @ names = rhs``; ``matrix`` entries ``(row, col, expr)``, sparse."""

    names: tuple[str, ...]
    matrix: tuple[tuple[int, int, Expr], ...]
    rhs: tuple[Expr, ...]
    spans: tuple[Span, ...]


@quick_init
@dataclass(frozen=True, slots=True)
class NonlinearBlock:
    """Newton iteration on ``tearing`` variables: ``inner`` computes the other block
    variables from them, then ``residuals`` must vanish. ``sensitivities`` compute
    ``d(inner)/d(tearing)`` (names ``d(a)/d(t)``) and ``jacobian`` holds
    ``(row, col, expr)`` of d(residual)/d(tearing) in terms of them."""

    tearing: tuple[str, ...]
    inner: tuple[Assign, ...]
    residuals: tuple[Expr, ...]
    sensitivities: tuple[Assign, ...]
    jacobian: tuple[tuple[int, int, Expr], ...]
    spans: tuple[Span, ...]


Step = Assign | LinearBlock | NonlinearBlock


def step_expressions(step: Step) -> list[Expr]:
    """Every expression a solve step evaluates (a nonlinear block's inner assignments,
    residuals, sensitivities and Jacobian entries included)."""
    if isinstance(step, Assign):
        return [step.expr]
    if isinstance(step, LinearBlock):
        return [e for _, _, e in step.matrix] + list(step.rhs)
    return ([a.expr for a in step.inner] + list(step.residuals)
            + [a.expr for a in step.sensitivities] + [e for _, _, e in step.jacobian])


def computed_names(step: Step) -> tuple[str, ...]:
    """The names a solve step computes (a nonlinear block's tearing variables, then its
    inner assignments)."""
    if isinstance(step, Assign):
        return (step.name,)
    if isinstance(step, LinearBlock):
        return step.names
    return step.tearing + tuple(a.name for a in step.inner)


def map_step(step: Step, f: Callable[[Expr], Expr]) -> Step:
    """``step`` with ``f`` applied to every expression it evaluates (the names it
    solves for and its structure unchanged)."""
    if isinstance(step, Assign):
        return Assign(step.name, f(step.expr), step.span)
    if isinstance(step, LinearBlock):
        return LinearBlock(step.names, tuple((i, j, f(e)) for i, j, e in step.matrix),
                           tuple(f(e) for e in step.rhs), step.spans)
    return NonlinearBlock(
        step.tearing, tuple(Assign(a.name, f(a.expr), a.span) for a in step.inner),
        tuple(f(e) for e in step.residuals),
        tuple(Assign(a.name, f(a.expr), a.span) for a in step.sensitivities),
        tuple((i, j, f(e)) for i, j, e in step.jacobian), step.spans)


@quick_init
@dataclass(frozen=True, slots=True)
class State:
    name: str
    derivative: str
    start: Expr | None
    fixed: bool
    nominal: Expr | None
    unit: str | None
    span: Span


@dataclass(frozen=True)
class ODE:
    name: str
    states: tuple[State, ...]
    steps: tuple[Step, ...]
    observed: tuple[Assign, ...]
    parameters: tuple[dae.Parameter, ...]
    dae: dae.DAE
    events: EventSystem | None = None  # relations, discrete variables, when-clauses
    # assert(...) conditions over states, step variables, parameters and time
    assertions: tuple[flat.Assertion, ...] = ()

    def step_names(self) -> list[str]:
        """Every name computed by the steps, in order."""
        return [name for step in self.steps for name in computed_names(step)]

    def observed_names(self) -> list[str]:
        """Algebraic variables the user can ask for (derivative variables excluded)."""
        computed = [n for n in self.step_names() if not dae.is_derivative(n)]
        held = [d.name for d in self.events.discrete] if self.events else []
        return computed + [a.name for a in self.observed] + held

    def _repr_latex_(self) -> str | None:
        """The evaluation order as LaTeX in a notebook (:func:`springc.ir.latex.notebook`)."""
        return latex.notebook(latex_rows(self))


def _step_text(step: Step) -> list[str]:
    if isinstance(step, Assign):
        return [f"  {step.name} := {to_text(step.expr)}"]
    if isinstance(step, LinearBlock):
        return [f"  linear system for {', '.join(step.names)} "
                f"({len(step.names)} unknowns, {len(step.matrix)} non-zeros)"]
    lines = [f"  nonlinear system, tearing {', '.join(step.tearing)}:"]
    lines += [f"    {a.name} := {to_text(a.expr)}" for a in step.inner]
    lines += [f"    0 = {to_text(r)}" for r in step.residuals]
    return lines


def format_ode(ode: ODE) -> str:
    """``springc flatten --simplify``: states, evaluation order and observed variables."""
    observed = ode.observed_names()
    lines = [f"model {ode.name}: {len(ode.states)} states, {len(observed)} observed, "
             f"{len(ode.parameters)} parameters"]
    lines.append("states:")
    lines += [f"  {s.name}" + (f" (start {to_text(s.start)}"
                               f"{', fixed' if s.fixed else ''})" if s.start is not None
                               else "") for s in ode.states]
    lines.append("evaluation order:")
    for step in ode.steps:
        lines += _step_text(step)
    if ode.observed:
        lines.append("aliases:")
        lines += [f"  {a.name} = {to_text(a.expr)}" for a in ode.observed]
    lines.append(f"observed: {', '.join(observed) if observed else '(none)'}")
    if ode.assertions:
        lines.append("assertions:")
        lines += [f"  {to_text(a.condition)}  ({a.level}: {a.message!r})"
                  for a in ode.assertions]
    return "\n".join(lines) + "\n"


def latex_rows(ode: ODE) -> list[tuple[Expr, Expr, str]]:
    """``(lhs, rhs, note)`` in evaluation order: assignments, each row of a linear
    system (``A x = b``), a nonlinear system's inner assignments and residuals
    (``0 = r``), then the aliases."""
    rows: list[tuple[Expr, Expr, str]] = []
    for step in ode.steps:
        if isinstance(step, Assign):
            rows.append((Var(step.name), step.expr, ""))
        elif isinstance(step, LinearBlock):
            sums: dict[int, Expr] = {}
            for row, col, coefficient in step.matrix:
                sums[row] = add(sums.get(row, ZERO), mul(coefficient, Var(step.names[col])))
            rows += [(sums.get(i, ZERO), b, "linear") for i, b in enumerate(step.rhs)]
        else:
            rows += [(Var(a.name), a.expr, "nonlinear") for a in step.inner]
            rows += [(ZERO, r, "nonlinear") for r in step.residuals]
    rows += [(Var(a.name), a.expr, "alias") for a in ode.observed]
    return rows


def format_ode_latex(ode: ODE) -> str:
    """``springc flatten --simplify --latex``: :func:`latex_rows` in an ``align``."""
    return latex.align(latex_rows(ode))
