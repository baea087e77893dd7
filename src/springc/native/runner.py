"""A model's C loop library (``cloop.so`` in its cache entry) loaded and run with the
standard library only: ctypes, ``array.array('d')`` buffers, no numpy at import or run.

- :func:`read_verified` / :func:`cached_library`: the library's bytes from a cache entry,
  only where they match their SHA-256 record (``cloop.sha256``, the hex digest and a
  newline), as springc's cache writes every file it adds;
- :class:`LoopLibrary`: those bytes loaded from a private temporary folder (the file
  loaded is the file checked); its sizes and names, the model's parameters and start
  values, :meth:`LoopLibrary.run` (one run of DOP853 or RK45 on an output grid,
  resumable: a run stopped at the step limit goes on from its failure time, state and
  next step as one uninterrupted run) and :meth:`LoopLibrary.observed` (the observed
  variables at the rows of a run).

Arguments that are arrays take any sequence of floats; objects with a writable buffer
of float64 (an ``array('d')``, a C-contiguous numpy array) are passed without a copy,
and ``z`` (the model's work array, updated in place) must be one. The status codes are
those of ``springc.integrate.Status`` (0 success, 1 step too small, 2 non-finite
derivative, 4 step limit, 5 the model's failure flag). See ``docs/c_model.md``.
"""

from __future__ import annotations

import array
import ctypes
import hashlib
import math
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

LIBRARY_FILE = "cloop.so"
RECORD_FILE = "cloop.sha256"
ABI = 3
"""The library's interface version (``springc_loop_abi()``; the same number as
``springc.integrate.native_loop.ABI``)."""
METHODS = {"dop853": 0, "rk45": 1, "radau": 2, "bdf": 3}
SUCCESS, MAX_STEPS = 0, 4
FIRST_STRETCH = 10_000
"""Steps (accepted and rejected) of a compiled run's first stretch; each next stretch
goes on from where the one before stopped (its time, state and next step size) and is
:data:`STRETCH_GROWTH` times longer. The explicit methods take the same steps as one
uninterrupted run; radau and bdf start their step history again (bdf at order 1), so
the full path (:func:`springc.simulation.compiled.advance_with`) and the warm replay
(:mod:`springc.launcher`) stop and resume at the same steps."""
STRETCH_GROWTH = 10

_int64 = ctypes.c_longlong
_double_p = ctypes.POINTER(ctypes.c_double)
_int64_p = ctypes.POINTER(_int64)


class LibraryMismatch(RuntimeError):
    """The library is not a springc loop library of this interface version."""


def read_verified(path: Path, record: Path) -> bytes | None:
    """The bytes of ``path`` if their SHA-256 matches ``record``; None if either is
    missing, unreadable or they do not match (nothing is removed)."""
    try:
        data = path.read_bytes()
        expected = record.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return data if hashlib.sha256(data).hexdigest() == expected else None


def cached_library(entry: Path) -> bytes | None:
    """The verified bytes of the loop library of the cache entry ``entry`` (the folder
    of the model's ``model.py``), or None."""
    return read_verified(entry / LIBRARY_FILE, entry / RECORD_FILE)


def doubles(values: Any, size: int | None = None) -> Any:
    """``values`` as a ctypes array of doubles: the object's own memory where it has a
    writable float64 buffer (no copy), else a copy (any sequence of floats, a scalar
    repeated ``size`` times)."""
    if isinstance(values, (int, float)):
        values = array.array("d", [float(values)]) * (size or 1)
    try:
        view = memoryview(values)
    except TypeError:
        view = None
    if view is not None and view.format == "d" and view.c_contiguous:
        count = view.nbytes // 8
        if not view.readonly:
            return (ctypes.c_double * max(count, 1)).from_buffer(values) if count else \
                (ctypes.c_double * 1)()
        return (ctypes.c_double * max(count, 1)).from_buffer_copy(view) if count else \
            (ctypes.c_double * 1)()
    copy = array.array("d", (float(v) for v in values))
    if size is not None and len(copy) != size:
        raise ValueError(f"expected {size} values, got {len(copy)}")
    return (ctypes.c_double * max(len(copy), 1))(*copy) if len(copy) else \
        (ctypes.c_double * 1)()


