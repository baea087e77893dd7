"""Code generation in C: ode.ODE (+ flat.FlatModel) -> CModelSource (one C file).

The file holds one model (one translation unit), includes only ``<math.h>``, allocates
nothing, has no global that changes and no recursion: it compiles as C99 and as CUDA
device code (``#define SPRINGC_FN __device__``). Its interface (sizes as
``SPRINGC_*`` macros, name tables, ``springc_parameters``, ``springc_start``,
``springc_rhs``, ``springc_observed``, the event functions) is documented in
``docs/c_model.md``; the values are those of the Python module of the same system
(:mod:`.generator`): the same statements (:mod:`.context`, :mod:`.events`) printed by
:mod:`.c_printer`, with the blocks of :mod:`.c_context`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import CodegenError
from ..ir import flat, ode
from ..ir.expr import If, Var
from .c_context import SOLVE, CContext, c_jacobian, c_statements
from .c_printer import C_RESERVED, HELPERS, c_function_body
from .c_tables import c_tables
from .c_vector import (
    grouped,
    grouped_parameters,
    jacobian_floor,
    model_functions,
    parameter_functions,
)
from .context import CodegenContext, source_comment
from .events import FUNCTIONS as EVENT_FUNCTIONS
from .events import held_system
from .generator import structural_parameters
from .jacobian import jacobian_statements
from .locate import at_initialization, locate, untranslatable
from .module_api import JACOBIAN_LIMIT
from .module_text import parameter_value, start_of, topological
from .statements import Let, Load, Namer, Raw, Stmt, Store, reserved_name

_SIGNATURE = "double t, const double *x, const double *p, double *z"


@dataclass(frozen=True)
class CModelSource:
    """The C file of a model (``text``) and what it holds."""

    name: str
    text: str
    states: tuple[str, ...]
    parameters: tuple[str, ...]
    observed: tuple[str, ...]
    crossings: tuple[str, ...]
    hybrid: bool
    n_z: int


def generate_c(system: ode.ODE, flat_model: flat.FlatModel | None = None,
               outputs: Sequence[str] | None = None, vector: bool | None = None
               ) -> CModelSource:
    """The C file of ``system`` computing the observed variables ``outputs`` (None:
    every one). An expression that C cannot compute is a :class:`CodegenError` located
    at the model element it comes from. ``vector``: loops over index tables
    (:mod:`.c_vector`) by the size rule of the Python modules (None), wherever the
    system allows them (True), or none (False: one statement per scalar)."""
    try:
        return _generate_c(at_initialization(system), flat_model, outputs, vector)
    except CodegenError as err:
        located = locate(err, system)
        if located is None:
            raise
        raise located from None


def _generate_c(system: ode.ODE, flat_model: flat.FlatModel | None,
                outputs: Sequence[str] | None, vector: bool | None) -> CModelSource:
    if system.events is not None:  # the continuous functions read held values
        system = held_system(system, CodegenContext(system, flat_model).events)  # type: ignore[arg-type]
    m = CContext(system, flat_model)
    if len(m.delays):
        raise untranslatable("cannot generate C code for delay(...) (not supported in "
                             "the C model)", m.delays.calls[0])
    available = system.observed_names()
    chosen = list(available if outputs is None else outputs)
    missing = sorted(set(chosen) - set(available))
    if missing:
        raise CodegenError(f"'{missing[0]}' is not an observed variable of {system.name}")
    reserved = reserved_name(m.model_names)
    if reserved is not None:
        raise CodegenError(f"the name '{reserved}' is reserved for springc's generated code")
    namer = Namer(m.model_names, C_RESERVED, "springc")
    helpers: set[str] = set()
    data, functions = _functions(m, chosen, namer, helpers, vector)
    m.code_chars = sum(len(line) + 1 for line in functions)
    structural = structural_parameters(system, flat_model)
    lines = c_tables(m, chosen, structural)
    if m.uses_solve:
        lines += ["", SOLVE]
    lines += [text for name in sorted(helpers) for text in ("", HELPERS[name])]
    lines += data + functions
    crossings = tuple(m.events.texts) if m.events is not None else ()
    return CModelSource(system.name, "\n".join(lines) + "\n", tuple(m.states),
                        tuple(m.params), tuple(chosen), crossings, m.events is not None,
                        m.flag_slot + 1)


def _function(head: str, body: list[str], ret: str = "_code") -> list[str]:
    return ["", f"SPRINGC_FN {head}", "{", "    int _code = 0;", *body,
            f"    return {ret};", "}"]


def _functions(m: CContext, outputs: Sequence[str], namer: Namer, helpers: set[str],
               vector: bool | None) -> tuple[list[str], list[str]]:
    """The file-scope data (index tables of the vector layout) and the functions."""
    steps, described = m.step_stmts()
    data: list[str] = []
    if grouped_parameters(m, vector):
        tables, parameters, start = parameter_functions(m, helpers)
        data += ["", *tables]
        lines = _parameters_function(parameters)
    else:
        lines = _parameters(m, namer, helpers)
        start = c_function_body(namer, helpers, _start(m))
    lines += _function("int springc_start(const double *p, double *x, double *z)", start)
    if grouped(m, vector):
        tables, bodies = model_functions(m, outputs, helpers)
        data += ["", *tables]
        rhs, obs = bodies[0][1], bodies[1][1]
    else:
        loads = m.loads()
        computed = set(m.ode.step_names())
        rhs_stmts = loads + steps + m.alias_stmts([d for d in m.derivatives
                                                   if d not in computed])
        rhs_stmts += [Store(f"dx[{i}]", Var(d), d) for i, d in enumerate(m.derivatives)]
        obs_stmts = loads + steps + m.alias_stmts(outputs)
        obs_stmts += [Store(f"out[{i}]", Var(name), name) for i, name in enumerate(outputs)]
        rhs = c_function_body(namer, helpers, rhs_stmts)
        obs = c_function_body(namer, helpers, obs_stmts)
    lines += _function(f"int springc_rhs({_SIGNATURE}, double *dx)", rhs)
    lines += _function(f"int springc_observed({_SIGNATURE}, double *out)", obs)
    large = grouped(m, vector) and jacobian_floor(m) > JACOBIAN_LIMIT
    lines += _jacobian(m, [] if large else steps, described, namer, helpers, large)
    return data, lines + _event_functions(m, namer, helpers)


def _jacobian(m: CContext, steps: list[Stmt], described: list[tuple[ode.Step, int, str]],
              namer: Namer, helpers: set[str], large: bool) -> list[str]:
    """``springc_jacobian`` (the non-zeros of d(rhs)/dx in CSC order, the analytic
    Jacobian of :mod:`.jacobian`, blocks through ``springc_solve``) and
    ``springc_jacobian_pattern``, where it has at most :data:`JACOBIAN_LIMIT`
    non-zeros (else ``SPRINGC_HAS_JACOBIAN`` is 0 and ``springc_jacobian`` returns
    -3; ``large``: known to have more, :func:`.c_vector.jacobian_floor`, so not
    differentiated at all)."""
    body, pattern = ([], []) if large else jacobian_statements(
        m.states, m.derivatives, described,
        {a.name: a.expr for a in m.ode.observed if a.name in m.derivative_set})
    cheap = not large and len(pattern) <= JACOBIAN_LIMIT
    m.jacobian_size = len(pattern) if cheap else 0
    m.has_jacobian = cheap
    lines = ["", "SPRINGC_FN void springc_jacobian_pattern(int *rows, int *cols)", "{"]
    if cheap:
        lines += [f"    rows[{k}] = {r};\n    cols[{k}] = {c};" for k, (r, c)
                  in enumerate(pattern)]
    lines.append("}")
    if not cheap:
        return lines + _function(f"int springc_jacobian({_SIGNATURE}, double *jv)", [],
                                 "-3")
    stmts = m.loads() + steps + c_jacobian(body)
    return lines + _function(f"int springc_jacobian({_SIGNATURE}, double *jv)",
                             c_function_body(namer, helpers, stmts))


def _parameters(m: CContext, namer: Namer, helpers: set[str]) -> list[str]:
    index = {name: i for i, name in enumerate(m.params)}
    stmts: list[Stmt] = []
    for q in topological(m.ode.parameters):
        i = index[q.name]
        # a given value is kept; the others follow their bindings
        stmts.append(Load(f"_pg{i}", f"given != 0 && given[{i}] ? 1.0 : 0.0"))
        stmts.append(Load(f"_pp{i}", f"p[{i}]"))
        stmts.append(Let(q.name, If(Var(f"_pg{i}"), Var(f"_pp{i}"), parameter_value(q)),
                         source_comment(q.name, q.span)))
        stmts.append(Store(f"p[{i}]", Var(q.name)))
    return _parameters_function(c_function_body(namer, helpers, stmts))


def _parameters_function(body: list[str]) -> list[str]:
    return ["", "SPRINGC_FN void springc_parameters(double *p, const int *given)", "{",
            *body, "}", "",
            "SPRINGC_FN void springc_default_parameters(double *p)", "{",
            "    springc_parameters(p, 0);", "}"]


def _start(m: CContext) -> list[Stmt]:
    stmts: list[Stmt] = list(m.loads()[:len(m.params)])
    stmts.append(Raw(f"for (int _i = 0; _i < {m.flag_slot + 1}; _i++) z[_i] = 0.0;"))
    for i, s in enumerate(m.ode.states):
        stmts.append(Store(f"x[{i}]", start_of(m, s.name, s.start), s.name))
    for t, slot in m.guess_slots.items():
        u = m.unknowns.get(t)
        stmts.append(Store(f"z[{slot}]", start_of(m, t, u.start if u else None), t))
    for d in m.ode.events.discrete if m.ode.events else ():
        assert m.events is not None
        stmts.append(Store(f"z[{m.events.slot[d.name]}]", start_of(m, d.name, d.start),
                           f"{d.name} (start)"))
    return stmts


_EVENT_UPDATE = """
SPRINGC_FN int springc_event_update(double t, double *x, const double *p, double *z)
{
    double xn[SPRINGC_N_STATES + 1];
    int code = springc_event_begin(t, x, p, z);
    int more = 0;
    z[SPRINGC_Z_STATUS] = 1.0;
    for (int k = 0; k < SPRINGC_EVENT_ITERATIONS; k++) {
        if (k == SPRINGC_SIMULTANEOUS_PASSES) z[SPRINGC_Z_STATUS] = 2.0;
        more = springc_event_pass(t, x, p, z, xn);
        code = more != 0 ? more : code;
        for (int i = 0; i < SPRINGC_N_STATES; i++) x[i] = xn[i];
        if (z[SPRINGC_Z_CHANGED] == 0.0) {
            z[SPRINGC_Z_STATUS] = 0.0;
            break;
        }
    }
    more = springc_event_end(t, x, p, z);
    code = more != 0 ? more : code;
    if (code != 0) return code;
    if (z[SPRINGC_Z_STATUS] != 0.0) return -1;
    return z[SPRINGC_Z_TERMINATE] > 0.0 ? -2 : 0;
}"""

_NO_EVENTS = f"""
SPRINGC_FN int springc_zero_crossings({_SIGNATURE}, double *g)
{{
    return 0;
}}

