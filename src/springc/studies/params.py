"""Parameter specifications -> the runs of a study (a table: one row per run).

Text forms (``--param NAME=SPEC``; the API takes the same strings, or lists of values):

- ``0.5,1,2``: a list of values;
- ``START:STOP:COUNT`` or ``START:STOP:lin:COUNT``: COUNT evenly spaced values, both ends
  included; ``START:STOP:log:COUNT``: COUNT values evenly spaced in log (``numpy.geomspace``);
- ``START:STOP`` (uniform) or ``START:STOP:log`` (log-uniform): a range to draw from;
- ``uniform(LOW, HIGH)``, ``loguniform(LOW, HIGH)``, ``normal(MEAN, STD)``,
  ``lognormal(MU, SIGMA)`` (of the logarithm), ``triangular(LOW, MODE, HIGH)``: a
  distribution of ``scipy.stats`` to draw from.

A grid study (:func:`grid`) is the cartesian product of the lists, the first parameter
varying slowest. A sampled study (:func:`sample`, ``--samples N``) draws N points of the
unit hypercube, by Monte Carlo (``numpy.random.default_rng(seed)``) or Latin hypercube
(``scipy.stats.qmc.LatinHypercube``, one point in each of N equal strata of every
parameter), and maps each coordinate through its distribution's inverse CDF.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import UsageError

MAX_RUNS = 1_000_000
"""The most runs one study may have."""
METHODS = ("lhs", "mc")
"""Sampling methods: Latin hypercube, Monte Carlo."""

DISTRIBUTIONS = {"uniform": ("LOW", "HIGH"), "loguniform": ("LOW", "HIGH"),
                 "normal": ("MEAN", "STD"), "lognormal": ("MU", "SIGMA"),
                 "triangular": ("LOW", "MODE", "HIGH")}
"""Distribution name -> the names of its arguments."""

_CALL = re.compile(r"\s*([A-Za-z_]\w*)\s*\((.*)\)\s*", re.DOTALL)


@dataclass(frozen=True)
class Distribution:
    """A distribution to draw a parameter from: ``kind`` in :data:`DISTRIBUTIONS`."""

    kind: str
    args: tuple[float, ...]

    def frozen(self) -> Any:
        """The ``scipy.stats`` frozen distribution."""
        from scipy import stats

        a = self.args
        if self.kind == "uniform":
            return stats.uniform(loc=a[0], scale=a[1] - a[0])
        if self.kind == "loguniform":
            return stats.loguniform(a[0], a[1])
        if self.kind == "normal":
            return stats.norm(loc=a[0], scale=a[1])
        if self.kind == "lognormal":
            return stats.lognorm(s=a[1], scale=math.exp(a[0]))
        return stats.triang(c=(a[1] - a[0]) / (a[2] - a[0]), loc=a[0], scale=a[2] - a[0])

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """The values at the quantiles ``u`` in [0, 1) (the inverse CDF)."""
        return np.asarray(self.frozen().ppf(u), dtype=float)

    def cdf(self, x: np.ndarray) -> np.ndarray:
        """The probability of a value at most ``x``."""
        return np.asarray(self.frozen().cdf(x), dtype=float)


@dataclass(frozen=True)
class ParameterSpec:
    """One swept parameter: explicit ``values`` (grid) or a ``distribution`` (samples)."""

    name: str
    values: tuple[float, ...] | None = None
    distribution: Distribution | None = None
    text: str = ""


def _number(word: str, item: str, option: str) -> float:
    try:
        value = float(word)
    except ValueError:
        raise UsageError(f"{option} {item}: '{word.strip()}' is not a number",
                         option=option) from None
    if not math.isfinite(value):
        raise UsageError(f"{option} {item}: {word.strip()} is not a finite number",
                         option=option)
    return value


def _distribution(kind: str, args: tuple[float, ...], item: str, option: str
                  ) -> Distribution:
    names = DISTRIBUTIONS[kind]
    if len(args) != len(names):
        raise UsageError(f"{option} {item}: {kind} takes {len(names)} arguments "
                         f"({kind}({', '.join(names)})), not {len(args)}", option=option)
    if kind in ("uniform", "loguniform") and not args[0] < args[1]:
        raise UsageError(f"{option} {item}: LOW must be less than HIGH", option=option)
    if kind == "loguniform" and not args[0] > 0:
        raise UsageError(f"{option} {item}: a log-uniform range needs LOW > 0",
                         option=option)
    if kind in ("normal", "lognormal") and not args[1] > 0:
        raise UsageError(f"{option} {item}: {names[1]} must be > 0", option=option)
    if kind == "triangular" and not (args[0] <= args[1] <= args[2] and args[0] < args[2]):
        raise UsageError(f"{option} {item}: triangular needs LOW <= MODE <= HIGH and "
                         "LOW < HIGH", option=option)
    return Distribution(kind, args)


def _range(name: str, parts: list[str], item: str, option: str) -> ParameterSpec:
    low, high = (_number(p, item, option) for p in parts[:2])
    rest = [p.strip().lower() for p in parts[2:]]
    scale = "lin"
    if rest and rest[0] in ("lin", "log"):
        scale = rest.pop(0)
    if len(rest) > 1:
        raise UsageError(f"{option} {item}: expected START:STOP[:lin|log][:COUNT]",
                         option=option)
    if scale == "log" and not (low > 0 and high > 0):
        raise UsageError(f"{option} {item}: a log range needs START and STOP > 0",
                         option=option)
    if not rest:
        kind = "loguniform" if scale == "log" else "uniform"
        return ParameterSpec(name, distribution=_distribution(kind, (low, high), item,
                                                                option), text=item)
    if not rest[0].isdigit() or int(rest[0]) < 1:
        raise UsageError(f"{option} {item}: COUNT must be a whole number >= 1, not "
                         f"'{rest[0]}'", option=option)
    count = int(rest[0])
    values = np.geomspace(low, high, count) if scale == "log" else \
        np.linspace(low, high, count)
    return ParameterSpec(name, tuple(float(v) for v in values), text=item)


def parse_parameter(item: str, option: str = "--param") -> ParameterSpec:
    """``NAME=SPEC`` (see the module text) -> :class:`ParameterSpec`; a
    :class:`UsageError` naming ``option`` for anything else."""
    name, sep, spec = item.partition("=")
    name = name.strip()
    if not sep or not name or not spec.strip():
        raise UsageError(f"{option}: expected NAME=VALUES, got '{item}'", option=option)
    return parse_values(name, spec, item, option)


def parse_values(name: str, spec: str, item: str | None = None,
                 option: str = "--param") -> ParameterSpec:
    """The values ``SPEC`` of the parameter ``name`` (see the module text)."""
    item = item or f"{name}={spec}"
    call = _CALL.fullmatch(spec)
    if call:
        kind = call.group(1).lower()
        if kind not in DISTRIBUTIONS:
            raise UsageError(f"{option} {item}: unknown distribution '{call.group(1)}' "
                             f"(choose from {', '.join(DISTRIBUTIONS)})", option=option)
        args = tuple(_number(w, item, option) for w in call.group(2).split(",")
                     if w.strip())
        return ParameterSpec(name, distribution=_distribution(kind, args, item, option),
                             text=item)
    if ":" in spec:
        parts = spec.split(":")
        if not 2 <= len(parts) <= 4:
            raise UsageError(f"{option} {item}: expected START:STOP[:lin|log][:COUNT]",
                             option=option)
        return _range(name, parts, item, option)
    values = tuple(_number(w, item, option) for w in spec.split(","))
    return ParameterSpec(name, values, text=item)


def _check_names(specs: Sequence[ParameterSpec]) -> None:
    seen = set()
    for spec in specs:
        if spec.name in seen:
            raise UsageError(f"--param {spec.name} is given twice", option="--param")
        seen.add(spec.name)
    if not specs:
        raise UsageError("give at least one parameter to vary (--param NAME=VALUES)",
                         option="--param")


def grid(specs: Sequence[ParameterSpec]) -> np.ndarray:
    """The cartesian product of the parameters' values: one row per run, one column per
    parameter, the first parameter varying slowest."""
    _check_names(specs)
    for spec in specs:
        if spec.values is None:
            raise UsageError(f"--param {spec.text}: a range without a count or a "
                             "distribution is drawn from: give --samples N (or a list, "
                             "or START:STOP:COUNT)", option="--param")
    count = math.prod(len(s.values or ()) for s in specs)
    if count > MAX_RUNS:
        raise UsageError(f"the grid has {count} runs, more than {MAX_RUNS}",
                         option="--param")
    rows = list(itertools.product(*(s.values or () for s in specs)))
    return np.array(rows, dtype=float).reshape(count, len(specs))


def unit_points(count: int, dimensions: int, method: str, seed: int) -> np.ndarray:
    """``count`` points of the unit hypercube [0, 1)^dimensions: Monte Carlo (``"mc"``)
    or Latin hypercube (``"lhs"``), reproducible from ``seed``."""
    if method == "mc":
        return np.random.default_rng(seed).random((count, dimensions))
    if method == "lhs":
        from scipy.stats import qmc

        return np.asarray(qmc.LatinHypercube(dimensions, rng=seed).random(count))
    raise UsageError(f"--method must be one of {', '.join(METHODS)}, not '{method}'",
                     option="--method")


def sample(specs: Sequence[ParameterSpec], count: int, method: str = "lhs",
           seed: int = 0) -> np.ndarray:
    """``count`` runs drawn from the parameters' distributions (see the module text)."""
    _check_names(specs)
    if not 1 <= count <= MAX_RUNS:
        raise UsageError(f"--samples must be between 1 and {MAX_RUNS}, not {count}",
                         option="--samples")
    for spec in specs:
        if spec.distribution is None:
            raise UsageError(f"--param {spec.text}: --samples draws values from ranges or "
                             "distributions: give START:STOP, START:STOP:log or e.g. "
                             "normal(MEAN, STD), not a list or a count", option="--param")
    u = unit_points(count, len(specs), method, seed)
    columns = [s.distribution.ppf(u[:, j]) for j, s in enumerate(specs)
               if s.distribution is not None]
    return np.column_stack(columns) if columns else np.empty((count, 0))
