"""The head of a C model file: its sizes as ``SPRINGC_*`` macros and its name tables.

Every name, unit, description and message is a C string literal (:func:`.c_printer.
c_string`); the file's comment names the model only through :func:`.c_printer.c_comment`.
The tables are host data (``static const``), left out where ``SPRINGC_NO_TABLES`` is
defined (CUDA device code needs none of them); each is NULL- or 0-terminated, so none
is empty.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir.expr import variables
from ..simplify import conditions as initial_conditions
from .c_context import CContext
from .c_printer import c_comment, c_double, c_string
from .context import CodegenContext
from .events import EVENT_ITERATIONS, SIMULTANEOUS_PASSES, after_initial

# NVRTC (CUDA C++ compiled at run time) has the math functions built in, no <math.h>,
# and no host tables; CUDA spells infinity and NaN with its bit-pattern intrinsics.
_HEADER = """#if defined(__CUDACC_RTC__) && !defined(SPRINGC_NO_TABLES)
#define SPRINGC_NO_TABLES
#endif
#ifndef __CUDACC_RTC__
#include <math.h>
#endif

#ifndef SPRINGC_FN
#define SPRINGC_FN static
#endif
#ifndef SPRINGC_DATA
#ifdef __CUDACC__
#define SPRINGC_DATA static __device__ const
#else
#define SPRINGC_DATA static const
#endif
#endif
#ifndef SPRINGC_INF
#ifdef __CUDACC__
#define SPRINGC_INF __longlong_as_double(0x7ff0000000000000LL)
#else
#define SPRINGC_INF HUGE_VAL
#endif
#endif
#ifndef SPRINGC_NAN
#ifdef __CUDACC__
#define SPRINGC_NAN __longlong_as_double(0x7ff8000000000000LL)
#else
#define SPRINGC_NAN NAN
#endif
#endif"""


def _strings(name: str, size: str, values: Sequence[str]) -> list[str]:
    items = [f"    {c_string(v)}," for v in values] + ["    0"]
    return [f"static const char *const {name}[{size} + 1] = {{", *items, "};"]


def _ints(name: str, size: str, values: Sequence[int]) -> list[str]:
    items = ", ".join(str(v) for v in [*values, 0])
    return [f"static const int {name}[{size} + 1] = {{{items}}};"]


def _host_double(value: float | None) -> str:
    # the tables are host data: <math.h>'s spelling of NaN and infinity
    text = c_double(value) if value is not None else "NAN"
    return text.replace("SPRINGC_NAN", "NAN").replace("SPRINGC_INF", "HUGE_VAL")


def _description(m: CodegenContext, name: str) -> str:
    v = m.variables.get(name)
    return v.description if v is not None and v.description else ""


def _macros(m: CContext, outputs: Sequence[str]) -> list[str]:
    layout = m.events
    sizes = [
        ("SPRINGC_N_STATES", len(m.states)), ("SPRINGC_N_PARAMS", len(m.params)),
        ("SPRINGC_N_Z", m.flag_slot + 1), ("SPRINGC_Z_FLAG", m.flag_slot),
        ("SPRINGC_N_OBSERVED", len(outputs)),
        ("SPRINGC_N_CROSSINGS", len(layout.relations) if layout else 0),
        ("SPRINGC_N_NEWTON", len(m.newton_systems())),
        ("SPRINGC_HYBRID", int(layout is not None)),
        ("SPRINGC_INITIAL_CONDITIONS", len(initial_conditions(m.ode))),
        ("SPRINGC_HAS_JACOBIAN", int(m.has_jacobian)), ("SPRINGC_N_JAC", m.jacobian_size),
        ("SPRINGC_WORK_DOUBLES", m.work_doubles), ("SPRINGC_CODE_CHARS", m.code_chars),
    ]
    if layout is not None:
        s = layout.slot
        sizes += [
            ("SPRINGC_Z_RELATIONS", s[layout.relations[0]] if layout.relations
             else layout.base),
            ("SPRINGC_Z_INITIAL", s["_zinit"]), ("SPRINGC_Z_TERMINAL", s["_zterm"]),
            ("SPRINGC_Z_TERMINATE", s["_zstop"]), ("SPRINGC_Z_CHANGED", s["_zchanged"]),
            ("SPRINGC_Z_STATUS", s["_zstatus"]),
            ("SPRINGC_EVENT_ITERATIONS", EVENT_ITERATIONS),
            ("SPRINGC_SIMULTANEOUS_PASSES", SIMULTANEOUS_PASSES),
            ("SPRINGC_USES_TERMINAL", int(layout.uses_terminal)),
            ("SPRINGC_AFTER_INITIAL", int(after_initial(layout))),
            ("SPRINGC_N_TERMINATE_MESSAGES", len(layout.messages)),
        ]
    return [f"#define {name} {value}" for name, value in sizes]


