/* springc: one FMU instance (see springc_fmu.h). */
#include "springc_fmu.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SMI_NEVER 1e300

static void smi_layout(SmInstance *inst) {
    inst->x = inst->v + 1;
    inst->dx = inst->x + sm_nx;
    inst->p = inst->dx + sm_nx;
    inst->w = inst->p + sm_np;
}

SmInstance *smi_new(const char *name, int cosimulation, smi_logger log, void *api) {
    SmInstance *inst = (SmInstance *)calloc(1, sizeof(SmInstance));
    if (!inst) return NULL;
    inst->nv = 1 + 2 * sm_nx + sm_np + sm_nw + sm_ng;
    inst->v = (double *)calloc((size_t)inst->nv, sizeof(double));
    inst->given = (int *)calloc((size_t)inst->nv, sizeof(int));
    inst->z = (double *)calloc((size_t)sm_nz + 1, sizeof(double));
    inst->g = (double *)calloc((size_t)sm_ng + 1, sizeof(double));
    inst->g_prev = (double *)calloc((size_t)sm_ng + 1, sizeof(double));
    inst->work = (double *)calloc(11 * ((size_t)sm_nx + 1), sizeof(double));
    inst->name = (char *)malloc(strlen(name ? name : "") + 1);
    if (!inst->v || !inst->given || !inst->z || !inst->g || !inst->g_prev || !inst->work
        || !inst->name) {
        smi_free(inst);
        return NULL;
    }
    strcpy(inst->name, name ? name : "");
    inst->cosimulation = cosimulation;
    inst->log = log;
    inst->api = api;
    smi_layout(inst);
    smi_reset(inst);
    return inst;
}

void smi_free(SmInstance *inst) {
    if (!inst) return;
    free(inst->v);
    free(inst->given);
    free(inst->z);
    free(inst->g);
    free(inst->g_prev);
    free(inst->work);
    free(inst->name);
    free(inst);
}

/* the parameters' values and the states' start values; initial values where springc
 * solved the initial problem at export (valid while no parameter is set) */
static int smi_defaults(SmInstance *inst, int keep_given) {
    int i, parameters_given = 0;
    double *start = inst->work + 10 * sm_nx;
    for (i = 0; i < sm_np; ++i) parameters_given |= inst->given[1 + 2 * sm_nx + i];
    sm_parameters(inst->p, keep_given ? inst->given + 1 + 2 * sm_nx : NULL);
    memset(inst->z, 0, sizeof(double) * (size_t)sm_nz);
    if (sm_start(inst->p, start, inst->z) != 0) return SMI_ERROR;
    for (i = 0; i < sm_nx; ++i) {
        if (keep_given && inst->given[1 + i]) continue;
        inst->x[i] = sm_has_x_initial && !parameters_given ? sm_x_initial[i] : start[i];
    }
    return SMI_OK;
}

void smi_reset(SmInstance *inst) {
    memset(inst->v, 0, sizeof(double) * (size_t)inst->nv);
    memset(inst->given, 0, sizeof(int) * (size_t)inst->nv);
    smi_defaults(inst, 0);
    inst->mode = SMI_INSTANTIATED;
    inst->dirty = 1;
    inst->start_time = 0.0;
    inst->stop_time = SMI_NEVER;
    inst->stop_defined = 0;
    inst->tolerance = sm_tolerance;
    inst->h = 0.0;
    inst->next_event = SMI_NEVER;
    inst->terminated_by_model = 0;
}

/* the same instant as the pending time event: an importer's clock may round it */
static int smi_at_time_event(const SmInstance *inst, double t) {
    return fabs(inst->next_event - t) <= 1e-12 * (1.0 + fabs(t));
}

static void smi_ask_next_event(SmInstance *inst) {
    inst->next_event = sm_next_time_event(inst->v[0], inst->x, inst->p, inst->z);
}

static void smi_message(SmInstance *inst, int status, const char *text) {
    if (inst->log) inst->log(inst, status, text);
}

