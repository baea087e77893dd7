"""The compiled methods and their facts, in one place: which loop runs each method, how
it compiles, whether numba has cached it, and what its first compile costs.

Every adaptive method is the shared loop of :mod:`.loop` specialised on the module of its
hooks (:func:`.loop.specialize`); the fixed-step methods share one loop
(:mod:`.fixed_step_kernel`). A loop is made and compiled on its first use only (lazily,
per method), under a file lock beside numba's cache (:mod:`.compile_lock`), so that
processes that need it at once compile it once. Adding a compiled method: its hooks
module, a line of :data:`METHODS`, its wrapper in :mod:`.engine`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

FIXED_STEP_METHODS = ("euler", "symplectic-euler", "verlet", "rk4")
FIXED_STEP = "fixed-step"


@dataclass(frozen=True)
class Method:
    """A compiled method: ``hooks`` (a module of this package, for :mod:`.loop`; None for
    the fixed-step loop), whether it takes a Jacobian, and ``compile_seconds``: about the
    CPU seconds of its first compile on a machine (numba's cache empty; measured on the
    development machine by ``benchmarks/bench_cold.py``), for the status line."""

    name: str
    hooks: str | None
    implicit: bool
    compile_seconds: int


METHODS = {
    "dop853": Method("dop853", "dop853_steps", False, 10),
    "rk45": Method("rk45", "rk45_steps", False, 8),
    "radau": Method("radau", "radau_steps", True, 25),
    "bdf": Method("bdf", "bdf_steps", True, 14),
    FIXED_STEP: Method(FIXED_STEP, None, False, 7),
}
"""The compiled methods by name (the fixed-step methods share :data:`FIXED_STEP`)."""

LOADED: dict[tuple[str, bool], Any] = {}
"""The loops made in this process, by (method, scipy's arithmetic)."""


def method_of(name: str) -> Method:
    """The :class:`Method` of a method name (a fixed-step method's is the shared one)."""
    if name in FIXED_STEP_METHODS:
        return METHODS[FIXED_STEP]
    if name not in METHODS:
        raise ValueError(f"unknown compiled method {name!r}; use one of "
                         f"{(*METHODS, *FIXED_STEP_METHODS)}")
    return METHODS[name]


def dispatcher(name: str, blas: bool = False) -> Any:
    """The numba dispatcher of the loop of ``name`` (not compiled yet: see
    :func:`kernel`); ``blas``: with scipy's summation order (DOP853, RK45)."""
    method = method_of(name)
    key = (method.name, blas and not method.implicit)
    if key not in LOADED:
        if method.hooks is None:
            from .fixed_step_kernel import fixed_step_run

            LOADED[key] = fixed_step_run
        else:
            from .loop import specialize

            hooks = importlib.import_module(f"{__package__}.{method.hooks}")
            suffix = "_blas" if key[1] else ""
            LOADED[key] = specialize(f"{method.name}_loop{suffix}", hooks, key[1])
    return LOADED[key]


def kernel(name: str, blas: bool = False) -> Any:
    """The compiled loop of ``name``: compiled for this machine on its first use (or
    loaded from numba's cache), once per machine at a time (:mod:`.compile_lock`)."""
    from .compile_lock import compile_once
    from .signatures import FIXED_STEP_SIGNATURE, LOOP_SIGNATURE

    loop = dispatcher(name, blas)
    if not loop.overloads:
        fixed = method_of(name).hooks is None
        compile_once(loop, FIXED_STEP_SIGNATURE if fixed else LOOP_SIGNATURE)
    return loop


def load(name: str, blas: bool = False) -> None:
    """Compile or load from numba's cache the loop of ``name`` now, as its first run
    would: a caller timing runs leaves the loading out."""
    kernel(name, blas)


def kernel_cached(name: str, blas: bool = False) -> bool:
    """Whether the loop of ``name`` loads at once: already loaded in this process, or
    numba's on-disk cache holds its index. If not, its first use compiles it for this
    machine (:attr:`Method.compile_seconds`, once). Imports numba, compiles nothing."""
    from .compile_lock import index_file

    loop = dispatcher(name, blas)
    if loop.overloads:
        return True
    index = index_file(loop)
    return index is not None and index.exists()


def compile_seconds(name: str) -> int:
    """About the CPU seconds of the first compile of the loop of ``name``."""
    return method_of(name).compile_seconds
