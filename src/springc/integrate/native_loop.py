"""The compiled engine's single-run loop in C: a model's C text -> the translation unit
of its loop library (DOP853 and RK45, ``single_loop.c``).

One text per model: the model's C functions (``static inline``, so that the C
compiler inlines them into the loop, and its name tables), the DOP853 tableau's
weighted sums written out (:func:`.native_ensemble.prelude`), RK45's
(:func:`rk45_prelude`), DOP853's step arithmetic shared with the ensemble kernel
(``dop853_core.c``) and the loop (``single_loop.c``): the contract of
:mod:`.loop` (its ``adaptive_loop`` specialised on :mod:`.dop853_steps` or
:mod:`.rk45_steps` with plain-loop sums), every operation in the same order. The
library is built by :func:`springc.pipeline.loop_library` and run by
:mod:`springc.native.runner` (stdlib and ctypes only). Imports nothing from springc.
"""

from __future__ import annotations

from pathlib import Path

from . import rk45_tableau
from .native_ensemble import CORE, c_array, c_switch, c_weighted_sum, prelude

LOOP = Path(__file__).with_name("single_loop.c")
ABI = 1
"""The interface version of the library's exports (``springc_loop_abi()``): a change of
an export's arguments moves it, and the runner refuses a library of another."""
METHODS = {"dop853": 0, "rk45": 1}
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


def loop_text(model_c: str) -> str:
    """The loop library's translation unit around the model's C text ``model_c``."""
    head = ("#include <math.h>\n#undef SPRINGC_FN\n#define SPRINGC_FN static inline\n")
    return (head + model_c + "\n" + prelude(False) + rk45_prelude()
            + CORE.read_text(encoding="utf-8") + LOOP.read_text(encoding="utf-8"))
