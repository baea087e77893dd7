"""Code generation: ode.ODE (+ flat.FlatModel) -> GeneratedModel (a Python module's text).

The module runs with numpy and scipy only (plus numba for the ``numba`` backend) and
exposes, over a state vector ``x``, a parameter vector ``p`` and Newton warm starts
``z``: ``parameters(values)``, ``start(p)``, ``guesses(p)``, ``rhs(t, x, p, z)``,
``jacobian_values``/``jacobian``/``jacobian_dense`` with the sparsity pattern
(``JAC_ROWS``, ``JAC_COLS``; ``JAC_INDICES``, ``JAC_INDPTR`` in CSC order),
``observed(t, x, p, z)`` and ``observed_grid(ts, X, p, z)`` for the requested observed
variables only, and the names, units and experiment settings as constants.

Every assignment carries a comment with its flat name and source ``file:line``;
common subexpressions are shared (:mod:`.printer`); the Jacobian is analytic
(:mod:`.jacobian`). Systems of thousands of explicit assignments (chains, cloths) use
the vector layout of :mod:`.vector` instead, whose code grows with the number of
distinct equation shapes; :mod:`.module_text` writes the rest of the module. Model text
reaches the module only as ``repr`` literals, sanitized identifiers (``printer.Namer``)
or escaped comments (``printer.escaped``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from ..errors import CodegenError
from ..ir import flat, ode
from ..ir.dae import derivative_name
from ..ir.expr import Var, variables
from ..ir.hybrid import event_expressions
from ..native.foreign_calls import REFUSAL, RunTimeCallRefused, function_of
from .assertions import assertion_function
from .context import (
    BACKENDS,
    CodegenBug,
    CodegenContext,
    CodegenOptions,
    GeneratedModel,
    shared_part,
)
from .delays import used_names
from .events import FUNCTIONS as EVENT_FUNCTIONS
from .events import held_system
from .jacobian import jacobian_statements
from .locate import at_initialization, locate
from .module_text import module_text, parameter_value, topological
from .printer import function_lines
from .statements import Namer, Raw, Store, reserved_name
from .vector import VectorLayout, vector_statements, vector_suits

# ------------------------------------------------------------------ parameters


def structural_parameters(system: ode.ODE, flat_model: flat.FlatModel | None) -> list[str]:
    """Parameters that generated code cannot change: Integer and Boolean ones (they may
    size arrays or pick equations), those the flattener already evaluated away (read
    by no equation, observed variable, start value or event) and those it computed a
    call with (``FlatModel.evaluated``, and the parameters their values come from)."""
    used: set[str] = set()
    if system.events is not None:
        for e in event_expressions(system.events):
            used |= variables(e)
    for step in system.steps:
        for e in ode.step_expressions(step):
            used |= variables(e)
    for a in system.observed:
        used |= variables(a.expr)
    for s in system.states:
        if s.start is not None:
            used |= variables(s.start)
    for u in system.dae.unknowns:
        if u.start is not None:
            used |= variables(u.start)
    by_name = {q.name: q for q in system.parameters}
    evaluated = set(flat_model.evaluated) if flat_model else set()
    for q in reversed(topological(system.parameters)):
        if q.name in used:
            used |= variables(parameter_value(q))
        if q.name in evaluated:  # what it is computed from was evaluated with it
            evaluated |= variables(parameter_value(q))
    types = {v.name: v.type for v in flat_model.variables} if flat_model else {}
    return [q.name for q in system.parameters
            if q.name not in used or types.get(q.name, "Real") != "Real"
            or q.name not in by_name or q.name in evaluated]


# ------------------------------------------------------------------ module


def generate(system: ode.ODE, flat_model: flat.FlatModel | None = None,
             options: CodegenOptions | None = None) -> GeneratedModel:
    """The Python module of ``system`` for ``options.backend`` (default options: the
    python backend, every observed variable). An expression that cannot be translated
    is a :class:`CodegenError` located at the model element it comes from."""
    if options is not None and options.shared is not None \
            and options.shared.setdefault("system", system) is not system:
        options = replace(options, shared=None)  # kept for another system: not used
    try:
        return _generate(at_initialization(system), flat_model, options)
    except CodegenError as err:
        located = locate(err, system)
        if located is None:
            raise
        raise located from None


def _generate(system: ode.ODE, flat_model: flat.FlatModel | None,
              options: CodegenOptions | None) -> GeneratedModel:
    options = options or CodegenOptions()
    if options.backend not in BACKENDS:
        raise CodegenError(f"unknown backend '{options.backend}'",
                           hint=f"choose one of {', '.join(BACKENDS)}")
    if system.events is not None:  # the continuous functions read held values
        system = held_system(system, CodegenContext(system, flat_model).events)  # type: ignore[arg-type]
    m = CodegenContext(system, flat_model)
    computed = system.step_names()
    available = [n for n in system.observed_names()]
    outputs = list(available if options.outputs is None else options.outputs)
    available_set = set(available)
    missing = [n for n in outputs if n not in available_set]
    if missing:
        raise CodegenError(f"'{missing[0]}' is not an observed variable of {system.name}")
    _check_defined(m, computed)
    reserved = reserved_name(m.model_names)
    if reserved is not None:
        raise CodegenError(f"the name '{reserved}' is reserved for springc's generated code",
                           hint="rename the variable (names such as _r0_1, _d2_0, _done1 "
                           "and _J3 are taken)")

    namer = Namer(m.model_names)
    helpers: set[str] = set()
    numba = options.backend == "numba"
    m.guard_errors = not numba  # math.exp raises in Python: a Newton trial backtracks
    if not numba:
        m.keep_linear_matrices()
    vector = options.vector
    if m.events is not None or len(m.delays):
        vector = False  # the event functions are written with scalar statements
    elif vector is None:
        vector = vector_suits(system)
    elif vector and not vector_suits(system, 0):
        raise CodegenError("the vector layout needs a system of explicit assignments only")
    if vector:
        layout = VectorLayout(m, vector_statements(m, outputs), numba)
        jac_lines, pattern = layout.jacobian_body(helpers)
        bodies = [
            ("rhs", "Time derivatives of the states at time t.",
             layout.body(m.derivatives, helpers), "dx"),
            ("jacobian_values", _JAC_DOC, jac_lines, "jv"),
            ("observed", "The OBSERVED variables at time t.",
             layout.body(outputs, helpers) + layout.gather(outputs), "out"),
        ]
        table: list[int] | None = layout.table
    else:
        bodies, pattern = _scalar_bodies(m, outputs, namer, helpers, numba)
        table = None
    if m.events is not None:
        prologue = [] if numba else [Raw("x = x.tolist()\np = p.tolist()")]
        bodies += [(fn, doc, function_lines(namer, helpers, prologue + make(m, m.events)), ret)
                   for fn, doc, make, ret in EVENT_FUNCTIONS]
    bodies.append(assertion_function(m, namer, helpers, numba))
    if len(m.delays):
        prologue = [] if numba else [Raw("x = x.tolist()\np = p.tolist()")]
        steps, _ = m.step_stmts()
        base = m.loads() + steps + m.alias_stmts(sorted(used_names(m.delays)))
        bodies.append(("delay_inputs", "The delayed expressions, then the delay times.",
                       function_lines(namer, helpers, prologue + m.delays.inputs_body(base)),
                       "di"))
    if numba and "_foreign" in helpers:
        raise RunTimeCallRefused(REFUSAL.format("the numba backend", foreign_function(bodies)))
    structural = shared_part(options, "structural",
                             lambda: structural_parameters(system, flat_model))
    source = module_text(m, options, bodies, helpers, pattern, outputs, structural, namer,
                          table)
    return GeneratedModel(system.name, source, options.backend, tuple(m.states),
                          tuple(outputs), tuple(m.params), tuple(structural))


def foreign_function(bodies: list[tuple[str, str, list[str], str]]) -> str:
    """The Modelica name of the first function the bodies call at run time."""
    for _, _, lines, _ in bodies:
        for line in lines:
            found = _FOREIGN_LINE.search(line)
            if found:
                return function_of(found.group(2))
    return "?"


_FOREIGN_LINE = re.compile(r"_foreign\((['\"])(.+?)\1")
_JAC_DOC = "Non-zeros of d(rhs)/dx in CSC order (JAC_INDICES, JAC_INDPTR)."


def _scalar_bodies(m: CodegenContext, outputs: Sequence[str], namer: Namer, helpers: set[str],
                   numba: bool) -> tuple[list[tuple[str, str, list[str], str]],
                                         list[tuple[int, int]]]:
    """Straight-line bodies: one statement per assignment, named locals."""
    computed = m.ode.step_names()
    steps, described = m.step_stmts()
    loads = m.loads()
    n = len(m.states)

    rhs = loads + steps + m.alias_stmts([d for d in m.derivatives if d not in computed])
    rhs.append(Raw(f"dx = np.empty({n})"))
    rhs += [Store(f"dx[{i}]", Var(d), derivative_name(s)) for i, (s, d)
            in enumerate(zip(m.states, m.derivatives))]

    jac_body, pattern = jacobian_statements(
        m.states, m.derivatives, described,
        {a.name: a.expr for a in m.ode.observed if a.name in m.derivative_set})
    jac = loads + steps + jac_body

    obs = loads + steps + m.alias_stmts(outputs) + [Raw(f"out = np.empty({len(outputs)})")]
    obs += [Store(f"out[{i}]", Var(name), name) for i, name in enumerate(outputs)]

    functions = [
        ("rhs", "Time derivatives of the states at time t.", rhs, "dx"),
        ("jacobian_values", _JAC_DOC, jac, "jv"),
        ("observed", "The OBSERVED variables at time t.", obs, "out"),
    ]
    # Plain Python computes fastest on Python floats, which also raise
    # ZeroDivisionError or ValueError where they happen (springc names the line).
    prologue = [] if numba else [Raw("x = x.tolist()\np = p.tolist()")]
    bodies = [(fn, doc, function_lines(namer, helpers, prologue + stmts), ret)
              for fn, doc, stmts, ret in functions]
    return bodies, pattern


def _check_defined(m: CodegenContext, computed: Sequence[str]) -> None:
    known = set(m.states) | set(m.params) | set(computed) | set(m.aliases)
    known |= set(m.events.slot) if m.events is not None else set()
    known |= set(m.delays.names)
    for step in m.ode.steps:
        inner = set()
        if isinstance(step, ode.NonlinearBlock):
            inner = {*step.tearing, *(s.name for s in step.sensitivities)}
        for e in ode.step_expressions(step):
            read = variables(e)
            if read <= known:  # the common case, without two new sets
                continue
            unknown = read - known - inner
            if unknown:
                name = sorted(unknown)[0]
                raise CodegenBug(f"the simplified system reads '{name}' but nothing "
                                 "computes it")
    computed_set = set(computed) | set(m.states)  # a state may be der(v) of another
    for d in m.derivatives:
        if d not in computed_set and d not in m.aliases:
            raise CodegenBug(f"nothing computes {d}")


