"""Reference evaluation of an ode.ODE: parameters, start values and the right-hand side.

A slow but simple interpreter over :func:`springc.expr.evaluate`, used by
initialization, by state selection (numeric checks at start values) and by tests as
an independent check of generated code. ``OdeEvaluator.rhs(t, x)`` runs ``ode.steps`` in
order: assignments, linear systems (dense, or sparse LU when large) and torn
nonlinear systems (Newton on the tearing variables with the analytic Jacobian,
starting from the previous solution, or from start values the first time).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping

import numpy as np

from ..errors import Note, SimplifyError, SimulationError, describe_failure
from ..ir import dae, ode
from ..ir import expr as x

SPARSE_FROM = 50
"""Linear systems with at least this many unknowns are solved with sparse LU."""


def parameter_values(parameters: Iterable[dae.Parameter],
                     overrides: Mapping[str, float] | None = None) -> dict[str, float]:
    """Numeric values of all parameters: ``overrides``, else the binding, else the
    start value, else 0; bindings may refer to other parameters (in any order)."""
    values = _ParameterValues({p.name: p for p in parameters}, dict(overrides or {}))
    for name in values.params:
        values.value(name)
    return values.values


class _ParameterValues:
    """:func:`parameter_values`'s work: an object, not a recursive closure, which would
    be a reference cycle (closure -> its cell -> closure) holding the parameters, left
    to the collector, paused while a model compiles (springc.collector)."""

    def __init__(self, params: dict[str, dae.Parameter], values: dict[str, float]) -> None:
        self.params, self.values = params, values
        self.active: set[str] = set()

    def value(self, name: str) -> float:
        values = self.values
        if name in values:
            return values[name]
        p = self.params[name]
        if name in self.active:
            raise SimplifyError(f"the binding of parameter '{name}' depends on itself", p.span)
        self.active.add(name)
        e = p.binding if p.binding is not None else p.start
        try:
            # Parameters are computed in initialization: initial() holds.
            values[name] = 0.0 if e is None else evaluate_with(e, self.value, initial=True)
        except (ArithmeticError, ValueError) as err:
            raise SimplifyError(f"the value of parameter '{name}' cannot be computed: "
                                f"{describe_failure(err)}", p.span,
                                hint="check the parameters its binding uses (--set)"
                                ) from None
        self.active.discard(name)
        return values[name]


class _Lazy(dict[str, float]):
    def __init__(self, lookup: Callable[[str], float]) -> None:
        super().__init__()
        self.lookup = lookup

    def __missing__(self, key: str) -> float:
        self[key] = result = self.lookup(key)
        return result


def evaluate_with(e: x.Expr, lookup: Callable[[str], float], time: float = 0.0,
                  initial: bool | None = None) -> float:
    """Evaluate ``e``, asking ``lookup(name)`` for each variable it needs (``initial``:
    whether ``initial()`` holds, see :func:`springc.ir.expr.evaluate`)."""
    return float(x.evaluate(e, _Lazy(lookup), time, initial))


def start_values(unknowns: Iterable[dae.Unknown], params: Mapping[str, float]
                 ) -> dict[str, float]:
    """The start value of every unknown (0 when not given), from parameter values."""
    out = {}
    for u in unknowns:
        try:
            value = 0.0 if u.start is None else float(x.evaluate(u.start, params,
                                                                 initial=True))
        except KeyError as err:
            raise SimplifyError(f"the start value of '{u.name}' must be a parameter "
                                f"expression, but it uses {err}", u.span) from None
        except (ArithmeticError, ValueError) as err:
            raise SimplifyError(f"the start value of '{u.name}' cannot be computed: "
                                f"{describe_failure(err)}", u.span,
                                hint="check the parameters it uses (--set)") from None
        if not math.isfinite(value):
            raise SimplifyError(f"the start value of '{u.name}' is {value}", u.span,
                                hint="check the parameters it uses (--set)")
        out[u.name] = value
    return out


class OdeEvaluator:
    """Evaluates the steps of ``model`` for given parameter values.

    ``initial``: the evaluation is that of initialization (``initial()`` holds).
    ``guess`` (by name) overrides the start values as the first Newton guess of the
    tearing variables: after a switch of states, the current values keep Newton on the
    branch the simulation is on (e.g. the sign of a coordinate solved from a length).
    """

    def __init__(self, model: ode.ODE, params: Mapping[str, float],
                 newton_tol: float = 1e-10, max_iterations: int = 50,
                 guess: Mapping[str, float] | None = None, initial: bool = False) -> None:
        self.model = model
        self.initial = initial  # evaluating in initialization: initial() holds
        self.params = dict(params)
        self.names = [s.name for s in model.states]
        self.derivatives = [s.derivative for s in model.states]
        self.guess = start_values(model.dae.unknowns, self.params)
        self.held = self._held_starts(model, self.guess)
        self.guess.update(guess or {})
        self.newton_tol = newton_tol
        self.max_iterations = max_iterations

    def _held_starts(self, model: ode.ODE, starts: Mapping[str, float]
                     ) -> dict[str, float]:
        """The discrete variables and the ``pre`` values at their start values, as
        they are before the first event (``pre(v)`` is read as ``env['pre(v)']``)."""
        if model.events is None:
            return {}
        held: dict[str, float] = {}
        for d in model.events.discrete:
            try:
                held[d.name] = 0.0 if d.start is None else float(
                    x.evaluate(d.start, self.params, initial=True))
            except (KeyError, ArithmeticError, ValueError):
                continue  # a start value that is not a parameter expression: unknown
        for name in model.events.pre:
            held[f"pre({name})"] = held.get(name, starts.get(name, 0.0))
        return held

    def values(self, t: float, states: Iterable[float]) -> dict[str, float]:
        """All parameters, states and step variables at time ``t``; a step that leaves
        the domain of an operation raises :class:`SimulationError` naming it."""
        env: dict[str, float] = dict(self.params)
        env.update(self.held)
        env.update(zip(self.names, (float(v) for v in states)))
        for step in self.model.steps:
            try:
                if isinstance(step, ode.Assign):
                    env[step.name] = float(x.evaluate(step.expr, env, t, self.initial))
                elif isinstance(step, ode.LinearBlock):
                    self._linear(step, env, t)
                else:
                    self._newton(step, env, t)
            except (ArithmeticError, ValueError) as err:
                names = ([step.name] if isinstance(step, ode.Assign) else
                         list(step.names) if isinstance(step, ode.LinearBlock) else
                         list(step.tearing))
                span = step.span if isinstance(step, ode.Assign) else step.spans[0]
                raise SimulationError(
                    f"{describe_failure(err)} while computing {', '.join(names[:4])} at "
                    f"t = {t:g}", span, hint="the model leaves the domain of an operation "
                    "there; check the parameters (--set) and start values") from None
        return env

    def rhs(self, t: float, states: Iterable[float]) -> np.ndarray:
        """The state derivatives, in the order of ``model.states``."""
        env = self.values(t, states)
        return np.array([env[d] for d in self.derivatives])

    def observed(self, env: Mapping[str, float], t: float = 0.0) -> dict[str, float]:
        """The eliminated aliases, from a ``values`` result."""
        return {a.name: float(x.evaluate(a.expr, env, t, self.initial))
                for a in self.model.observed}

    def _linear(self, step: ode.LinearBlock, env: dict[str, float], t: float) -> None:
        n = len(step.names)
        rows = [r for r, _, _ in step.matrix]
        cols = [c for _, c, _ in step.matrix]
        data = [float(x.evaluate(e, env, t, self.initial)) for _, _, e in step.matrix]
        b = np.array([float(x.evaluate(e, env, t, self.initial)) for e in step.rhs])
        try:
            if n >= SPARSE_FROM:
                from scipy.sparse import csc_matrix
                from scipy.sparse.linalg import spsolve
                solution = spsolve(csc_matrix((data, (rows, cols)), shape=(n, n)), b)
                if not np.all(np.isfinite(solution)):
                    raise np.linalg.LinAlgError
            else:
                a = np.zeros((n, n))
                np.add.at(a, (rows, cols), data)
                solution = np.linalg.solve(a, b)
        except np.linalg.LinAlgError:
            raise SimulationError(
                f"the linear system for {', '.join(step.names[:6])} is singular at t = {t:g}",
                step.spans[0] if step.spans else None,
                [Note("equation of the system", s) for s in step.spans[1:6]]) from None
        env.update(zip(step.names, solution.tolist()))

    def _newton(self, step: ode.NonlinearBlock, env: dict[str, float], t: float) -> None:
        z = np.array([self.guess.get(n, 0.0) for n in step.tearing])
        n = len(z)
        for _ in range(self.max_iterations):
            env.update(zip(step.tearing, z.tolist()))
            for a in step.inner + step.sensitivities:
                env[a.name] = float(x.evaluate(a.expr, env, t, self.initial))
            f = np.array([float(x.evaluate(r, env, t, self.initial)) for r in step.residuals])
            jac = np.zeros((n, n))
            for i, j, e in step.jacobian:
                jac[i, j] = float(x.evaluate(e, env, t, self.initial))
            try:
                dz = np.linalg.solve(jac, -f)
            except np.linalg.LinAlgError:
                break
            z = z + dz
            if np.max(np.abs(dz)) <= self.newton_tol * (1 + np.max(np.abs(z))):
                env.update(zip(step.tearing, z.tolist()))
                for a in step.inner:
                    env[a.name] = float(x.evaluate(a.expr, env, t, self.initial))
                self.guess.update(zip(step.tearing, z.tolist()))
                return
        raise SimulationError(
            f"the nonlinear system for {', '.join(step.tearing)} did not converge at "
            f"t = {t:g}", step.spans[0] if step.spans else None,
            [Note("equation of the system", s) for s in step.spans[1:6]])
