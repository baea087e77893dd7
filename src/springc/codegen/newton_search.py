"""The backtracking of the Newton iterations of torn blocks, in generated Python,
numba and C code: a Newton step that lands where the block cannot be evaluated is
shortened.

Newton's full step from a point far from the solution can overshoot: on a diode's
exponential, from a warm start on the flat side of its knee, it lands where ``exp``
overflows (numba and C: ``inf``, then NaN; Python: ``OverflowError``), and before this
search the iteration was lost (NaN from then on, "did not converge"). Now a trial
point ``t = base - lam d`` whose squared residual norm ``sum r_i^2`` is not finite,
or whose evaluation raises an arithmetic or domain error (the Python backend:
``math.exp`` overflows, ``math.pow`` of a negative base, ``math.log`` of a negative
number), is retried with ``lam`` 10 times smaller (KINSOL's and Dennis and
Schnabel's smallest backtracking factor, the one they take where the trial tells
nothing about the residual's shape), down to :data:`LAMBDA_MIN`; below it the full
step is taken, as before, and fails as before. A block that does not converge
ends on its warm start (:func:`search_end`), not on its last iterate.

Why not Armijo's sufficient decrease on the residual norm (KINSOL's line search)?
It was tried (2026-11-28, branch semi) and made the MSL's HeatingNPN_NORGate fail
earlier (55.5 s instead of 135 s of 200): the block mixes residuals in watts and in
amperes, the full step (exact Jacobian, checked by differences) raises the unscaled
norm 10^4-fold and still converges undamped, while the damped iteration crept by
1 % steps and used up the 200 iterations. Only steps that undamped Newton cannot
survive are shortened, so every block that converged before converges through the
same iterates, bit for bit.

The statements (the loop of :meth:`.context.CodegenContext._nonlinear` and of its C
twin) are, per block ``i`` with tearing variables ``t_k``::

    _base_k = _warm_k = t_k; _d_k = 0; _lam = 0; _ls = False  (before the loop)
    loop:
        t_k = _base_k - _lam * _d_k                           (trial)
        inner assignments, residuals _r_k, _nr = sum _r_k^2   (Python: in a try)
        converged: break; _nr not finite while _ls: shrink _lam, continue
        _base_k = t_k                                         (accepted)
        Jacobian, _d_k = J^-1 r
        _lam = 1; _ls = True; _done = every |_d_k| small
    t_k = t_k if _ok else _warm_k                             (after the loop)
"""

from __future__ import annotations

from collections.abc import Sequence

from ..ir.expr import BinOp, Call, Const, Expr, If, Var, add, mul, sub
from .statements import Let, Loop, Raw, Stmt

SHRINK = 0.1
"""A backtrack's new ``lam`` relative to the one whose trial was not finite."""

LAMBDA_MIN = 1e-6
"""Below this ``lam`` the search gives up and takes the full Newton step (a trial
``lam`` = 1e-6 of a step is within rounding of the base point for the usual steps)."""

NEWTON_TOLERANCE = 1e-10
"""Converged: every Newton correction within this of ``1 + |t|`` (relative)."""


def search_start(tearing: Sequence[str], index: int) -> list[Stmt]:
    """Before the loop: the base point is the warm start, no direction yet."""
    out: list[Stmt] = []
    for k, t in enumerate(tearing):
        out.append(Let(f"_base{index}_{k}", Var(t)))
        out.append(Let(f"_warm{index}_{k}", Var(t)))
        out.append(Let(f"_d{index}_{k}", Const(0.0)))
    out += [Let(f"_lam{index}", Const(0.0)), Let(f"_ls{index}", Const(False))]
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
    """Leave the loop when converged; backtrack (``continue``) from a trial whose
    residual norm is not finite."""
    i = index
    if c:
        return Raw(
            f"if (_done{i} != 0.0) {{\n    _ok{i} = 1;\n    break;\n}}\n"
            f"if (_ls{i} != 0.0 && !(_nr{i} - _nr{i} == 0.0)) {{\n"
            f"    if (_lam{i} > {LAMBDA_MIN!r}) {{\n        _lam{i} = {SHRINK!r} * _lam{i};\n"
            f"    }} else {{\n        _lam{i} = 1.0;\n        _ls{i} = 0.0;\n    }}\n"
            f"    continue;\n}}")
    return Raw(
        f"if _done{i}:\n    _ok{i} = True\n    break\n"
        f"if _ls{i} and not (_nr{i} - _nr{i} == 0.0):\n"
        f"    if _lam{i} > {LAMBDA_MIN!r}:\n        _lam{i} = {SHRINK!r} * _lam{i}\n"
        f"    else:\n        _lam{i} = 1.0\n        _ls{i} = False\n"
        f"    continue")


def search_accept(tearing: Sequence[str], index: int) -> list[Stmt]:
    """The trial is the new base point (before its Jacobian is evaluated)."""
    return [Let(f"_base{index}_{k}", Var(t)) for k, t in enumerate(tearing)]


def search_step(tearing: Sequence[str], index: int) -> list[Stmt]:
    """After the correction ``_d_k`` is solved: the full step is the next trial, and
    ``_done`` where every correction is within :data:`NEWTON_TOLERANCE` of
    ``1 + |t|`` at the stepped point (the test of the iteration before the search)."""
    done: Expr | None = None
    for k in range(len(tearing)):
        base, d = Var(f"_base{index}_{k}"), Var(f"_d{index}_{k}")
        small = BinOp("<=", Call("abs", (d,)), mul(Const(NEWTON_TOLERANCE),
                      add(Const(1.0), Call("abs", (sub(base, d),)))))
        done = small if done is None else BinOp("and", done, small)
    assert done is not None
    return [Let(f"_lam{index}", Const(1.0)), Let(f"_ls{index}", Const(True)),
            Let(f"_done{index}", done)]


def search_end(tearing: Sequence[str], index: int) -> list[Stmt]:
    """After the loop: where the block did not converge, its tearing variables go back
    to the warm start, so that the next call (the step retried smaller) starts from
    the last point that converged, not from where the iteration wandered off."""
    return [Let(t, If(Var(f"_ok{index}"), Var(t), Var(f"_warm{index}_{k}")),
                f"{t} (warm start kept where not converged)")
            for k, t in enumerate(tearing)]
