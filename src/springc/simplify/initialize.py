"""Initialization: ode.ODE + parameter values -> consistent initial states.

The initial problem (Modelica 8.6) is built from ``fixed = true`` start values and
``initial equation`` sections:

1. A state with a fixed start value takes it.
2. The *conditions* are the initial equations and the fixed start values of
   variables that are not states (algebraic variables, dummy derivatives); each is a
   residual evaluated by running the ODE's steps (:class:`~springc.evaluate_ode.OdeEvaluator`).
3. The conditions choose which of the other states they determine: the columns of
   their Jacobian with respect to those states (at the start values) picked by
   QR with column pivoting. States not chosen keep their ``start`` (default 0), as
   Modelica tools do when the problem is underdetermined.
4. The chosen states are solved with ``scipy.optimize.root`` from their start values.
5. Conditions whose Jacobian rows depend on the others' (redundant: ``x = 1`` and
   ``2*x = 2``, or more conditions than free states) are left out of steps 3 and 4, as
   the established tools do, and checked at the solution: where they hold, a
   :class:`RedundantInitialWarning` names them; where one does not, the problem is
   inconsistent (an :class:`InitializationError`).

Values the steps compute (algebraic variables, and the derivatives chosen as dummies
by index reduction) are consistent by construction, since the steps are run.
Redundant conditions that do not hold at the solution (over-determined, or singular
and inconsistent) are an :class:`InitializationError` naming the user's variables and
equations with their locations.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import Note, SimulationError, Span, SpringcError
from ..ir import expr as x
from ..ir import ode
from .ode_eval import OdeEvaluator, parameter_values, start_values


class InitializationError(SpringcError):
    """The initial problem is over- or under-determined, or has no solution."""


class RedundantInitialWarning(UserWarning):
    """Initial conditions that the others determine were left out (they hold);
    ``conditions`` are those left out, with where the model states them."""

    def __init__(self, message: str, conditions: tuple[Condition, ...] = ()) -> None:
        super().__init__(message)
        self.conditions = conditions


@dataclass(frozen=True, slots=True)
class Condition:
    """One equation of the initial problem: ``residual = 0`` (user text at ``span``)."""

    text: str
    residual: x.Expr
    span: Span | None


@dataclass(frozen=True)
class InitialInfo:
    """What initialization found: ``values`` holds every parameter, state, algebraic
    variable and derivative at ``t0``, ``observed`` the aliases; ``solved`` the states
    determined by the conditions, ``fixed`` those with a fixed start, ``defaulted`` the
    states that took their start value; ``residual`` the largest condition residual;
    ``dropped`` the redundant conditions left out of the solve (they hold)."""

    values: dict[str, float]
    observed: dict[str, float]
    conditions: tuple[Condition, ...]
    solved: tuple[str, ...]
    fixed: tuple[str, ...]
    defaulted: tuple[str, ...]
    residual: float
    dropped: tuple[Condition, ...] = ()


def conditions(model: ode.ODE, starts: Mapping[str, float] | None = None
               ) -> tuple[Condition, ...]:
    """The conditions of step 2 of the module docstring; ``starts`` replaces the start
    values of those it names (set at run time: ``--set``)."""
    state_names = {s.name for s in model.states}
    # fixed = true on a variable that pre() reads sets its pre value (section 8.6):
    # the value held before the first event, not a condition on the continuous start
    held = set(model.events.pre) if model.events is not None else set()
    out = [Condition(r.describe(), r.expr, r.span) for r in model.dae.initial_equations]
    given = starts or {}
    for u in model.dae.unknowns:
        if u.fixed and u.start is not None and u.name not in state_names \
                and u.name not in held:
            start = x.Const(float(given[u.name])) if u.name in given else u.start
            out.append(Condition(f"{u.name} = {x.to_text(start)} (fixed start value)",
                                 x.sub(x.Var(u.name), start), u.span))
    return tuple(out)


def initial_state(model: ode.ODE, parameters: Mapping[str, float] | None = None,
                  t0: float = 0.0, tol: float = 1e-9,
                  starts: Mapping[str, float] | None = None) -> tuple[np.ndarray, InitialInfo]:
    """Consistent initial values of ``model.states`` (in that order) at ``t0``.

    ``parameters`` overrides parameter values (others come from their bindings),
    ``starts`` start values (a fixed one is then the initial value, a free one the
    guess the solve starts from). Raises :class:`InitializationError`
    (over-/under-determined, no convergence).
    """
    params = parameter_values(model.parameters, parameters)
    evaluator = OdeEvaluator(model, params, initial=True)
    values = start_values(model.dae.unknowns, params)
    values.update((k, float(v)) for k, v in (starts or {}).items())
    x0 = np.array([values.get(s.name, 0.0) for s in model.states])
    fixed = [i for i, s in enumerate(model.states) if s.fixed and s.start is not None]
    free = [i for i, s in enumerate(model.states) if i not in set(fixed)]
    conds = conditions(model, starts)

    def residuals(z: np.ndarray, chosen: list[int]) -> np.ndarray:
        trial = x0.copy()
        trial[chosen] = z
        env = evaluator.values(t0, trial)
        return np.array([float(x.evaluate(c.residual, env, t0, True)) for c in conds])

    chosen: list[int] = []
    dropped: tuple[Condition, ...] = ()
    if conds:
        _check_evaluable(model, conds, evaluator, x0, t0)
        chosen, kept = _choose_states(conds, free, x0, lambda z, c: residuals(z, c))
        regular = _regular_elsewhere(model, conds, free, x0, residuals, tol) \
            if len(kept) < len(conds) <= len(free) else None
        if regular is not None:  # singular at the start values only: nothing dropped
            chosen, kept = regular, list(range(len(conds)))
        dropped = tuple(c for i, c in enumerate(conds) if i not in set(kept))
        if chosen:
            x0[chosen] = _solve(model, tuple(conds[i] for i in kept), chosen, x0,
                                lambda z: residuals(z, chosen)[kept], tol)
        if dropped:
            _check_redundant(model, conds, kept, residuals(x0[chosen], chosen), x0,
                             (fixed, free))
    env = evaluator.values(t0, x0)
    worst = max((abs(float(x.evaluate(c.residual, env, t0, True))) for c in conds),
                default=0.0)
    names = [s.name for s in model.states]
    info = InitialInfo(env, evaluator.observed(env, t0), conds,
                       tuple(names[i] for i in chosen), tuple(names[i] for i in fixed),
                       tuple(names[i] for i in free if i not in chosen), worst, dropped)
    return x0, info


def _check_evaluable(model: ode.ODE, conds: tuple[Condition, ...], evaluator: OdeEvaluator,
                     x0: np.ndarray, t0: float) -> None:
    env = evaluator.values(t0, x0)
    for c in conds:
        try:
            x.evaluate(c.residual, env, t0, True)
        except x.NotEvaluable as err:
            raise InitializationError(f"the initial equation cannot be evaluated: {err}",
                                      c.span, [], "springc evaluates initial equations "
                                      "numerically at the start time") from None
        except KeyError as err:
            raise InitializationError(
                f"the initial equation uses {err}, which the simplified model does not "
                f"compute", c.span, [], "initial equations may use variables and the "
                "derivatives of variables that appear differentiated in the model") from None


def _jacobian(n: int, free: list[int], x0: np.ndarray,
              residuals: Callable[[np.ndarray, list[int]], np.ndarray]) -> np.ndarray:
    """The finite-difference Jacobian of the ``n`` residuals on the ``free`` states."""
    base = residuals(x0[free], free)
    jac = np.zeros((n, len(free)))
    for j in range(len(free)):
        z = x0[free].copy()
        h = 1e-7 * max(1.0, abs(z[j]))
        z[j] += h
        jac[:, j] = (residuals(z, free) - base) / h
    return jac


def _regular_elsewhere(model: ode.ODE, conds: tuple[Condition, ...], free: list[int],
                       x0: np.ndarray,
                       residuals: Callable[[np.ndarray, list[int]], np.ndarray], tol: float
                       ) -> list[int] | None:
    """Conditions whose Jacobian is singular at the start values only (nonlinear ones
    at a degenerate start, LightningImpulse's ``eta``, ``T``, ``tau1``...): solved all
    together for the states of the pivoted columns; those states where the Jacobian
    has full rank at the solution (then nothing is redundant), else None."""
    import scipy.linalg

    _, _, perm = scipy.linalg.qr(_scaled(_jacobian(len(conds), free, x0, residuals)),
                                 pivoting=True, mode="economic")
    chosen = sorted(free[j] for j in perm[:len(conds)])
    try:
        z = _solve(model, conds, chosen, x0, lambda z: residuals(z, chosen), tol)
    except InitializationError:
        return None
    trial = x0.copy()
    trial[chosen] = z
    if _rank(_jacobian(len(conds), free, trial, residuals)) < len(conds):
        return None
    return chosen


def _choose_states(conds: tuple[Condition, ...], free: list[int], x0: np.ndarray,
                   residuals: Callable[[np.ndarray, list[int]], np.ndarray]
                   ) -> tuple[list[int], list[int]]:
    """Steps 3 and 5: the free states the conditions determine and the conditions kept
    (QR with column pivoting on a finite-difference Jacobian at the start values, of
    its transpose where its rank is below the number of conditions)."""
    import scipy.linalg

    jac = _scaled(_jacobian(len(conds), free, x0, residuals))
    kept = list(range(len(conds)))
    rank = _rank(jac)
    if rank < len(conds):
        _, _, rows = scipy.linalg.qr(jac.T, pivoting=True, mode="economic")
        kept = sorted(int(i) for i in rows[:rank])
    if not kept:
        return [], []
    _, _, perm = scipy.linalg.qr(jac[kept], pivoting=True, mode="economic")
    return sorted(free[j] for j in perm[:len(kept)]), kept


def _scaled(jac: np.ndarray) -> np.ndarray:
    """``jac`` with each row, then each column, scaled to a largest entry of 1 (zero
    ones left): conditions and states of any magnitude (a time constant of 1e-5 s
    beside an amplitude factor of 1) count alike in the rank decisions."""
    out = np.array(jac, dtype=float)
    if out.size == 0:
        return out
    rows = np.abs(out).max(axis=1, keepdims=True)
    out /= np.where(rows > 0, rows, 1.0)
    cols = np.abs(out).max(axis=0, keepdims=True)
    out /= np.where(cols > 0, cols, 1.0)
    return out


def _rank(jac: np.ndarray) -> int:
    """The numerical rank of ``jac`` (scaled: relative threshold 1e-6 on R's
    diagonal)."""
    import scipy.linalg

    jac = _scaled(jac)
    if jac.size == 0:
        return 0
    r = scipy.linalg.qr(jac, pivoting=True, mode="r")[0]
    diag = np.abs(np.diag(r))
    return int(np.sum(diag > 1e-6 * max(1.0, diag[0] if diag.size else 1.0)))


def _check_redundant(model: ode.ODE, conds: tuple[Condition, ...], kept: list[int],
                     values: np.ndarray, x0: np.ndarray,
                     fixed_free: tuple[list[int], list[int]]) -> None:
    """Step 5: the conditions left out must hold at the solution (``values`` are all
    the residuals there); a warning names them, an error the first that does not."""
    limit = 1e-6 * (1.0 + float(np.abs(x0).max(initial=0.0)))
    left = [i for i in range(len(conds)) if i not in set(kept)]
    wrong = [i for i in left if not abs(values[i]) <= limit]
    if wrong:
        fixed, free = fixed_free
        if len(conds) > len(free):
            raise _overdetermined(model, conds, fixed, free)
        raise _inconsistent(model, conds, len(kept), [(conds[i], values[i]) for i in wrong])
    names = "; ".join(conds[i].text for i in left[:5]) + ("; ..." if len(left) > 5 else "")
    warnings.warn(RedundantInitialWarning(
        f"{model.dae.name}: {len(left)} redundant initial condition(s) left out, "
        f"consistent with the others: {names}", tuple(conds[i] for i in left)), stacklevel=3)


def _solve(model: ode.ODE, conds: tuple[Condition, ...], chosen: list[int], x0: np.ndarray,
           residuals: Callable[[np.ndarray], np.ndarray], tol: float) -> np.ndarray:
    """Step 4: Newton-type solve (MINPACK hybrid) from the start values."""
    import scipy.optimize

    def safe(z: np.ndarray) -> np.ndarray:
        try:
            return np.asarray(residuals(z), dtype=float)
        except (SimulationError, ArithmeticError, ValueError):
            return np.full(len(conds), 1e10)

    result = scipy.optimize.root(safe, x0[chosen], method="hybr", options={"xtol": 1e-12})
    if not np.all(np.abs(safe(result.x)) <= tol * (1 + np.abs(x0[chosen]).max())):
        lsq = scipy.optimize.least_squares(safe, x0[chosen], xtol=1e-14, ftol=1e-14)
        if np.all(np.abs(safe(lsq.x)) <= tol * (1 + np.abs(lsq.x).max())):
            return np.asarray(lsq.x, dtype=float)
        names = ", ".join(f"'{model.states[i].name}'" for i in chosen)
        raise InitializationError(
            f"the initial equations have no solution near the start values of {names}",
            conds[0].span, [Note(f"condition: {c.text}", c.span) for c in conds[:10]],
            "check the initial equations and start values for consistency")
    return np.asarray(result.x, dtype=float)


def _overdetermined(model: ode.ODE, conds: tuple[Condition, ...], fixed: list[int],
                    free: list[int]) -> InitializationError:
    notes = [Note(f"condition: {c.text}", c.span) for c in conds[:10]]
    notes += [Note(f"'{model.states[i].name}' has a fixed start value", model.states[i].span)
              for i in fixed[:10]]
    return InitializationError(
        f"the initialization problem is over-determined: {len(conds)} initial conditions "
        f"for {len(free)} state(s) without a fixed start value", model.dae.span, notes,
        "remove an initial equation or a `fixed = true`")


def _inconsistent(model: ode.ODE, conds: tuple[Condition, ...], rank: int,
                  wrong: list[tuple[Condition, float]]) -> InitializationError:
    notes = [Note(f"condition: {c.text} (residual {r:.3g} at the solution of the others)",
                  c.span) for c, r in wrong[:10]]
    return InitializationError(
        f"the initialization problem is singular: {len(conds)} initial conditions "
        f"determine only {rank} state(s), and the redundant ones do not hold",
        wrong[0][0].span, notes,
        "remove the redundant initial equations or `fixed = true` attributes")