static int smi_failed(SmInstance *inst, int code) {
    char text[200];
    snprintf(text, sizeof text, "at time %.17g the nonlinear system %d of the model did "
             "not converge", inst->v[0], code - 1);
    smi_message(inst, SMI_DISCARD, text);
    return SMI_DISCARD;
}

/* the zero crossings at (t, x); one exactly at zero reads a tiny value on the side of
 * its relation's held value, so that leaving zero towards the other side is a sign
 * change (a contact closing exactly at a step's end, then pressing) */
int smi_crossings(SmInstance *inst, double t, const double *x, double *g) {
    int k, code = sm_crossings(t, x, inst->p, inst->z, g);
    if (sm_z_relations < 0) return code;
    for (k = 0; k < sm_ng; ++k) {
        if (g[k] == 0.0) {
            int held = inst->z[sm_z_relations + k] != 0.0;
            g[k] = (held == (sm_true_below[k] != 0)) ? -1e-300 : 1e-300;
        }
    }
    return code;
}

/* dx, w and the event indicators (after w) at the current time and states */
int smi_refresh(SmInstance *inst) {
    int code;
    if (!inst->dirty) return SMI_OK;
    code = sm_rhs(inst->v[0], inst->x, inst->p, inst->z, inst->dx);
    if (code == 0) code = sm_observed(inst->v[0], inst->x, inst->p, inst->z, inst->w);
    if (code == 0 && sm_ng > 0)
        code = smi_crossings(inst, inst->v[0], inst->x, inst->w + sm_nw);
    if (code != 0) return smi_failed(inst, code);
    inst->dirty = 0;
    return SMI_OK;
}

/* the value of value reference vr; NULL where it does not exist or may not be set */
double *smi_slot(SmInstance *inst, unsigned int vr, int for_writing) {
    unsigned int derivatives = 1u + (unsigned int)sm_nx;
    unsigned int parameters = derivatives + (unsigned int)sm_nx;
    unsigned int observed = parameters + (unsigned int)sm_np;
    if (vr >= (unsigned int)inst->nv) return NULL;
    if (for_writing) {
        if (vr == 0 || (vr >= derivatives && vr < parameters) || vr >= observed)
            return NULL; /* time, derivatives and observed values are computed */
        if (inst->mode != SMI_INSTANTIATED && inst->mode != SMI_INIT
            && (vr >= parameters || inst->cosimulation))
            return NULL; /* parameters are fixed once initialized */
        inst->dirty = 1;
        inst->given[vr] = 1;
        return inst->v + vr;
    }
    if (vr >= derivatives && inst->mode != SMI_INSTANTIATED && smi_refresh(inst) != SMI_OK)
        return NULL;
    return inst->v + vr;
}

int smi_enter_initialization(SmInstance *inst, int tolerance_defined, double tolerance,
                             double start_time, int stop_defined, double stop_time) {
    if (tolerance_defined && tolerance > 0) inst->tolerance = tolerance;
    inst->start_time = start_time;
    inst->v[0] = start_time;
    inst->stop_defined = stop_defined;
    inst->stop_time = stop_defined ? stop_time : SMI_NEVER;
    inst->mode = SMI_INIT;
    inst->dirty = 1;
    return SMI_OK;
}

static void smi_indicators(SmInstance *inst, double *g) {
    if (sm_ng > 0) smi_crossings(inst, inst->v[0], inst->x, g);
}