SPRINGC_FN double springc_next_time_event({_SIGNATURE})
{{
    return SPRINGC_INF;
}}

SPRINGC_FN int springc_event_update(double t, double *x, const double *p, double *z)
{{
    return 0;
}}"""

_HEADS = {
    "zero_crossings": f"int springc_zero_crossings({_SIGNATURE}, double *g)",
    "next_time_event": f"double springc_next_time_event({_SIGNATURE})",
    "event_begin": f"int springc_event_begin({_SIGNATURE})",
    "event_pass": "int springc_event_pass(double t, const double *x, const double *p, "
                  "double *z, double *xn)",
    "event_end": f"int springc_event_end({_SIGNATURE})",
}


def _event_functions(m: CContext, namer: Namer, helpers: set[str]) -> list[str]:
    if m.events is None:
        return _NO_EVENTS.splitlines()
    lines: list[str] = []
    for fn, _doc, make, _ret in EVENT_FUNCTIONS:
        stmts = c_statements(make(m, m.events), ("g", "xn"))
        body = c_function_body(namer, helpers, stmts)
        if fn == "next_time_event":
            lines += ["", f"SPRINGC_FN {_HEADS[fn]}", "{", *body, "    return _zo[0];", "}"]
        else:
            lines += _function(_HEADS[fn], body)
    return lines + _EVENT_UPDATE.splitlines()
