"""Linear blocks whose matrix holds still between events, in generated Python code.

A loop of ideal switches (``v = s*(if off then 1 else Ron)``) is a linear block whose
matrix entries read only parameters and discrete values: the matrix changes at events,
not from one evaluation to the next. In the python backend such a block keeps its
matrix and inverse per value of its entries (``_linear_factors``: a dictionary keyed
by the entries' values, so a hit is the very matrix; at most :data:`KEPT` of them per
block), and solves ``A y = b`` as ``M b`` with one step of iterative refinement
(``y + M (b - A y)``) instead of a fresh ``np.linalg.solve`` with its checks at every
evaluation: Electrical.Analog.Examples.CauerLowPassSC solves eleven such blocks in
every right-hand side. A singular matrix gets the basic solution of a consistent
system, its free unknowns 0, NaN where inconsistent (``_newton_solve``, the torn blocks'
rule: a loop of switches or stuck elements was a torn block before ``fold`` made it
linear); a non-finite matrix gives NaN, as the solve's guard does. The numba and C backends solve
each time (:func:`.statements.guarded_solve`, :mod:`.c_context`).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir import expr as x
from ..ir import ode
from .statements import Raw, Stmt, Store, guarded_solve

KEPT = 64
"""The matrices a block keeps; one more clears them (a matrix that moves after all)."""

LINEAR_FACTORS = f'''_LINEAR_FACTORS = {{}}


def _linear_factors(block, key, where, n):
    kept = _LINEAR_FACTORS.setdefault(block, {{}})
    hit = kept.get(key)
    if hit is None:
        a = np.zeros((n, n))
        for (i, j), v in zip(where, key):
            a[i, j] = v
        if not np.isfinite(a).all():
            m = np.full((n, n), np.nan)
        else:
            try:
                m = np.linalg.inv(a)
            except np.linalg.LinAlgError:
                m = None
        if len(kept) >= {KEPT}:
            kept.clear()
        hit = kept[key] = (a, m)
    return hit'''


def varying_names(system: ode.ODE) -> set[str]:
    """The names whose values may change between events: the states, and what the
    steps compute from them or from ``time`` (the rest read parameters and the
    discrete values held in ``z``)."""
    varying = {s.name for s in system.states}
    for step in system.steps:
        if isinstance(step, ode.Assign) and not moves(step.expr, varying):
            continue
        varying.update(ode.computed_names(step))
    return varying


def moves(e: x.Expr, varying: set[str]) -> bool:
    """Whether ``e`` reads ``time`` or a varying name."""
    return bool(x.variables(e) & varying) or any(type(n) is x.Time for n in x.walk(e))


def held_linear(block: ode.LinearBlock, index: int, varying: set[str]) -> list[Stmt] | None:
    """The statements of ``block`` with its matrix kept (see the module docstring), or
    None where an entry moves between events."""
    if any(moves(e, varying) for _, _, e in block.matrix):
        return None
    n, m = len(block.names), len(block.matrix)
    where = tuple((i, j) for i, j, _ in block.matrix)
    body: list[Stmt] = [Raw(f"_k{index} = [0.0] * {m}")]
    body += [Store(f"_k{index}[{k}]", e) for k, (_, _, e) in enumerate(block.matrix)]
    body.append(Raw(f"_A{index}, _M{index} = _linear_factors({index}, tuple(_k{index}), "
                    f"{where!r}, {n})"))
    body += _rhs(block.rhs, index)
    body.append(Raw(f"if _M{index} is None:\n"
                    f"    _y{index} = _newton_solve(_A{index}, _b{index}, np.zeros({n}))\n"
                    f"elif np.isfinite(_b{index}).all():\n"
                    f"    _y{index} = _M{index} @ _b{index}\n"
                    f"    _y{index} = _y{index} + _M{index} @ (_b{index} - _A{index} @ _y{index})\n"
                    f"else:\n"
                    f"    _y{index} = np.full({n}, np.nan)"))
    return body


def solved_linear(block: ode.LinearBlock, index: int) -> list[Stmt]:
    """The statements of ``block`` solved at every evaluation."""
    n = len(block.names)
    body: list[Stmt] = [Raw(f"_A{index} = np.zeros(({n}, {n}))")]
    body += [Store(f"_A{index}[{i}, {j}]", e) for i, j, e in block.matrix]
    body += _rhs(block.rhs, index)
    body.append(Raw(guarded_solve(f"_y{index}", f"_A{index}", f"_b{index}", f"{n}")))
    return body


def _rhs(rhs: Sequence[x.Expr], index: int) -> list[Stmt]:
    out: list[Stmt] = [Raw(f"_b{index} = np.empty({len(rhs)})")]
    return out + [Store(f"_b{index}[{i}]", e) for i, e in enumerate(rhs)]
