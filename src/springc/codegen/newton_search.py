"""The backtracking line search of the Newton iterations of torn blocks, in generated
Python, numba and C code.

Newton's full step from a point far from the solution can overshoot: on a diode's or a
transistor's exponential it lands where ``exp`` is astronomically large (or overflows),
and the next steps wander off (the MSL's HeatingNPN_NORGate stopped at 135 s of 200 on
its five-unknown transistor block). As established solvers do (the line search of
KINSOL and of Dennis and Schnabel's ``lnsrch``), a step ``t = base - lam d`` is taken
only where the squared residual norm ``n = sum r_i^2`` falls enough:
``n(lam) <= (1 - 2 ARMIJO lam) n(0)`` (``-2 n(0)`` is its slope at ``lam = 0`` along
the Newton direction); else ``lam`` shrinks to the minimum of the quadratic through
``n(0)``, that slope and ``n(lam)``, kept within ``[0.1 lam, 0.5 lam]``
(``0.1 lam`` where ``n(lam)`` is not finite). A point whose evaluation raises (the
Python backend: ``math.exp`` overflows, ``math.pow`` of a negative base) counts as
not finite.

Two guards keep the iterations that converged before as they were, bit for bit: a
step with every ``|d_k| <= SEARCHED_STEP (1 + |t_k|)`` is taken without the test (near
the solution the residual is rounding noise, and a noise-level "increase" must not
shrink a convergent step), and where ``lam`` would fall below :data:`LAMBDA_MIN` the
full step is taken, as before the line search. The convergence test is unchanged: it
reads the full step.

The statements (the loop of :meth:`.context.CodegenContext._nonlinear` and of its C
twin) are, per block ``i`` with tearing variables ``t_k``::

    _base_k = t_k; _d_k = 0; _lam = 0; _np = 0; _ls = False   (before the loop)
    loop:
        t_k = _base_k - _lam * _d_k                           (trial)
        inner assignments, residuals _r_k, _nr = sum _r_k^2   (Python: in a try)
        converged: break; no sufficient decrease: shrink _lam, continue
        _np = _nr; _base_k = t_k                              (accepted)
        Jacobian, _d_k = J^-1 r
        _lam = 1; _ls = some |_d_k| > SEARCHED_STEP (1 + |_base_k|); _done = ...
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir.expr import BinOp, Call, Const, Expr, Var, add, mul, sub
from .statements import Let, Loop, Raw, Stmt

ARMIJO = 1e-4
"""The sufficient decrease of the line search (KINSOL's and Dennis-Schnabel's alpha)."""

SHRINK = (0.1, 0.5)
"""Bounds of a backtrack's new ``lam`` relative to the one that failed."""

LAMBDA_MIN = 1e-4
"""Below this ``lam`` the search gives up and takes the full Newton step."""

SEARCHED_STEP = 1e-3
"""A Newton step is searched only where some ``|d_k|`` exceeds this times
``1 + |t_k|``."""

NEWTON_TOLERANCE = 1e-10
"""Converged: every Newton correction within this of ``1 + |t|`` (relative)."""


def search_start(tearing: Sequence[str], index: int) -> list[Stmt]:
    """Before the loop: the base point is the warm start, no direction yet."""
    out: list[Stmt] = []
    for k, t in enumerate(tearing):
        out.append(Let(f"_base{index}_{k}", Var(t)))
        out.append(Let(f"_d{index}_{k}", Const(0.0)))
    out += [Let(f"_lam{index}", Const(0.0)), Let(f"_np{index}", Const(0.0)),
            Let(f"_ls{index}", Const(False))]
    return out


def search_trial(tearing: Sequence[str], index: int) -> list[Stmt]:
    """The loop's first statements: the trial point ``base - lam d``."""
    return [Let(t, sub(Var(f"_base{index}_{k}"),
                       mul(Var(f"_lam{index}"), Var(f"_d{index}_{k}"))),
                f"{t} (Newton trial)")
            for k, t in enumerate(tearing)]


