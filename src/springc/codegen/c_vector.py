"""The C model's functions in the vector layout: CContext -> loops over index tables.

A large system of explicit assignments (a chain's masses, a cloth's nodes; the one
policy of :func:`.vector.vector_suits` and :func:`.vector.parameters_suit`, shared
with the Python modules) is printed as the numba module prints it: one ``for`` loop
per group of same-shaped assignments (:class:`.vector.VectorLayout` with ``c=True``),
its members' indices affine in the loop counter or read from an index table. The C
text then grows with the number of shapes, not of masses, and so does the C
compiler's time. Intermediate values live in the fixed-size local array ``w`` (and
``dx`` in ``springc_observed``); :data:`CContext.work_doubles` records the largest
(``SPRINGC_WORK_DOUBLES``: such arrays are on the caller's stack). The index tables
and the constants lifted from parameter bindings and start values are file-scope
``SPRINGC_DATA`` arrays (``static const``; CUDA: ``__device__``).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir.expr import variables
from .c_context import CContext
from .c_printer import c_double
from .module_text import parameter_value, start_of, topological
from .vector import (
    VECTOR_THRESHOLD,
    VectorLayout,
    parameters_suit,
    vector_statements,
    vector_suits,
)

Printed = tuple[str, list[str]]
"""A function's head (``int springc_rhs(...)``) and its body lines."""


def grouped(m: CContext, vector: bool | None = None) -> bool:
    """Whether ``rhs`` and ``observed`` of ``m`` are printed as loops (``vector``:
    None by size, :func:`.vector.vector_suits`; True: wherever the system allows)."""
    if m.events is not None or len(m.delays) or vector is False:
        return False
    return vector_suits(m.ode, 0 if vector else VECTOR_THRESHOLD)


def grouped_parameters(m: CContext, vector: bool | None = None) -> bool:
    """Whether ``springc_parameters`` and ``springc_start`` are printed as loops."""
    if vector is not None:
        return vector and m.guess_slots == {} and m.events is None and not len(m.delays)
    return not len(m.delays) and parameters_suit(m)


def jacobian_floor(m: CContext) -> int:
    """The derivatives whose assignment reads a state, directly or through other
    assignments: each is a non-zero of the Jacobian (barring an exact cancellation),
    so a floor of their count, found without differentiating anything."""
    states = set(m.states)
    reads: dict[str, bool] = {}
    for name, e, _ in vector_statements(m, ()):
        reads[name] = any(v in states or reads.get(v, False) for v in variables(e))
    return sum(reads.get(d, False) for d in m.derivatives)


def _data(kind: str, name: str, values: Sequence[int] | Sequence[float]) -> list[str]:
    if kind == "int":
        items = [str(int(v)) for v in values] or ["0"]
    else:
        items = [c_double(float(v)) for v in values] or ["0.0"]
    rows = [", ".join(items[i:i + 16]) for i in range(0, len(items), 16)]
    return [f"SPRINGC_DATA {kind} {name}[{len(items)}] = {{",
            *(f"    {row}," for row in rows), "};"]


def model_functions(m: CContext, outputs: Sequence[str], helpers: set[str]
                    ) -> tuple[list[str], list[Printed]]:
    """The index table and the bodies of ``springc_rhs`` and ``springc_observed``."""
    layout = VectorLayout(m, vector_statements(m, outputs), numba=False, c=True,
                          table_name="springc_index")
    rhs = layout.body(m.derivatives, helpers, dx=False)
    observed = layout.body(outputs, helpers) + layout.gather(outputs)
    m.work_doubles = max(m.work_doubles, layout.work_doubles(m.derivatives, dx=False),
                         layout.work_doubles(outputs))
    return _data("int", "springc_index", layout.table), [("rhs", rhs), ("observed", observed)]


def parameter_functions(m: CContext, helpers: set[str]) -> tuple[list[str], list[str],
                                                                  list[str]]:
    """The tables and the bodies of ``springc_parameters`` (a given value kept, its
    dependents following) and ``springc_start``."""
    params = VectorLayout(m, [(q.name, parameter_value(q), q.span)
                              for q in topological(m.ode.parameters)],
                          numba=False, c=True, table_name="springc_pindex",
                          lift_constants=True, float_name="springc_pfloats")
    body = params.body(m.params, helpers,
                       kept=lambda target: f"(given != 0 && given{target[1:]} != 0)")
    starts = VectorLayout(m, [(s.name, start_of(m, s.name, s.start), s.span)
                              for s in m.ode.states],
                          numba=False, c=True, table_name="springc_sindex",
                          lift_constants=True, float_name="springc_sfloats")
    start = [f"    for (int _i = 0; _i < {m.flag_slot + 1}; _i++) z[_i] = 0.0;",
             *starts.body(m.states, helpers)]
    m.work_doubles = max(m.work_doubles, params.work_doubles(m.params),
                         starts.work_doubles(m.states))
    data = _data("int", "springc_pindex", params.table)
    data += _data("double", "springc_pfloats", params.floats)
    data += _data("int", "springc_sindex", starts.table)
    data += _data("double", "springc_sfloats", starts.floats)
    return data, body, start
