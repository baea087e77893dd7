"""CompiledModel -> CLibrary: the model's C file (:func:`springc.codegen.generate_c`)
compiled by a C compiler (:func:`springc.native.find_compiler`: the system's, else
``zig cc`` from the ``ziglang`` package of PyPI) into a shared library, loaded with ctypes.

The C file and the library are additions to the model's cache entry (``cmodel.c``,
``libcmodel.so``, each with its hash record, :func:`.cache.add_to_entry`); a library is
loaded only from bytes whose hash matched the record (copied into a private temporary
folder first, so the file loaded is the file checked), a damaged one is built again
with a note. The compiler runs from an argument list, never a shell: no model text
reaches a command line (the file names are springc's own). Layering: codegen prints the
text, this module builds and loads it.
"""

from __future__ import annotations

import contextlib
import ctypes
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..codegen import CodegenBug
from ..native import ZIG_MODULE, CCompilerMissing, find_compiler, first_error, run_compiler
from .cache import add_to_entry, read_addition
from .compiler import CompiledModel

__all__ = ["C_FLAGS", "C_LIBRARY_FILE", "C_SOURCE_FILE", "ZIG_MODULE", "CCompilerMissing",
           "CLibrary", "CompilerRefused", "build_library", "c_library", "c_source",
           "find_compiler"]

C_SOURCE_FILE = "cmodel.c"
C_LIBRARY_FILE = "libcmodel.so"
C_FLAGS = ("-O2", "-g0", "-shared", "-fPIC", "-ffp-contract=off", "-DSPRINGC_FN=")
"""No -ffast-math, and no contraction into fused multiply-adds: the library computes
what the Python module computes, operation for operation. No debug information (zig cc
writes one by default, naming the private build folder): one text, the same bytes."""
FloatArray = npt.NDArray[np.float64]


class CompilerRefused(CodegenBug):
    """The C compiler failed on springc's C text (a bug of springc's printer, or a
    broken compiler); ``stderr``: what the compiler said."""

    def __init__(self, message: str, stderr: str) -> None:
        super().__init__(message)
        self.stderr = stderr

    def first_error(self) -> str:
        """The compiler's first line that names an error (else its first line)."""
        return first_error(self.stderr, 200)


def build_library(source: str, folder: Path, extra: Sequence[str] = ()) -> bytes:
    """The shared library compiled from the C text ``source`` in ``folder`` (a private
    folder of the caller), with further compiler arguments ``extra``; its bytes."""
    out = folder / "build.so"
    (folder / "build.c").write_text(source, encoding="ascii")
    # names relative to the folder: the library records "build.c", not a random path,
    # so two builds of one text give the same bytes
    argv = [*find_compiler(), *C_FLAGS, *extra, "-o", "build.so", "build.c", "-lm"]
    code, messages = run_compiler(argv, folder, "springc's C model")
    if code != 0 or not out.is_file():
        raise CompilerRefused("the C compiler refused springc's C model "
                              f"({' '.join(argv[:1])} exit {code}): "
                              + messages.strip()[-2000:], messages)
    return out.read_bytes()