def c_tables(m: CContext, outputs: Sequence[str], structural: Sequence[str]
             ) -> list[str]:
    """The file's first lines: a comment, ``#include <math.h>``, ``SPRINGC_FN``, the
    size macros and the name tables of the model ``m`` with observed ``outputs`` (after
    its functions were printed: they set ``m.has_jacobian``)."""
    exp = m.ode.dae.experiment
    experiment = [exp.start, exp.stop, exp.interval, exp.tolerance]
    fixed = set(structural)
    bound = {q.name for q in m.ode.parameters
             if q.binding is not None and variables(q.binding)}
    newton = m.newton_systems()
    lines = [f"/* springc-generated C model {c_comment(m.ode.name)}: the interface is "
             "described in springc's docs/c_model.md */", _HEADER, "",
             *_macros(m, outputs), "", "#ifndef SPRINGC_NO_TABLES",
             f"static const char *const springc_model_name = {c_string(m.ode.name)};"]
    lines += _strings("springc_state_names", "SPRINGC_N_STATES", m.states)
    lines += _strings("springc_derivative_names", "SPRINGC_N_STATES", m.derivatives)
    lines += _strings("springc_state_units", "SPRINGC_N_STATES",
                      [m.unit(s) for s in m.states])
    lines += _strings("springc_state_descriptions", "SPRINGC_N_STATES",
                      [_description(m, s) for s in m.states])
    lines += _strings("springc_parameter_names", "SPRINGC_N_PARAMS", m.params)
    lines += _strings("springc_parameter_units", "SPRINGC_N_PARAMS",
                      [m.unit(q) for q in m.params])
    lines += _strings("springc_parameter_descriptions", "SPRINGC_N_PARAMS",
                      [_description(m, q) for q in m.params])
    lines += _ints("springc_parameter_structural", "SPRINGC_N_PARAMS",
                   [int(q in fixed) for q in m.params])
    lines += _ints("springc_parameter_bound", "SPRINGC_N_PARAMS",
                   [int(q in bound) for q in m.params])
    lines += _strings("springc_observed_names", "SPRINGC_N_OBSERVED", outputs)
    lines += _strings("springc_observed_units", "SPRINGC_N_OBSERVED",
                      [m.unit(o) for o in outputs])
    lines += _strings("springc_observed_descriptions", "SPRINGC_N_OBSERVED",
                      [_description(m, o) for o in outputs])
    lines += _strings("springc_crossing_texts", "SPRINGC_N_CROSSINGS",
                      m.events.texts if m.events else [])
    lines += _strings("springc_terminate_messages",
                      str(len(m.events.messages) if m.events else 0),
                      m.events.messages if m.events else [])
    lines += _ints("springc_newton_codes", "SPRINGC_N_NEWTON", list(newton))
    lines += _strings("springc_newton_tearing", "SPRINGC_N_NEWTON",
                      [", ".join(names) for names in newton.values()])
    lines += ["/* start, stop, interval, tolerance of the experiment; NAN: not given */",
              "static const double springc_experiment[4] = {"
              + ", ".join(_host_double(v) for v in experiment)
              + "};",
              "#endif", "",
              "SPRINGC_FN void springc_sizes(int *n)", "{",
              "    n[0] = SPRINGC_N_STATES;", "    n[1] = SPRINGC_N_PARAMS;",
              "    n[2] = SPRINGC_N_Z;", "    n[3] = SPRINGC_N_OBSERVED;",
              "    n[4] = SPRINGC_N_CROSSINGS;", "    n[5] = SPRINGC_HYBRID;",
              "    n[6] = SPRINGC_N_JAC;", "    n[7] = SPRINGC_HAS_JACOBIAN;", "}"]
    return lines
