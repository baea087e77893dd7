"""What a user asks of a run: options -> :class:`RunSettings`, one frozen value.

Every run option lives here once: its field, its default, its command-line name
(:data:`OPTION_NAMES`) and its checks (:func:`run_settings`, which the API and the
command line's shared option group both call). ``None`` means: from the model's
``experiment`` annotation, else the documented default; :func:`springc.simulation.plan`
resolves a model and its settings into the run's plan (grid, tolerances, parameters,
start state, limits, engine, driver).

Defaults: start 0 s, stop 10 s, 500 output intervals, unless the model's
``experiment`` annotation says otherwise (its Interval applies even when the start or
stop time is given); rtol 1e-6 (or the experiment's Tolerance), atol = rtol / 1000;
solver ``auto``; at most :data:`DEFAULT_MAX_STEPS` steps and :data:`DEFAULT_TIME_LIMIT`
seconds.

This module imports neither numpy nor scipy: the command line builds its options
from it before any of them loads. The ``--error-control`` values are read here
(:func:`error_control_mode`); the rule they select lives in :mod:`.error_control`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TextIO

from ..errors import UsageError
from .solver_names import DEFAULT_ENGINE, DEFAULT_ERROR_CONTROL, DEFAULT_SOLVER, ERROR_CONTROLS
from .values import API_NAMES, check_run_values

DEFAULT_START, DEFAULT_STOP, DEFAULT_INTERVALS = 0.0, 10.0, 500
DEFAULT_RTOL = 1e-6
DEFAULT_MAX_STEPS = 20_000_000
"""Integrator steps per run (fixed-step runs are refused up front beyond it)."""
DEFAULT_TIME_LIMIT = 3600.0
"""Seconds of wall clock per run (integration and outputs)."""


@dataclass(frozen=True, kw_only=True)
class RunSettings:
    """Every option of a run (see the module docstring); built by :func:`run_settings`
    from the API's keywords or the command line's options."""

    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    solver: str = DEFAULT_SOLVER
    rtol: float | None = None
    atol: float | None = None
    step: float | None = None  # fixed-step solvers only
    parameters: Mapping[str, float] = field(default_factory=dict)  # and start values
    max_steps: int | None = None  # integrator steps: an error past them
    time_limit: float | None = None  # seconds of wall clock: an error past it
    budget: float = math.inf  # seconds: past it the run raises OverBudget (not an error)
    engine: str = DEFAULT_ENGINE  # auto, compiled (springc.integrate) or scipy
    error_control: str = DEFAULT_ERROR_CONTROL  # tighten, warn or off (.error_control)
    event_rows: bool = False  # add rows with the left and right limits at each event
    progress: TextIO | None = None  # a progress bar on this stream (after a second)
    # error control's companion: a continuous run returns its states and computes its
    # outputs when read (``SimulationResult.deferred``; not an option of the user's)
    deferred_outputs: bool = False

    @property
    def step_limit(self) -> int:
        """``max_steps``, or :data:`DEFAULT_MAX_STEPS`."""
        return DEFAULT_MAX_STEPS if self.max_steps is None else self.max_steps

    @property
    def seconds_limit(self) -> float:
        """``time_limit``, or :data:`DEFAULT_TIME_LIMIT`."""
        return DEFAULT_TIME_LIMIT if self.time_limit is None else self.time_limit


SimulationOptions = RunSettings
"""The former name of :class:`RunSettings` (its fields by keyword)."""

OPTION_NAMES = {"start": "--start", "stop": "--stop", "interval": "--interval",
                "rtol": "--rtol", "atol": "--atol", "step": "--step", "parameters": "--set",
                "solver": "--solver", "engine": "--engine", "max_steps": "--max-steps",
                "time_limit": "--time-limit", "error_control": "--error-control",
                "error_estimate": "--error-estimate", "event_rows": "--event-rows"}
"""The command-line option of each setting (errors name what the caller typed)."""

ESTIMATE_MODES = {"off": "off", "on": "warn", "auto": "tighten"}
"""The deprecated ``--error-estimate`` values and the ``--error-control`` each means."""


def check_mode(mode: object, option: str = "--error-control") -> str:
    """``mode`` lowered, or a usage error naming ``option``."""
    name = mode.lower() if isinstance(mode, str) else mode
    if name not in ERROR_CONTROLS:
        raise UsageError(f"{option} must be one of {', '.join(ERROR_CONTROLS)}, not "
                         f"{mode!r}", option=option)
    return str(name)


def error_control_mode(control: str | None, estimate: str | None,
                       names: tuple[str, str] = ("--error-control", "--error-estimate")
                       ) -> str:
    """The error-control mode from the new option and the deprecated one (at most one
    of them given; ``names``: how the caller spells them, for the messages)."""
    if estimate is None:
        return check_mode(DEFAULT_ERROR_CONTROL if control is None else control, names[0])
    if control is not None:
        raise UsageError(f"{names[1]} is deprecated and cannot be combined with "
                         f"{names[0]}: use {names[0]} alone", option=names[1])
    value = estimate.lower() if isinstance(estimate, str) else estimate
    if value not in ESTIMATE_MODES:
        raise UsageError(f"{names[1]} must be one of {', '.join(ESTIMATE_MODES)}, not "
                         f"{estimate!r}", option=names[1])
    return ESTIMATE_MODES[str(value)]


def estimate_deprecation(estimate: str, names: tuple[str, str] = ("--error-control",
                                                                  "--error-estimate")
                         ) -> str:
    """The warning of a deprecated ``--error-estimate`` value."""
    return (f"{names[1]} is deprecated: {names[1]} {estimate.lower()} is {names[0]} "
            f"{ESTIMATE_MODES.get(estimate.lower(), '?')}")


def run_settings(*, start: float | None = None, stop: float | None = None,
                 interval: float | None = None, solver: str = DEFAULT_SOLVER,
                 rtol: float | None = None, atol: float | None = None,
                 step: float | None = None, parameters: Mapping[str, float] | None = None,
                 max_steps: int | None = None, time_limit: float | None = None,
                 engine: str = DEFAULT_ENGINE, error_control: str | None = None,
                 error_estimate: str | None = None, event_rows: bool = False,
                 progress: TextIO | None = None, cli: bool = False) -> RunSettings:
    """The :class:`RunSettings` of these options, checked before any work: a
    :class:`UsageError` names the option as the caller spells it (``cli``: the
    command-line options of :data:`OPTION_NAMES`, else the API's keywords). ``None``
    means the default; ``error_estimate`` is the deprecated form of
    ``error_control`` (the caller says the deprecation in its own way)."""
    names = OPTION_NAMES if cli else {**API_NAMES, "error_control": "error_control",
                                      "error_estimate": "error_estimate"}
    check_run_values(start, stop, interval, rtol, atol, step, parameters, names)
    mode = error_control_mode(error_control, error_estimate,
                              (names["error_control"], names["error_estimate"]))
    return RunSettings(
        start=start, stop=stop, interval=interval, solver=solver, rtol=rtol, atol=atol,
        step=step, parameters=dict(parameters or {}), max_steps=max_steps,
        time_limit=time_limit, engine=engine, error_control=mode,
        event_rows=bool(event_rows), progress=progress)