/* one event at the current time (the model iterates to its fixed point) */
static int smi_event(SmInstance *inst, int *states_changed) {
    double *before = inst->work + 10 * sm_nx;
    int code;
    if (smi_at_time_event(inst, inst->v[0])) inst->v[0] = inst->next_event;
    memcpy(before, inst->x, sizeof(double) * (size_t)sm_nx);
    code = sm_event_update(inst->v[0], inst->x, inst->p, inst->z);
    inst->dirty = 1;
    if (memcmp(before, inst->x, sizeof(double) * (size_t)sm_nx) != 0) *states_changed = 1;
    if (code == -2 || (sm_z_terminate >= 0 && inst->z[sm_z_terminate] > 0)) {
        inst->terminated_by_model = 1;
        smi_message(inst, SMI_OK, "the model called terminate()");
        return SMI_OK;
    }
    if (code == -1) {
        smi_message(inst, SMI_ERROR, "the event iteration did not settle");
        return SMI_ERROR;
    }
    return code > 0 ? smi_failed(inst, code) : SMI_OK;
}

/* the event at the current time: relations, when-clauses, reinit */
int smi_event_iteration(SmInstance *inst, int *states_changed, int *next_defined,
                        double *next_time) {
    int status = SMI_OK;
    *states_changed = 0;
    if (sm_z_initial >= 0) status = smi_event(inst, states_changed);
    if (status != SMI_OK) return status;
    if (smi_refresh(inst) != SMI_OK) return SMI_DISCARD;
    smi_indicators(inst, inst->g_prev);
    smi_ask_next_event(inst);
    *next_defined = inst->next_event < SMI_NEVER;
    *next_time = inst->next_event;
    return SMI_OK;
}

/* the initial problem: parameters, start values and the event at the start */
int smi_exit_initialization(SmInstance *inst) {
    int changed = 0, status;
    if (smi_defaults(inst, 1) != SMI_OK) {
        smi_message(inst, SMI_ERROR, "the start values have no solution");
        return SMI_ERROR;
    }
    inst->dirty = 1;
    if (sm_z_initial >= 0) {
        inst->z[sm_z_initial] = 1.0;
        status = smi_event(inst, &changed);
        inst->z[sm_z_initial] = 0.0;
        if (status == SMI_OK && sm_after_initial) status = smi_event(inst, &changed);
        if (status != SMI_OK) return status;
    }
    if (smi_refresh(inst) != SMI_OK) return SMI_ERROR;
    smi_indicators(inst, inst->g_prev);
    smi_ask_next_event(inst);
    inst->mode = inst->cosimulation ? SMI_STEP : SMI_EVENT;
    return SMI_OK;
}

/* the directional derivative of state derivatives (unknowns) along states (knowns):
 * the model's analytic Jacobian d(dx)/dx times the seed */
int smi_directional(SmInstance *inst, const unsigned int *unknowns, size_t n_unknowns,
                    const unsigned int *knowns, size_t n_knowns, const double *seed,
                    double *sensitivity) {
    unsigned int first_derivative = 1u + (unsigned int)sm_nx;
    int k, status = SMI_OK, *rows, *cols;
    size_t i, j;
    double *jv;
    for (i = 0; i < n_unknowns; ++i)
        if (unknowns[i] < first_derivative || unknowns[i] >= first_derivative + sm_nx) {
            smi_message(inst, SMI_ERROR, "directional derivatives: the unknowns must be "
                        "state derivatives");
            return SMI_ERROR;
        }
    for (j = 0; j < n_knowns; ++j)
        if (knowns[j] < 1u || knowns[j] >= first_derivative) {
            smi_message(inst, SMI_ERROR, "directional derivatives: the knowns must be "
                        "continuous states");
            return SMI_ERROR;
        }
    if (!sm_has_jacobian) {
        smi_message(inst, SMI_ERROR, "the model has no Jacobian in C");
        return SMI_ERROR;
    }
    rows = (int *)malloc(sizeof(int) * ((size_t)sm_njac + 1));
    cols = (int *)malloc(sizeof(int) * ((size_t)sm_njac + 1));
    jv = (double *)malloc(sizeof(double) * ((size_t)sm_njac + 1));
    for (i = 0; i < n_unknowns; ++i) sensitivity[i] = 0.0;
    if (!rows || !cols || !jv) {
        status = SMI_ERROR;
    } else {
        sm_jacobian_pattern(rows, cols);
        if (sm_jacobian(inst->v[0], inst->x, inst->p, inst->z, jv) != 0) status = SMI_DISCARD;
    }
    for (k = 0; status == SMI_OK && k < sm_njac; ++k)
        for (i = 0; i < n_unknowns; ++i)
            if ((int)(unknowns[i] - first_derivative) == rows[k])
                for (j = 0; j < n_knowns; ++j)
                    if ((int)(knowns[j] - 1u) == cols[k]) sensitivity[i] += jv[k] * seed[j];
    free(rows);
    free(cols);
    free(jv);
    return status;
}

