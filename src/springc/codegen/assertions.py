"""The assertions of a generated module: ``ASSERTIONS`` and ``assertions(t, x, p, z)``.

``ASSERTIONS`` is a tuple of ``(message, level, location, parameters_only, width)``
per ``assert`` of the model (``width``: of the caret under the location), written as a
``repr`` literal (model text is data: the message reaches the module only so).
``assertions(t, x, p, z)`` returns one number per assertion, 1.0 where its condition
holds and 0.0 where it fails; it computes the steps and aliases its conditions read, as
``observed`` does.
"""

from __future__ import annotations

from ..ir import flat, ode
from ..ir.expr import Time, variables, walk
from .context import CodegenContext
from .printer import function_lines
from .statements import Namer, Raw, Stmt, Store


def parameters_only(item: flat.Assertion, system: ode.ODE) -> bool:
    """Whether the condition reads parameters and constants only (checked once, before
    the integration starts)."""
    names = {q.name for q in system.parameters}
    return variables(item.condition) <= names and not any(
        isinstance(n, Time) for n in walk(item.condition))


def assertion_table(system: ode.ODE) -> str:
    """The ``ASSERTIONS`` constant's value as Python text."""
    rows = tuple((item.message, item.level,
                  f"{item.span.file}:{item.span.line}:{item.span.column}",
                  parameters_only(item, system), item.span.width(len("assert")))
                 for item in system.assertions)
    return repr(rows)


def assertion_function(m: CodegenContext, namer: Namer, helpers: set[str], numba: bool
                       ) -> tuple[str, str, list[str], str]:
    """``(name, docstring, body lines, returned name)`` of ``assertions``."""
    items = m.ode.assertions
    stmts: list[Stmt] = []
    if items:
        read = sorted({n for item in items for n in variables(item.condition)})
        # conditions on parameters only (a sample interval's): no step of the model
        steps = [] if all(parameters_only(item, m.ode) for item in items) \
            else m.step_stmts()[0]
        stmts = m.loads() + steps + m.alias_stmts(read)
    stmts.append(Raw(f"ok = np.empty({len(items)})"))
    layout = m.events  # initial() and terminal() read their event slots
    stmts += [Store(f"ok[{i}]", layout.hold(item.condition) if layout else item.condition,
                    f"assertion {i}") for i, item in enumerate(items)]
    prologue: list[Stmt] = [] if numba or not items else [
        Raw("x = x.tolist()\np = p.tolist()")]
    doc = "1.0 for each ASSERTIONS condition that holds at time t, 0.0 where it fails."
    return "assertions", doc, function_lines(namer, helpers, prologue + stmts), "ok"