def _rows(out: Any, count: int) -> Any:
    """``out`` where it is a writable C-contiguous buffer of at least ``count`` float64."""
    view = memoryview(out)
    if view.readonly or view.format != "d" or not view.c_contiguous \
            or view.nbytes // 8 < count:
        raise TypeError(f"out must be a writable contiguous buffer of {count} float64")
    return out


def zeros(count: int) -> array.array[float]:
    """``count`` zeros as an ``array('d')``."""
    return array.array("d", [0.0]) * count  # (repetition: no bytes object of the size)


@dataclass(frozen=True)
class LoopRun:
    """A run's outcome. ``states`` holds ``filled`` rows of ``n`` values (row-major,
    the grid's length in rows; later rows are zeros); ``failure_time`` and
    ``failure_state`` are where the run stopped (the end of the grid on success), and
    ``next_step`` the step size it would take next."""

    status: int
    states: array.array[float]
    filled: int
    accepted_steps: int
    rejected_steps: int
    rhs_evaluations: int
    failure_time: float
    failure_state: array.array[float]
    next_step: float
    jacobian_evaluations: int = 0
    fired: tuple[int, ...] = ()
    """Of a run with ``signs``: each zero-crossing indicator's crossing at the state
    event it stopped at (+1 rising, -1 falling, 0 not crossed)."""

    @property
    def ok(self) -> bool:
        return self.status == SUCCESS