class CLibrary:
    """The loaded C library of a model: its functions on numpy arrays (see
    ``docs/c_model.md`` for the C interface)."""

    def __init__(self, source: str, data: bytes) -> None:
        self.source = source
        self._folder = tempfile.TemporaryDirectory(prefix="springc-c-")  # private (0700)
        self.path = Path(self._folder.name) / C_LIBRARY_FILE
        self.path.write_bytes(data)
        self.lib = ctypes.CDLL(str(self.path))
        sizes = (ctypes.c_int * 8)()
        self.lib.springc_sizes(sizes)
        self.n_states, self.n_params, self.n_z, self.n_observed, self.n_crossings = (
            sizes[0], sizes[1], sizes[2], sizes[3], sizes[4])
        self.hybrid, self.n_jac, self.has_jacobian = bool(sizes[5]), sizes[6], bool(sizes[7])
        array = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS")
        model = [ctypes.c_double, array, array, array]
        for name, args, result in (
                ("springc_parameters", [array, ctypes.c_void_p], None),
                ("springc_start", [array, array, array], ctypes.c_int),
                ("springc_rhs", [*model, array], ctypes.c_int),
                ("springc_observed", [*model, array], ctypes.c_int),
                ("springc_zero_crossings", [*model, array], ctypes.c_int),
                ("springc_next_time_event", model, ctypes.c_double),
                ("springc_event_update", model, ctypes.c_int),
                ("springc_jacobian", [*model, array], ctypes.c_int),
                ("springc_jacobian_pattern", [ctypes.c_void_p, ctypes.c_void_p], None)):
            function = getattr(self.lib, name)
            function.argtypes, function.restype = args, result
        self.functions = {name: getattr(self.lib, name) for name in (
            "springc_rhs", "springc_observed", "springc_zero_crossings", "springc_jacobian")}

    def parameters(self, given: Mapping[int, float] | None = None) -> FloatArray:
        """The parameter vector: the model's values, with ``given`` (index: value) kept
        and the parameters bound to them following."""
        p = np.zeros(self.n_params + 1)
        mask = (ctypes.c_int * (self.n_params + 1))()
        for i, value in (given or {}).items():
            p[i], mask[i] = value, 1
        self.lib.springc_parameters(p, ctypes.cast(mask, ctypes.c_void_p))
        return p[:self.n_params].copy()

    def start(self, p: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The start values of the states and the initial ``z``."""
        x, z = np.zeros(self.n_states + 1), np.zeros(self.n_z)
        self.lib.springc_start(_vector(p), x, z)
        return x[:self.n_states], z

    def _call(self, name: str, size: int, t: float, x: FloatArray, p: FloatArray,
              z: FloatArray) -> tuple[int, FloatArray]:
        out = np.zeros(size + 1)
        code = self.functions[name](t, _vector(x), _vector(p), _writable(z, self.n_z), out)
        return int(code), out[:size]

    def rhs(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
            ) -> tuple[int, FloatArray]:
        """(return code, dx); ``z`` (float64, contiguous) is updated in place."""
        return self._call("springc_rhs", self.n_states, t, x, p, z)

    def observed(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                 ) -> tuple[int, FloatArray]:
        return self._call("springc_observed", self.n_observed, t, x, p, z)

    def zero_crossings(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                       ) -> tuple[int, FloatArray]:
        return self._call("springc_zero_crossings", self.n_crossings, t, x, p, z)

    def jacobian_dense(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                       ) -> tuple[int, FloatArray]:
        """(return code, d(rhs)/dx as a dense array); code -3: no Jacobian in C."""
        code, values = self._call("springc_jacobian", self.n_jac, t, x, p, z)
        rows = np.zeros(self.n_jac + 1, dtype=np.intc)
        cols = np.zeros(self.n_jac + 1, dtype=np.intc)
        self.lib.springc_jacobian_pattern(rows.ctypes.data, cols.ctypes.data)
        dense = np.zeros((self.n_states, self.n_states))
        dense[rows[:self.n_jac], cols[:self.n_jac]] = values
        return code, dense

    def next_time_event(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                        ) -> float:
        return float(self.lib.springc_next_time_event(t, _vector(x), _vector(p),
                                                       _writable(z, self.n_z)))

    def event_update(self, t: float, x: FloatArray, p: FloatArray, z: FloatArray
                     ) -> tuple[int, FloatArray]:
        """(return code, the states after the event at ``t``); ``z`` updated in place."""
        after = np.array(x, dtype=np.float64)
        after = np.concatenate([after, [0.0]])
        code = self.lib.springc_event_update(t, after, _vector(p), _writable(z, self.n_z))
        return int(code), after[:self.n_states]


def _vector(values: FloatArray) -> FloatArray:
    # one spare entry: a model with no states or parameters still passes an array
    return np.concatenate([np.asarray(values, dtype=np.float64).ravel(), [0.0]])


def _writable(z: FloatArray, size: int) -> FloatArray:
    if not (isinstance(z, np.ndarray) and z.dtype == np.float64 and z.flags.c_contiguous
            and z.flags.writeable and z.shape == (size,)):
        raise TypeError(f"z must be a writable contiguous float64 array of {size} entries")
    return z


def c_source(model: CompiledModel) -> str:
    """The C file of ``model`` computing its observed variables: from its cache entry
    when it holds a verified one, else generated from the model's system (and added)."""
    entry = model.path.parent
    data = read_addition(entry, C_SOURCE_FILE)
    if data is not None:
        return data.decode("ascii")
    derived = model.compiled_from or model.derive()
    from ..codegen import generate_c  # the C printer: on a miss only

    text = generate_c(derived.system, derived.flat_model, model.observed).text
    with contextlib.suppress(OSError):  # a read-only cache: the text is used, not kept
        add_to_entry(entry, C_SOURCE_FILE, text.encode("ascii"))
    return text


def c_library(model: CompiledModel) -> CLibrary:
    """The C library of ``model``, built once per cache entry with the system C
    compiler (:class:`CCompilerMissing` without one) and loaded with ctypes."""
    source = c_source(model)
    entry = model.path.parent
    data = read_addition(entry, C_LIBRARY_FILE)
    if data is None:
        with tempfile.TemporaryDirectory(prefix="springc-cc-") as folder:
            data = build_library(source, Path(folder))
        with contextlib.suppress(OSError):
            add_to_entry(entry, C_LIBRARY_FILE, data)
    return CLibrary(source, data)