def residual_norm(index: int, count: int) -> Let:
    """``_nr = sum r_k^2`` of block ``index``'s ``count`` residuals."""
    total: Expr | None = None
    for k in range(count):
        r = Var(f"_r{index}_{k}")
        total = mul(r, r) if total is None else add(total, mul(r, r))
    assert total is not None
    return Let(f"_nr{index}", total, "squared residual norm")


def guarded(part: list[Stmt], index: int, python: bool) -> list[Stmt]:
    """``part`` (the trial's evaluation); in Python inside a ``try`` whose arithmetic
    errors make the norm infinite while a search is on, else are raised as before."""
    if not python:
        return part
    handler = (f"except (ArithmeticError, ValueError):\n"
               f"    if not _ls{index}:\n"
               f"        raise\n"
               f"    _nr{index} = math.inf\n"
               f"    _done{index} = False")
    return [Loop("try:", part), Raw(handler)]


def search_control(index: int, c: bool) -> Raw:
    """Leave the loop when converged; backtrack (``continue``) when the trial's
    residual did not fall enough."""
    lo, hi = SHRINK
    i = index
    quadratic = f"_np{i} * _lam{i} * _lam{i} / (_nr{i} - _np{i} + 2.0 * _np{i} * _lam{i})"
    if c:
        return Raw(
            f"if (_done{i} != 0.0) {{\n    _ok{i} = 1;\n    break;\n}}\n"
            f"if (_ls{i} != 0.0 && !(_nr{i} <= (1.0 - {2 * ARMIJO!r} * _lam{i}) * _np{i})) {{\n"
            f"    if (_lam{i} > {LAMBDA_MIN!r}) {{\n"
            f"        double _q{i} = _nr{i} - _nr{i} == 0.0 ? {quadratic} : 0.0;\n"
            f"        _lam{i} = fmin(fmax(_q{i}, {lo!r} * _lam{i}), {hi!r} * _lam{i});\n"
            f"    }} else {{\n        _lam{i} = 1.0;\n        _ls{i} = 0.0;\n    }}\n"
            f"    continue;\n}}")
    return Raw(
        f"if _done{i}:\n    _ok{i} = True\n    break\n"
        f"if _ls{i} and not (_nr{i} <= (1.0 - {2 * ARMIJO!r} * _lam{i}) * _np{i}):\n"
        f"    if _lam{i} > {LAMBDA_MIN!r}:\n"
        f"        _q{i} = {quadratic} if _nr{i} < math.inf else 0.0\n"
        f"        _lam{i} = min(max(_q{i}, {lo!r} * _lam{i}), {hi!r} * _lam{i})\n"
        f"    else:\n        _lam{i} = 1.0\n        _ls{i} = False\n"
        f"    continue")


def search_accept(tearing: Sequence[str], index: int) -> list[Stmt]:
    """The trial is the new base point (before its Jacobian is evaluated)."""
    out: list[Stmt] = [Let(f"_np{index}", Var(f"_nr{index}"))]
    out += [Let(f"_base{index}_{k}", Var(t)) for k, t in enumerate(tearing)]
    return out


def search_step(tearing: Sequence[str], index: int) -> list[Stmt]:
    """After the correction ``_d_k`` is solved: the full step is the next trial,
    searched where it is large, and ``_done`` where every correction is within
    :data:`NEWTON_TOLERANCE` of ``1 + |t|`` at the stepped point."""
    done: Expr | None = None
    large: Expr | None = None
    for k in range(len(tearing)):
        base, d = Var(f"_base{index}_{k}"), Var(f"_d{index}_{k}")
        size = Call("abs", (d,))
        small = BinOp("<=", size, mul(Const(NEWTON_TOLERANCE),
                                      add(Const(1.0), Call("abs", (sub(base, d),)))))
        big = BinOp(">", size, mul(Const(SEARCHED_STEP),
                                   add(Const(1.0), Call("abs", (base,)))))
        done = small if done is None else BinOp("and", done, small)
        large = big if large is None else BinOp("or", large, big)
    assert done is not None and large is not None
    return [Let(f"_lam{index}", Const(1.0)), Let(f"_ls{index}", large),
            Let(f"_done{index}", done)]