class LoopLibrary:
    """A loop library's bytes (verified by the caller) loaded with ctypes."""

    def __init__(self, data: bytes) -> None:
        self._folder = tempfile.TemporaryDirectory(prefix="springc-cloop-")  # 0700
        self.path = Path(self._folder.name) / LIBRARY_FILE
        self.path.write_bytes(data)
        self.lib = ctypes.CDLL(str(self.path))
        try:
            abi = self.lib.springc_loop_abi
        except AttributeError:
            raise LibraryMismatch(f"{self.path} is not a springc loop library") from None
        abi.restype = ctypes.c_int
        if abi() != ABI:
            raise LibraryMismatch(f"loop library interface {abi()}, not {ABI}")
        sizes = (_int64 * 6)()
        self.lib.springc_loop_sizes(sizes)
        (self.n_states, self.n_params, self.n_z, self.n_observed,
         self.initial_conditions, self.hybrid) = (int(s) for s in sizes)
        self.lib.springc_loop_crossings.restype = _int64
        self.n_crossings = int(self.lib.springc_loop_crossings())
        self.lib.springc_loop_name.restype = ctypes.c_char_p
        self.lib.springc_loop_name.argtypes = [ctypes.c_int, _int64]
        self.lib.springc_loop_start.restype = ctypes.c_int
        self.lib.springc_loop_run.restype = ctypes.c_int
        self.lib.springc_loop_run.argtypes = [
            ctypes.c_int, _int64, _double_p, _double_p, _double_p, _double_p,
            ctypes.c_double, _double_p, ctypes.c_double, ctypes.c_double, _int64,
            _double_p, _int64_p, _double_p, _double_p, _int64_p, _double_p, ctypes.c_double,
            _int64_p]
        self.lib.springc_loop_observed.restype = _int64
        self.lib.springc_loop_observed.argtypes = [_int64, _double_p, _double_p, _double_p,
                                                   _double_p, _double_p]

    def names(self, table: str) -> tuple[str, ...]:
        """The names of ``table``: ``states``, ``parameters`` or ``observed`` (or
        ``model``: its name alone)."""
        number, size = {"states": (0, self.n_states), "parameters": (1, self.n_params),
                        "observed": (2, self.n_observed), "model": (3, 1)}[table]
        return tuple(self.lib.springc_loop_name(number, i).decode("utf-8")
                     for i in range(size))

    def parameters(self, given: Mapping[int, float] | None = None) -> array.array[float]:
        """The parameter vector: the model's values with ``given`` (index: value) kept
        and the parameters bound to them following."""
        p = zeros(self.n_params + 1)
        mask = (ctypes.c_int * (self.n_params + 1))()
        for i, value in (given or {}).items():
            p[i], mask[i] = float(value), 1
        self.lib.springc_loop_parameters(doubles(p), mask)
        return p[:self.n_params]

    def start(self, p: Any) -> tuple[int, array.array[float], array.array[float]]:
        """(return code, the start values of the states, the initial ``z``): the C
        model's start values (consistent only where ``initial_conditions`` is 0: else
        springc solves the initial problem in Python)."""
        x, z = zeros(self.n_states + 1), zeros(self.n_z + 1)
        code = self.lib.springc_loop_start(doubles(p, self.n_params), doubles(x), doubles(z))
        return int(code), x[:self.n_states], z[:self.n_z]

    def run(self, method: str, grid: Any, x0: Any, p: Any, z: Any, *, rtol: float,
            atol: float | Sequence[float], max_step: float = math.inf,
            first_step: float = 0.0, max_steps: int = 0,
            order: Sequence[int] | None = None, out: Any = None,
            signs: Sequence[float] | None = None, t_stop: float = math.inf) -> LoopRun:
        """Integrate from ``(grid[0], x0)`` over the increasing ``grid`` with ``method``
        (dop853, rk45, radau or bdf); ``z`` is updated in place. ``first_step`` 0 selects
        the first step as scipy does; ``max_steps`` counts accepted and rejected steps
        (0: no limit). ``order``: radau's and bdf's ordering of the states in their
        banded LU above 64 states (position -> state, e.g. the reverse Cuthill-McKee
        order of ``springc.integrate.ordering.band_layout``, which the numba loops use;
        None: state order). ``out``: a writable C-contiguous float64 buffer of at least
        ``len(grid)`` rows of the states, which the run's rows are written into (no
        other row is touched) and which :attr:`LoopRun.states` then is; None: a new
        buffer of zeros. A hybrid model's run between events: ``signs``, the held sign
        of each zero-crossing indicator (+1/-1, ``n_crossings`` of them), stops it at the
        first crossing (status 6, :attr:`LoopRun.fired`); a ``t_stop`` before the grid's
        end at that time (status 7)."""
        n = self.n_states
        grid_ = doubles(grid)
        m = len(grid_) if len(grid) else 0
        if m < 1:
            raise ValueError("the grid is empty")
        z_ = self._z(z)
        states = zeros(max(m * n, 1)) if out is None or not n else _rows(out, m * n)
        end = zeros(max(n, 1))
        counts, reals = (_int64 * 5)(), (ctypes.c_double * 2)()
        ordering = None
        if order is not None:
            if sorted(int(i) for i in order) != list(range(n)):
                raise ValueError(f"order must be a permutation of the {n} states")
            ordering = (_int64 * max(n, 1))(*(int(i) for i in order))
        held = None if signs is None else doubles(signs, self.n_crossings)
        fired = (_int64 * max(self.n_crossings, 1))()
        status = self.lib.springc_loop_run(
            METHODS[method], m, grid_, doubles(x0, n), doubles(p, self.n_params), z_,
            float(rtol), doubles(atol, n), float(max_step), float(first_step),
            int(max_steps), doubles(states), counts, reals, doubles(end), ordering,
            held, float(t_stop), fired)
        if status < 0:
            raise MemoryError("the loop could not allocate its work arrays")
        return LoopRun(int(status), states if n else zeros(0), int(counts[4]),
                       int(counts[0]), int(counts[1]), int(counts[2]), float(reals[0]),
                       end[:n], float(reals[1]), int(counts[3]),
                       tuple(int(f) for f in fired[:self.n_crossings]) if held is not None
                       else ())

    def observed(self, ts: Any, states: Any, p: Any, z: Any
                 ) -> tuple[int, array.array[float]]:
        """(-1, or the first row whose evaluation set the model's failure flag; the
        observed variables at the rows ``(ts[k], states[k])``, row-major) with ``z``
        carried from row to row (updated in place)."""
        ts_ = doubles(ts)
        m = len(ts)
        out = zeros(max(m * self.n_observed, 1))
        row = self.lib.springc_loop_observed(m, ts_, doubles(states), doubles(p, self.n_params),
                                             self._z(z), doubles(out))
        return int(row), out if self.n_observed else zeros(0)

    def _z(self, z: Any) -> Any:
        try:
            view = memoryview(z)
        except TypeError:
            view = memoryview(b"")
        if view.readonly or view.format != "d" or not view.c_contiguous \
                or view.nbytes // 8 != self.n_z:
            raise TypeError(f"z must be a writable contiguous buffer of {self.n_z} float64")
        return doubles(z)