void smi_set_time(SmInstance *inst, double t) {
    inst->v[0] = t;
    inst->dirty = 1;
}

void smi_set_states(SmInstance *inst, const double *x) {
    memcpy(inst->x, x, sizeof(double) * (size_t)sm_nx);
    inst->dirty = 1;
}

static int smi_crossed(double before, double after) {
    return (before > 0.0) != (after > 0.0) && (before != 0.0 || after != 0.0);
}

static int smi_any_crossing(const double *before, const double *after) {
    int i;
    for (i = 0; i < sm_ng; ++i)
        if (smi_crossed(before[i], after[i])) return 1;
    return 0;
}

int smi_completed_step(SmInstance *inst, int *enter_event) {
    *enter_event = 0; /* the importer locates crossings on the event indicators */
    return smi_refresh(inst);
}

/* ---- Co-Simulation: Dormand-Prince 5(4) with error control ---- */

static const double DP_C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
static const double DP_A[7][6] = {
    {0, 0, 0, 0, 0, 0},
    {1.0 / 5, 0, 0, 0, 0, 0},
    {3.0 / 40, 9.0 / 40, 0, 0, 0, 0},
    {44.0 / 45, -56.0 / 15, 32.0 / 9, 0, 0, 0},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0, 0},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
/* fifth-order weights minus fourth-order weights: the error estimate */
static const double DP_E[7] = {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920,
                               -17253.0 / 339200, 22.0 / 525, -1.0 / 40};

/* one step of size h from (t, x0) into x1 (x0 == inst->x untouched); the error norm
 * in *err; returns non-zero where the model failed to evaluate */
static int dp_step(SmInstance *inst, double t, const double *x0, double h, double *x1,
                   double *err) {
    int n = sm_nx, s, j, i;
    double *k = inst->work;        /* 7 stages of n */
    double *y = inst->work + 7 * n; /* stage argument */
    double sum = 0.0;
    for (s = 0; s < 7; ++s) {
        for (i = 0; i < n; ++i) {
            double acc = x0[i];
            for (j = 0; j < s; ++j) acc += h * DP_A[s][j] * k[j * n + i];
            y[i] = acc;
        }
        if (s == 6) memcpy(x1, y, sizeof(double) * (size_t)n);
        if (sm_rhs(t + DP_C[s] * h, y, inst->p, inst->z, k + s * n) != 0) return 1;
    }
    for (i = 0; i < n; ++i) {
        double e = 0.0, scale;
        for (s = 0; s < 7; ++s) e += DP_E[s] * k[s * n + i];
        e *= h;
        scale = inst->tolerance * (1.0 + fmax(fabs(x0[i]), fabs(x1[i])));
        sum += (e / scale) * (e / scale);
    }
    *err = n > 0 ? sqrt(sum / n) : 0.0;
    return 0;
}

/* the state at t + theta (one step of that size from x0), its indicators in g */
static int dp_probe(SmInstance *inst, double t, const double *x0, double theta,
                    double *x, double *g) {
    double err;
    if (dp_step(inst, t, x0, theta, x, &err) != 0) return 1;
    return smi_crossings(inst, t + theta, x, g) != 0;
}

/* bisection on the step size for the first crossing between t and t + h: the state
 * just after it in x, its time returned */
