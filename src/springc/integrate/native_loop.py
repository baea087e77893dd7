"""The compiled engine's single-run loop in C: a model's C text -> the translation unit
of its loop library (DOP853 and RK45, ``single_loop.c``; Radau IIA and BDF,
``implicit_core.c``, ``radau_steps.c``, ``bdf_steps.c``).

One text per model: the model's C functions (``static inline``, so that the C
compiler inlines them into the loop, and its name tables), the DOP853 tableau's
weighted sums written out (:func:`.native_ensemble.prelude`), RK45's
(:func:`rk45_prelude`), DOP853's step arithmetic shared with the ensemble kernel
(``dop853_core.c``), the loop (``single_loop.c``), the implicit methods' constants
(:func:`implicit_prelude`) and hooks (``implicit_core.c``, ``radau_steps.c``,
``bdf_steps.c``): the contract of :mod:`.loop` (its ``adaptive_loop`` specialised
on :mod:`.dop853_steps` or :mod:`.rk45_steps` with plain-loop sums, on
:mod:`.radau_steps` or :mod:`.bdf_steps` with the C model's analytic Jacobian), every
operation in the same order. The
library is built by :func:`springc.pipeline.loop_library` and run by
:mod:`springc.native.runner` (stdlib and ctypes only). Imports nothing from springc.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import bdf_tableau, radau_tableau, rk45_tableau
from .native_ensemble import CORE, c_array, c_switch, c_weighted_sum, prelude

LOOP = Path(__file__).with_name("single_loop.c")
IMPLICIT = tuple(Path(__file__).with_name(name) for name in (
    "implicit_core.c", "radau_steps.c", "bdf_steps.c"))
ABI = 3
"""The interface version of the library's exports (``springc_loop_abi()``): a change of
an export's arguments moves it, and the runner refuses a library of another."""
METHODS = {"dop853": 0, "rk45": 1, "radau": 2, "bdf": 3}
"""The methods the loop runs, by their number in ``springc_loop_run``."""


def rk45_prelude() -> str:
    """RK45's tableau as C: ``RK_C``, the stage sums ``rk_a_row``, ``rk_b_sum``,
    ``rk_e_sum`` and the dense output's columns ``rk_p_col`` (each summed from 0.0 in
    the order of the stages, as :mod:`.rk45_steps` sums with plain loops)."""
    function = "static inline"
    rows = [""] + [f"rk_a_{s}" for s in range(1, rk45_tableau.STAGES)]
    parts = [c_array("RK_C", rk45_tableau.C, "static const")]
    parts += [c_weighted_sum(rows[s], rk45_tableau.A[s, :s], function)
              for s in range(1, rk45_tableau.STAGES)]
    parts.append(c_switch("rk_a_row", rows, function))
    parts.append(c_weighted_sum("rk_b_sum", rk45_tableau.B, function))
    parts.append(c_weighted_sum("rk_e_sum", rk45_tableau.E, function))
    columns = [f"rk_p_{r}" for r in range(rk45_tableau.P.shape[1])]
    parts += [c_weighted_sum(columns[r], rk45_tableau.P[:, r], function)
              for r in range(len(columns))]
    parts.append(c_switch("rk_p_col", columns, function))
    return "".join(parts)


def _table(name: str, values: np.ndarray) -> str:
    """A constant array of doubles (of any shape) as C, every value exact."""
    values = np.asarray(values, dtype=float)
    dims = "".join(f"[{d}]" for d in values.shape)

    def braced(part: np.ndarray) -> str:
        if part.ndim == 0:
            return repr(float(part))
        return "{" + ", ".join(braced(row) for row in part) + "}"
    return f"static const double {name}{dims} = {braced(values)};\n"


O1_PRAGMA = ('#if defined(__GNUC__) && !defined(__clang__)\n#pragma GCC optimize ("O1")\n'
             '#endif\n')
