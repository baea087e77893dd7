"""The contract of a generated module: what :func:`springc.codegen.generate` writes and
what the pipeline, the simulator and the tradeoff study read.

``GeneratedModule`` is a Protocol over module attributes; the pipeline checks
``MODULE_NAMES`` on import (a module missing one is not a springc module of this
version) and then treats the module as a ``GeneratedModule``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

CODEGEN_VERSION = 15
"""The version of the generated code's layout and of a cache entry's contents: part of
every cache key (here, not with the module text, so that the cache reads it without
loading the generator). 5: a cache entry holds the captured system (``system.pickle``,
:mod:`springc.pipeline.closed`); 6: a module declares its ``KIND``; 7: a module declares
``PARAMETER_BOUNDS``; 9: torn blocks take ``_newton_solve`` (``codegen.newton_step``);
10: relations switch past a band (``codegen.hysteresis``; slots ``_zb``, ``_zw``,
``_zpass``); 11: the Newton iterations of torn blocks search their steps
(``codegen.newton_search``); 15: a when-clause branch's assignments under one guard
(``codegen.statements.Guard``)."""


JACOBIAN_LIMIT = 2000
"""Non-zeros of the largest Jacobian printed in C (``codegen.c_model``). The 10 x 10
cloth's 3,300 take 2.5 MB of C in one function, and the C compiler minutes at -O2 (about
30 s of CPU without it); integrators of the C model (FMI's, the GPU's explicit methods)
work without. Here, with the module contract, so that the pipeline knows a model the C
loop refuses from its module alone (``pipeline.c_kernels.known_refusal``)."""


class ModuleKind:
    """What a generated module declares as ``KIND``: the driver that runs it
    (``springc.simulation.runner.DRIVERS``)."""

    CONTINUOUS = "continuous"  # an ODE: the step loop, auto's race, the compiled loops
    HYBRID = "hybrid"  # events (a HybridModule): the event loop
    DELAY = "delay"  # delay(...) calls: the history of the delayed expressions
    SWITCHING = "switching"  # dynamic state selection: states that switch in a run
    ALL = (CONTINUOUS, HYBRID, DELAY, SWITCHING)

    @staticmethod
    def of(events: bool, delays: int, switchable: bool) -> str:
        """The kind of a module with ``events``, ``delays`` delay calls and
        ``switchable`` states (delay calls first: a model with events and delays is
        refused by that driver)."""
        if delays:
            return ModuleKind.DELAY
        if events:
            return ModuleKind.HYBRID
        return ModuleKind.SWITCHING if switchable else ModuleKind.CONTINUOUS


class GeneratedModule(Protocol):
    """A generated module: constants over the state vector ``x``, the parameter vector
    ``p`` and the Newton warm starts ``z`` (last entry: failure flag), and functions."""

    MODEL: str
    BACKEND: str
    CODEGEN_VERSION: int
    KIND: str  # one of ModuleKind.ALL: the driver that runs it
    STATES: tuple[str, ...]
    STATE_UNITS: tuple[str, ...]
    DERIVATIVES: tuple[str, ...]
    PARAMETERS: tuple[str, ...]
    PARAMETER_UNITS: tuple[str, ...]
    PARAMETER_TYPES: tuple[str, ...]
    #: per parameter, its declared (min, max) where they are numbers (None: not declared)
    PARAMETER_BOUNDS: tuple[tuple[float | None, float | None], ...]
    STRUCTURAL: tuple[str, ...]
    OBSERVED: tuple[str, ...]
    OBSERVED_UNITS: tuple[str, ...]
    GUESSES: tuple[str, ...]
    DESCRIPTIONS: tuple[str, ...]  # name, description, name, ... (those with one)
    NEWTON_SYSTEMS: dict[int, tuple[str, ...]]
    EXPERIMENT: dict[str, Any]  # start, stop, interval, tolerance: float or None
    INITIAL_CONDITIONS: int
    SWITCHABLE: bool
    WARNINGS: tuple[str, ...]  # diagnostics that are not errors, as the pipeline wrote them
    JAC_ROWS: IntArray
    JAC_COLS: IntArray
    JAC_INDICES: IntArray
    JAC_INDPTR: IntArray
    EVENTS: bool  # a hybrid module: it has the names of HybridModule too
    # message, level, location, params only, caret width
    ASSERTIONS: tuple[tuple[str, str, str, bool, int], ...]

    def parameters(self, values: Mapping[str, float] | None = None) -> FloatArray: ...

    def start(self, p: FloatArray) -> FloatArray: ...

    def guesses(self, p: FloatArray) -> FloatArray: ...

    def rhs(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray) -> FloatArray: ...

    def jacobian_values(self, t: float, x: FloatArray, p: FloatArray,
                        z: FloatArray) -> FloatArray: ...

    def jacobian(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray) -> Any: ...

    def jacobian_dense(self, t: float, x: FloatArray, p: FloatArray,
                       z: FloatArray) -> FloatArray: ...

    def sparsity(self) -> Any: ...

    def observed(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray) -> FloatArray: ...

    def observed_grid(self, ts: FloatArray, X: FloatArray, p: FloatArray,
                      z: FloatArray) -> FloatArray: ...

    def assertions(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                   ) -> FloatArray: ...


MODULE_NAMES = frozenset(name for name in GeneratedModule.__annotations__) | {
    "parameters", "start", "guesses", "rhs", "jacobian_values", "jacobian",
    "jacobian_dense", "sparsity", "observed", "observed_grid", "assertions"}
"""Every name a generated module defines (checked when the pipeline imports one)."""


class HybridModule(GeneratedModule, Protocol):
    """A generated module with events (``EVENTS`` true): Modelica 3.6, 8.5-8.6.

    Where the discrete values live: in ``z``, between the Newton warm starts and the
    failure flag (``z[-1]``), from ``Z_EVENTS`` to ``Z_SIZE - 2``: the held value of
    every state relation (``Z_RELATIONS + k``, 1.0 true, 0.0 false, for the relation
    ``ZERO_CROSSINGS[k]``), of every time relation and ``sample``, the discrete
    variables (slots ``Z_DISCRETE``, names ``DISCRETE``), their ``pre`` values, the
    when-conditions at the last event, and the flags ``Z_INITIAL``, ``Z_TERMINAL``,
    ``Z_TERMINATE`` (0, or 1 + the index into ``TERMINATE_MESSAGES``), ``Z_CHANGED``,
    ``Z_STATUS``. ``guesses(p)`` returns a ``z`` of ``Z_SIZE`` with the start values of
    the discrete variables. ``rhs``, ``jacobian_values`` and ``observed`` only read
    these slots, so between events the right-hand side is smooth; the event functions
    write them.

    How a loop drives it (``springc.simulation.events`` does exactly this):

    1. at the start ``z[Z_INITIAL] = 1.0; x = event_update(t0, x, p, z)``, and if
       ``AFTER_INITIAL`` (a when-condition such as ``not initial()``) once more at
       ``t0`` with ``z[Z_INITIAL]`` cleared;
    2. integrate ``rhs`` up to ``next_time_event(t, x, p, z)`` (or the stop time);
    3. after each accepted step compare ``zero_crossings(t, x, p, z)[k]`` (compared
       with 0 by ``RELATION_OPS[k]``) with the held ``z[Z_RELATIONS + k]``; where one
       differs, locate the first time it does (dense output or bisection), take the
       states there and ``x = event_update(te, x, p, z)``; restart the integrator;
    4. at a time event ``x = event_update(t, x, p, z)`` likewise;
    5. after any event: ``z[Z_STATUS] != 0`` means the event iteration did not
       settle; ``z[Z_TERMINATE] > 0`` that ``terminate()`` ended the simulation;
    6. at the end, if ``USES_TERMINAL``: ``z[Z_TERMINAL] = 1.0`` and ``event_update``.
    """

    Z_EVENTS: int
    Z_SIZE: int
    Z_RELATIONS: int
    ZERO_CROSSINGS: tuple[str, ...]
    RELATION_OPS: tuple[str, ...]
    TIME_EVENTS: tuple[str, ...]
    SAMPLES: int
    DISCRETE: tuple[str, ...]
    Z_DISCRETE: list[int]
    TERMINATE_MESSAGES: tuple[str, ...]
    Z_INITIAL: int
    Z_TERMINAL: int
    Z_TERMINATE: int
    Z_CHANGED: int
    Z_STATUS: int
    EVENT_ITERATIONS: int
    USES_TERMINAL: bool  # a when-condition uses terminal(): run the event at the end
    AFTER_INITIAL: bool  # a when-condition such as 'not initial()': an event after init

    def zero_crossings(self, t: float, x: FloatArray, p: FloatArray,
                       z: FloatArray) -> FloatArray: ...

    def next_time_event(self, t: float, x: FloatArray, p: FloatArray,
                        z: FloatArray) -> float: ...

    def event_update(self, t: float, x: FloatArray, p: FloatArray,
                     z: FloatArray) -> FloatArray: ...

    def event_begin(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray) -> float: ...

    def event_pass(self, t: float, x: FloatArray, p: FloatArray,
                   z: FloatArray) -> FloatArray: ...

    def event_end(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray) -> float: ...


HYBRID_NAMES = frozenset(HybridModule.__annotations__) | {
    "zero_crossings", "next_time_event", "event_update", "event_begin", "event_pass",
    "event_end"}
"""The further names of a hybrid module (``EVENTS`` true)."""