static double dp_locate(SmInstance *inst, double t, const double *x0, double h,
                        double *x, double *g) {
    double lo = 0.0, hi = h;
    int i;
    for (i = 0; i < 200 && hi - lo > 1e-14 * (1.0 + fabs(t)); ++i) {
        double mid = 0.5 * (lo + hi);
        if (dp_probe(inst, t, x0, mid, x, g) != 0) break;
        if (smi_any_crossing(inst->g_prev, g)) hi = mid; else lo = mid;
    }
    dp_probe(inst, t, x0, hi, x, g);
    return t + hi;
}

/* the event at the current time inside doStep; the solver restarts with a small step,
 * so that the indicators leave zero before a step could cross one twice (a bounce
 * whose rise and fall fit in one step would be missed) */
static int smi_step_event(SmInstance *inst, int *terminate, double step) {
    int changed = 0, status = smi_event(inst, &changed);
    inst->h = fmin(inst->h, 1e-6 * step);
    if (status == SMI_OK) status = smi_refresh(inst);
    smi_indicators(inst, inst->g_prev);
    if (inst->terminated_by_model) *terminate = 1;
    return status;
}

int smi_do_step(SmInstance *inst, double t0, double step, int *terminate,
                double *last_time) {
    int n = sm_nx;
    double t = inst->v[0], t_end = t0 + step;
    double *x1 = inst->work + 8 * n, *x0 = inst->work + 9 * n;
    double *g = inst->g;
    *terminate = 0;
    if (smi_refresh(inst) != SMI_OK) return SMI_DISCARD;
    if (inst->h <= 0.0) inst->h = fmin(step, 1e-3 * fmax(1.0, fabs(step)));
    while (t < t_end - 1e-13 * (1.0 + fabs(t_end))) {
        double next = sm_next_time_event(t, inst->x, inst->p, inst->z);
        inst->next_event = next;
        /* a time event rounded just past the end of the step is taken in it */
        double target = next <= t_end + 1e-12 * (1.0 + fabs(t_end)) ? next : t_end;
        double h = fmin(inst->h, target - t), err = 0.0;
        int hits_target = h >= target - t;
        if (hits_target) h = target - t;
        memcpy(x0, inst->x, sizeof(double) * (size_t)n);
        if (n > 0 && dp_step(inst, t, x0, h, x1, &err) != 0) {
            inst->h = 0.5 * h;
            if (inst->h < 1e-14 * (1.0 + fabs(t))) break;
            continue;
        }
        if (err > 1.0) {
            inst->h = h * fmax(0.2, 0.9 * pow(err, -0.2));
            continue;
        }
        /* accepted: look for a state event inside the step */
        if (sm_ng > 0 && smi_crossings(inst, t + h, x1, g) != 0) break;
        if (sm_ng > 0 && smi_any_crossing(inst->g_prev, g)) {
            double te = dp_locate(inst, t, x0, h, x1, g);
            memcpy(inst->x, x1, sizeof(double) * (size_t)n);
            smi_set_time(inst, te);
            t = te;
            if (smi_step_event(inst, terminate, step) != SMI_OK) return SMI_ERROR;
        } else {
            memcpy(inst->x, x1, sizeof(double) * (size_t)n);
            t = hits_target ? target : t + h;
            smi_set_time(inst, t);
            memcpy(inst->g_prev, g, sizeof(double) * (size_t)sm_ng);
            if (hits_target && target == next) {
                if (smi_step_event(inst, terminate, step) != SMI_OK) return SMI_ERROR;
            }
            if (!hits_target || h == inst->h)
                inst->h = h * fmin(5.0, 0.9 * pow(fmax(err, 1e-10), -0.2));
        }
        if (*terminate) break;
    }
    *last_time = t;
    if (t < t_end - 1e-13 * (1.0 + fabs(t_end)) && !*terminate) {
        smi_message(inst, SMI_DISCARD, "the step size fell below the time resolution");
        return SMI_DISCARD;
    }
    smi_set_time(inst, t_end);
    return smi_refresh(inst);
}