"""GCC compiles the implicit methods (the rest of the text) at -O1: at -O2 they took
the seed's library build from 0.6-0.7 s to 1.7-2.3 s of CPU (1.1-1.6 s with this, gcc
12 at load 16), while a warm run's time (the 256-state chain: radau 36 ms, bdf 14 ms)
moved within this machine's noise. The results do not depend on it (no fast-math, no
contraction: IEEE arithmetic at every level). Clang (and zig cc) ignore it."""


def implicit_prelude() -> str:
    """Radau IIA's and BDF's constants as C (``SI_RADAU_*``, ``SI_MU_REAL``,
    ``si_radau_mu_complex()``, ``si_radau_ti_complex(i)``, ``SI_BDF_*``): the values of
    :mod:`.radau_tableau` and :mod:`.bdf_tableau` the numba hooks use, exactly; the
    complex ones built from their real and imaginary parts."""
    t = radau_tableau
    mu = complex(t.MU_COMPLEX)
    parts = [O1_PRAGMA, "#include <complex.h>\n",
             f"#define SI_MU_REAL {float(t.MU_REAL)!r}\n",
             f"#define SI_NEWTON_RADAU {t.NEWTON_MAXITER}\n",
             f"#define SI_NEWTON_BDF {bdf_tableau.NEWTON_MAXITER}\n",
             f"#define SI_MAX_ORDER {bdf_tableau.MAX_ORDER}\n",
             _table("SI_RADAU_C", t.C), _table("SI_RADAU_E", t.E), _table("SI_RADAU_T", t.T),
             _table("SI_RADAU_TI", t.TI), _table("SI_RADAU_P", t.P),
             _table("SI_RADAU_TIC_RE", t.TI_COMPLEX.real),
             _table("SI_RADAU_TIC_IM", t.TI_COMPLEX.imag),
             "static inline double complex si_make_complex(double re, double im) {\n"
             "    double complex v = im * I;\n    return v + re;\n}\n",
             "static inline double complex si_radau_mu_complex(void) {\n"
             f"    return si_make_complex({mu.real!r}, {mu.imag!r});\n}}\n",
             "static inline double complex si_radau_ti_complex(int i) {\n"
             "    return si_make_complex(SI_RADAU_TIC_RE[i], SI_RADAU_TIC_IM[i]);\n}\n",
             _table("SI_BDF_GAMMA", bdf_tableau.GAMMA), _table("SI_BDF_ALPHA", bdf_tableau.ALPHA),
             _table("SI_BDF_ERROR_CONST", bdf_tableau.ERROR_CONST)]
    return "".join(parts)


def pattern_prelude(indptr: np.ndarray, indices: np.ndarray) -> str:
    """The pattern of a model's Jacobian (CSC: column starts, row of each non-zero) as
    C (``SI_PATTERN_NNZ``, ``si_pattern_indptr``, ``si_pattern_indices``), for the
    implicit methods' grouped forward differences of a C model with no Jacobian."""
    def ints(name: str, values: np.ndarray) -> str:
        items = [str(int(v)) for v in values] or ["0"]
        rows = ",\n".join(", ".join(items[i:i + 20]) for i in range(0, len(items), 20))
        return f"static const int {name}[{len(items)}] = {{\n{rows}}};\n"
    return (f"#define SI_PATTERN_NNZ {int(indptr[-1])}\n" + ints("si_pattern_indptr", indptr)
            + ints("si_pattern_indices", indices))


def loop_text(model_c: str, pattern: tuple[np.ndarray, np.ndarray] | None = None) -> str:
    """The loop library's translation unit around the model's C text ``model_c``;
    ``pattern`` (CSC ``indptr``, ``indices``): the Jacobian's pattern that a C model
    without a Jacobian differences by groups of columns (None: one column at a
    time)."""
    head = ("#include <math.h>\n#undef SPRINGC_FN\n#define SPRINGC_FN static inline\n")
    return (head + model_c + "\n" + prelude(False) + rk45_prelude()
            + CORE.read_text(encoding="utf-8") + LOOP.read_text(encoding="utf-8")
            + implicit_prelude() + (pattern_prelude(*pattern) if pattern else "")
            + "".join(path.read_text(encoding="utf-8") for path in IMPLICIT))
