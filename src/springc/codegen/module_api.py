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


class GeneratedModule(Protocol):
    """A generated module: constants over the state vector ``x``, the parameter vector
    ``p`` and the Newton warm starts ``z`` (last entry: failure flag), and functions."""

    MODEL: str
    BACKEND: str
    CODEGEN_VERSION: int
    STATES: tuple[str, ...]
    STATE_UNITS: tuple[str, ...]
    DERIVATIVES: tuple[str, ...]
    PARAMETERS: tuple[str, ...]
    PARAMETER_UNITS: tuple[str, ...]
    PARAMETER_TYPES: tuple[str, ...]
    STRUCTURAL: tuple[str, ...]
    OBSERVED: tuple[str, ...]
    OBSERVED_UNITS: tuple[str, ...]
    GUESSES: tuple[str, ...]
    NEWTON_SYSTEMS: dict[int, tuple[str, ...]]
    EXPERIMENT: dict[str, Any]  # start, stop, interval, tolerance: float or None
    INITIAL_CONDITIONS: int
    SWITCHABLE: bool
    JAC_ROWS: IntArray
    JAC_COLS: IntArray
    JAC_INDICES: IntArray
    JAC_INDPTR: IntArray
    ASSERTIONS: tuple[tuple[str, str, str, bool], ...]  # message, level, location, params only

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
