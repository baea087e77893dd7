"""The per-model C file of an FMU (``springc_glue.c``): includes the model's generated C
code (``model.c``, :func:`springc.codegen.generate_c`) and gives the FMU wrapper
(``c/springc_fmu.c``) the names of ``c/springc_glue.h`` around it: sizes, the
instantiation token, the states' nominal and initial values, and the model functions.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

MODEL_FILE = "model.c"
GLUE_FILE = "springc_glue.c"


def _doubles(values: Sequence[float]) -> str:
    """A C initializer of at least one element (C has no empty arrays)."""
    return "{" + ", ".join(repr(float(v)) if math.isfinite(v) else "0.0"
                           for v in (list(values) or [0.0])) + "}"


DEFAULT_TOLERANCE = 1e-6
"""Co-Simulation's relative tolerance where neither the importer nor the model's
experiment annotation gives one."""


def _flags(values: Sequence[bool]) -> str:
    return "{" + ", ".join(str(int(v)) for v in (list(values) or [False])) + "}"


def glue_source(token: str, nominals: Sequence[float],
                initial: Sequence[float] | None, tolerance: float | None = None,
                true_below: Sequence[bool] = ()) -> str:
    """``springc_glue.c``: ``initial`` the consistent initial states springc computed at
    the default parameters (None: the start values of ``springc_start`` are initial);
    ``tolerance`` the experiment annotation's (None: :data:`DEFAULT_TOLERANCE`);
    ``true_below``: for each zero crossing ``g = left - right``, whether its relation
    holds below zero (``<``, ``<=``), so that an indicator exactly at zero reads on the
    side of the relation's held value (empty: no relations)."""
    return f"""/* springc: the FMU's view of the model in {MODEL_FILE} (springc_glue.h). */
#include <math.h>

#include "{MODEL_FILE}"
#include "springc_glue.h"

const int sm_nx = SPRINGC_N_STATES;
const int sm_np = SPRINGC_N_PARAMS;
const int sm_nw = SPRINGC_N_OBSERVED;
const int sm_nz = SPRINGC_N_Z;
const int sm_ng = SPRINGC_N_CROSSINGS;
#if SPRINGC_HYBRID
const int sm_z_initial = SPRINGC_Z_INITIAL;
const int sm_z_terminate = SPRINGC_Z_TERMINATE;
const int sm_after_initial = SPRINGC_AFTER_INITIAL;
#else
const int sm_z_initial = -1;
const int sm_z_terminate = -1;
const int sm_after_initial = 0;
#endif
const int sm_has_x_initial = {0 if initial is None else 1};
const double sm_nominals[] = {_doubles(nominals)};
const double sm_x_initial[] = {_doubles(initial or [])};
const int sm_z_relations = {"SPRINGC_Z_RELATIONS" if true_below else "-1"};
const unsigned char sm_true_below[] = {_flags(true_below)};
const int sm_has_jacobian = SPRINGC_HAS_JACOBIAN;
const int sm_njac = SPRINGC_N_JAC;
const double sm_tolerance = {float(tolerance or DEFAULT_TOLERANCE)!r};
const char *const sm_token = "{token}";

void sm_parameters(double *p, const int *given) {{ springc_parameters(p, given); }}

int sm_start(const double *p, double *x, double *z) {{ return springc_start(p, x, z); }}

int sm_rhs(double t, const double *x, const double *p, double *z, double *dx) {{
    return springc_rhs(t, x, p, z, dx);
}}

int sm_observed(double t, const double *x, const double *p, double *z, double *w) {{
    return springc_observed(t, x, p, z, w);
}}

int sm_crossings(double t, const double *x, const double *p, double *z, double *g) {{
    return springc_zero_crossings(t, x, p, z, g);
}}

double sm_next_time_event(double t, const double *x, const double *p, double *z) {{
    return springc_next_time_event(t, x, p, z);
}}

int sm_event_update(double t, double *x, const double *p, double *z) {{
    return springc_event_update(t, x, p, z);
}}

void sm_jacobian_pattern(int *rows, int *cols) {{ springc_jacobian_pattern(rows, cols); }}

int sm_jacobian(double t, const double *x, const double *p, double *z, double *jv) {{
    return springc_jacobian(t, x, p, z, jv);
}}
"""
