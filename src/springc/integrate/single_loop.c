/* springc's single-run loop in C: the compiled engine's adaptive loop for DOP853,
   RK45, Radau IIA and BDF on a model's C functions, one shared library per model with
   the model.

   springc.integrate.native_loop puts the translation unit together: the model's C text
   (its functions static inline), the DOP853 tableau's sums (sc_a_row ...), RK45's
   (rk_a_row, rk_b_sum, rk_e_sum, rk_p_col, RK_C), the status codes (SC_SUCCESS ...),
   dop853_core.c (DOP853's step arithmetic, shared with the ensemble kernel), then this,
   then the implicit methods' constants and their hooks (implicit_core.c: si_create,
   si_begin, si_step, si_dense, declared here).

   The contract is springc.integrate.loop's adaptive_loop specialised on
   dop853_steps / rk45_steps with plain-loop sums (scipy_arithmetic off), with its zero
   crossings against held signs (crossings.py, no direction filters) and its time event
   t_stop where the run has them (a hybrid model's run between two events, the Python
   side doing the event update): the same start, initial step (scipy's
   select_initial_step), step-size clamp, controller, step limit (accepted and
   rejected steps), dense output on the grid and result record, every operation in the
   same order, so that on one machine the states equal the numba loop's within
   rounding of the math library's functions, with the same steps. A run that stops at
   the step limit goes on from (failure_time, failure_state, next_step) as one
   uninterrupted run would. Nothing here allocates but the run's work arrays. Radau
   and BDF are the loop specialised on radau_steps / bdf_steps the same way (see
   implicit_core.c, radau_steps.c, bdf_steps.c). */

#include <stdlib.h>

#ifndef SPRINGC_LOOP_EXPORT
#define SPRINGC_LOOP_EXPORT __attribute__((visibility("default")))
#endif
#define SL_ABI 3
#define SL_DOP853 0
#define SL_RK45 1
#define SL_RADAU 2
#define SL_BDF 3
#define SL_RK_STAGES 6
#define SL_HUGE 1.7976931348623157e308
#define SL_ACCEPTED 0
#define SL_REJECTED 1
#define SL_RHS_CALLS 2
#define SL_JACOBIAN_CALLS 3

typedef long long sl_int;
struct si_work;

/* The run's work arrays (rows of SC_NXS doubles). */
typedef struct {
    double *K;      /* the stages: 16 rows (DOP853), 7 (RK45) */
    double *F;      /* DOP853's dense output rows (7); RK45's Q (n x 4) */
    double *stage, *sums, *scale, *err5, *err3, *y, *y_new;
    double *z_step; /* z at the step's start (a hybrid model's trial points: sl_step) */
    double *z_end;  /* z at the accepted step's end (kept across its dense output) */
    int method;
    struct si_work *implicit;  /* Radau's or BDF's work (implicit_core.c), else NULL */
} sl_work;

/* The implicit methods' hooks (implicit_core.c). */
SC_FN int si_begin(struct si_work *s, double t, const double *y, const double *f,
                   double h_abs, const double *p, double *z, double rtol, sl_int *counts,
                   double *end);
SC_FN int si_step(struct si_work *s, double t, const double *y, double h_proposed,
                  double *h_abs, double min_step, double limit, const double *p, double *z,
                  double rtol, const double *atol, sl_int *counts, double *y_new,
                  double *end, double *t_new, double *h, double *t_fail);
SC_FN void si_dense(const struct si_work *s, double t, double h, const double *y, double at,
                    double *out);
SC_FN struct si_work *si_create(int method, const sl_int *order);
SC_FN void si_free(struct si_work *s);

SC_FN void sl_copy(double *dst, const double *src) {
    for (int i = 0; i < SC_NX; i++) dst[i] = src[i];
}

SC_FN void sl_copy_z(double *dst, const double *src) {
    for (int i = 0; i < SPRINGC_N_Z; i++) dst[i] = src[i];
}

/* springc_rhs at (t, x) into out, its verdict. A hybrid model's Newton block that did
   not converge from the warm starts in z is solved again from those of the step's
   start (w->z_step, an accepted point), where they differ: the rule of the scipy
   engine's Problem.solved (springc.simulation.steps). An accepted step may end past an
   event not yet located, on a held branch whose solution is far from the one inside
   the step (HeatingNPN_NORGate: from C1.v = -1.39 V past V1's ramp end at 80 s,
   Newton cycles at a stage of the step's dense output at 79.88 s). */
SC_FN int sl_rhs(const sl_work *w, double t, const double *x, const double *p, double *z,
                 double *out, sl_int *counts) {
    springc_rhs(t, x, p, z, out);
    counts[SL_RHS_CALLS] += 1;
    int status = sc_verdict(out, z);
    if (!SPRINGC_HYBRID || status != SC_MODEL_FAILED) return status;
    int same = 1;
    for (int i = 0; i < SPRINGC_N_Z - 1; i++) same = same && z[i] == w->z_step[i];
    if (same) return status;
    sl_copy_z(z, w->z_step);  /* its failure flag clear: an accepted point's */
    springc_rhs(t, x, p, z, out);
    counts[SL_RHS_CALLS] += 1;
    return sc_verdict(out, z);
}

/* numba's rms of plain sums: sqrt(x . x) / n ** 0.5 */
SC_FN double sl_rms(const double *x) {
    double total = 0.0;
    for (int i = 0; i < SC_NX; i++) total += x[i] * x[i];
    return sqrt(total) / pow((double)SC_NX, 0.5);
}

/* scipy's select_initial_step from (t, y) with the derivative f there (loop.initial_step);
   the status; h_abs, or the time of a failed evaluation (its state left in end). A
   hybrid model's probe at t + h0 is a point a step only tries (Problem.start): z keeps
   the warm starts of (t, y), and a probe that fails counts as scipy's NaN there (its
   max(d1, NaN) is d1), the step size then from (t, y) alone. */
SC_FN int sl_initial_step(double t, const double *y, const double *f, double limit,
                          const double *p, double *z, double rtol, const double *atol,
                          double max_step, double exponent, sl_work *w, double *end,
                          sl_int *counts, double *h_abs, double *t_fail) {
    double *scale = w->scale, *d = w->sums, interval = limit - t;
    for (int i = 0; i < SC_NX; i++) {
        scale[i] = atol[i] + fabs(y[i]) * rtol;
        end[i] = y[i] / scale[i];
    }
    double d0 = sl_rms(end);
    for (int i = 0; i < SC_NX; i++) end[i] = f[i] / scale[i];
    double d1 = sl_rms(end);
    double h0 = d0 < 1e-5 || d1 < 1e-5 ? 1e-6 : 0.01 * d0 / d1;
    h0 = sc_min(h0, interval);
    for (int i = 0; i < SC_NX; i++) end[i] = y[i] + h0 * f[i];
    if (SPRINGC_HYBRID) sl_copy_z(w->z_end, z);
    springc_rhs(t + h0, end, p, z, d);
    counts[SL_RHS_CALLS] += 1;
    int status = sc_verdict(d, z);
    *t_fail = t;
    if (SPRINGC_HYBRID) {
        sl_copy_z(z, w->z_end);
        if (status != SC_SUCCESS) {
            double h1 = pow(0.01 / d1, exponent);
            *h_abs = sc_min(sc_min(sc_min(100 * h0, h1), interval), max_step);
            if (!(*h_abs > 0.0)) {
                sl_copy(end, y);
                return SC_STEP_TOO_SMALL;
            }
            return SC_SUCCESS;
        }
    }
    if (status != SC_SUCCESS) {
        *h_abs = 0.0;
        *t_fail = t + h0;
        return status;
    }
    for (int i = 0; i < SC_NX; i++) scale[i] = (d[i] - f[i]) / scale[i];
    double d2 = sl_rms(scale) / h0;
    double h1 = d1 <= 1e-15 && d2 <= 1e-15 ? sc_max(1e-6, h0 * 1e-3)
                                           : pow(0.01 / sc_max(d1, d2), exponent);
    *h_abs = sc_min(sc_min(sc_min(100 * h0, h1), interval), max_step);
    if (!(*h_abs > 0.0)) {
        sl_copy(end, y);
        return SC_STEP_TOO_SMALL;
    }
    return SC_SUCCESS;
}

/* The stages of one attempt from (t, y) with step h, the new state in y_new and the
   FSAL evaluation in K's last row; a failed evaluation's time in t_fail, state in end. */
SC_FN int sl_stages(const sl_work *w, double t, double h, const double *p, double *z,
                    sl_int *counts, double *end, double *t_fail) {
    const double *y = w->y;
    double *K = w->K, *sums = w->sums, *stage = w->stage, *y_new = w->y_new;
    int dop = w->method == SL_DOP853, stages = dop ? SC_STAGES : SL_RK_STAGES;
    for (int s = 1; s < stages; s++) {
        double c = dop ? DOP_C[s] : RK_C[s];
        if (dop) {
            sc_stage(y, K, s, h, sums, stage);
        } else {
            rk_a_row(s, K, sums);
            for (int i = 0; i < SC_NX; i++) stage[i] = y[i] + sums[i] * h;
        }
        int status = sl_rhs(w, t + c * h, stage, p, z, K + s * SC_NXS, counts);
        if (status != SC_SUCCESS) {
            sl_copy(end, stage);
            *t_fail = t + c * h;
            return status;
        }
    }
    if (dop) sc_b_sum(K, sums);
    else rk_b_sum(K, sums);
    for (int i = 0; i < SC_NX; i++) y_new[i] = y[i] + h * sums[i];
    int status = sl_rhs(w, t + h, y_new, p, z, K + stages * SC_NXS, counts);
    if (status != SC_SUCCESS) {
        sl_copy(end, y_new);
        *t_fail = t + h;
    }
    return status;
}

/* RK45's error norm of the attempt (rk45_steps.step). */
SC_FN double sl_rk45_error(const sl_work *w, double h, double rtol, const double *atol) {
    double *err = w->err5, *scale = w->scale;
    rk_e_sum(w->K, err);
    for (int i = 0; i < SC_NX; i++) {
        scale[i] = atol[i] + sc_max(fabs(w->y[i]), fabs(w->y_new[i])) * rtol;
        err[i] = err[i] * h / scale[i];
    }
    double total = 0.0;
    for (int i = 0; i < SC_NX; i++) total += err[i] * err[i];
    return pow(total / SC_NX, 0.5);
}

/* One accepted step from (t, y) (the step hook of dop853_steps / rk45_steps: rejected
   attempts inside); *h_abs in: the clamped size, out: the next one. A hybrid model's
   attempt whose evaluation sets the failure flag (a Newton iteration that does not
   converge at a stage's trial point) is rejected as a non-finite one is, z put back
   as it was at the step's start: the rule of the scipy engine's event loop
   (springc.simulation.steps.Problem.rhs), which ran these models before. */
SC_FN int sl_step(const sl_work *w, double t, double *h_abs, double min_step, double limit,
                  const double *p, double *z, double rtol, const double *atol,
                  sl_int *counts, double *end, double *t_new, double *h, double *t_fail) {
    int dop = w->method == SL_DOP853, stages = dop ? SC_STAGES : SL_RK_STAGES;
    double exponent = dop ? -1.0 / 8.0 : -1.0 / (4 + 1);
    sl_copy(w->K, w->K + stages * SC_NXS);
    if (SPRINGC_HYBRID)
        for (int i = 0; i < SPRINGC_N_Z; i++) w->z_step[i] = z[i];
    int rejected = 0;
    for (;;) {
        if (*h_abs < min_step) {
            sl_copy(end, w->y);
            *t_new = t;
            *h = 0.0;
            *t_fail = t;
            return SC_STEP_TOO_SMALL;
        }
        *t_new = t + *h_abs;
        if (*t_new - limit > 0) *t_new = limit;
        *h = *t_new - t;
        *h_abs = fabs(*h);
        int status = sl_stages(w, t, *h, p, z, counts, end, t_fail);
        int retried = SPRINGC_HYBRID && status == SC_MODEL_FAILED && *h_abs * 0.2 >= min_step;
        if (retried)
            for (int i = 0; i < SPRINGC_N_Z; i++) z[i] = w->z_step[i];
        if ((retried || status == SC_NON_FINITE_DERIVATIVE) && *h_abs * 0.2 >= min_step) {
            *h_abs *= 0.2;  /* dop853_steps.shrinks: rejected, as scipy's NaN error is */
            rejected = 1;
            counts[SL_REJECTED] += 1;
            continue;
        }
        if (status != SC_SUCCESS) {
            *t_new = t;
            return status;
        }
        double error = dop ? sc_error_norm(w->y, w->y_new, w->K, *h, rtol, atol, w->scale,
                                           w->err5, w->err3)
                           : sl_rk45_error(w, *h, rtol, atol);
        if (error < 1) {
            double factor = error == 0 ? 10.0 : sc_min(10.0, 0.9 * pow(error, exponent));
            if (rejected) factor = sc_min(1.0, factor);
            *h_abs = *h_abs * factor;
            *t_fail = t;
            return SC_SUCCESS;
        }
        *h_abs *= sc_max(0.2, 0.9 * pow(error, exponent));
        rejected = 1;
        counts[SL_REJECTED] += 1;
    }
}

/* What the dense output of the step needs (prepare_dense): DOP853's three extra stages
   and its rows F; RK45's Q = K^T P. A hybrid model's z keeps the accepted end's warm
   starts (Problem.dense_output): the extra stages lie inside the step. */
SC_FN int sl_prepare_dense(const sl_work *w, double t, double h, const double *p, double *z,
                           sl_int *counts, double *end, double *t_fail) {
    double *K = w->K;
    if (w->implicit) return SC_SUCCESS;  /* the step's polynomial is its dense output */
    if (w->method == SL_DOP853) {
        if (SPRINGC_HYBRID) sl_copy_z(w->z_end, z);
        for (int s = SC_STAGES + 1; s < SC_EXTENDED; s++) {
            sc_stage(w->y, K, s, h, w->sums, w->stage);
            int status = sl_rhs(w, t + DOP_C[s] * h, w->stage, p, z, K + s * SC_NXS,
                                counts);
            if (status != SC_SUCCESS) {
                sl_copy(end, w->stage);
                *t_fail = t + DOP_C[s] * h;
                return status;
            }
        }
        if (SPRINGC_HYBRID) sl_copy_z(z, w->z_end);
        sc_interpolant(w->y, w->y_new, K, h, w->F, w->sums);
        return SC_SUCCESS;
    }
    for (int r = 0; r < 4; r++) {
        rk_p_col(r, K, w->sums);
        for (int i = 0; i < SC_NX; i++) w->F[i * 4 + r] = w->sums[i];
    }
    return SC_SUCCESS;
}

/* The dense output of the step from (t, y) with size h at time at, into out. */
SC_FN void sl_dense(const sl_work *w, double t, double h, double at, double *out) {
    if (w->implicit) {
        si_dense(w->implicit, t, h, w->y, at, out);
        return;
    }
    double x = (at - t) / h;
    if (w->method == SL_DOP853) {
        sc_interpolate(w->F, w->y, x, out);
        return;
    }
    double powers[4], power = 1.0;
    for (int r = 0; r < 4; r++) {
        power *= x;
        powers[r] = power;
    }
    for (int i = 0; i < SC_NX; i++) {
        double value = 0.0;
        for (int r = 0; r < 4; r++) value += w->F[i * 4 + r] * powers[r];
        out[i] = h * value + w->y[i];
    }
}

/* The result record after the loop (adaptive_loop's Step 8). */
typedef struct {
    sl_int *counts;   /* accepted, rejected, rhs evaluations, (Jacobians: 0), filled */
    double *reals;    /* failure time, next step size */
    double *end;      /* the failure state */
} sl_record;

/* The zero crossings of a run between events (adaptive_loop's Steps 4 and 6): n_g
   indicators, their held signs, the crossing found (fired: +1 rising, -1 falling, 0),
   the indicators at the step's start and end (g0, g1) and at a bisection point (gt),
   and the time event t_stop (INFINITY: none). n_g 0 and t_stop INFINITY: a continuous
   run, step for step the loop without events. */
typedef struct {
    sl_int n_g;
    const double *signs;
    sl_int *fired, *trial;
    double *g0, *g1, *gt;
    double t_stop;
} sl_events;

/* crossings.crossings without direction filters: whether some indicator went from its
   held side (or zero) at g_start strictly to the other at g_end; fired[i] its direction. */
SC_FN int sl_crossed(const sl_events *ev, const double *g_start, const double *g_end,
                     sl_int *fired) {
    int any = 0;
    for (sl_int i = 0; i < ev->n_g; i++) {
        double s = ev->signs[i];
        fired[i] = 0;
        if (s * g_start[i] >= 0.0 && s * g_end[i] < 0.0) {
            fired[i] = s < 0 ? 1 : -1;
            any = 1;
        }
    }
    return any;
}

/* crossings.time_tolerance: the bracket width at which a crossing counts as located. */
SC_FN double sl_time_tolerance(double t, double t_new) {
    double width = 1e-12 * sc_max(sc_max(fabs(t), fabs(t_new)), t_new - t);
    double ulp = nextafter(fabs(t_new), INFINITY) - fabs(t_new);
    return sc_max(width, 4.0 * ulp);
}

/* The earliest crossing in (t, t_new] by bisection on the step's dense output (Step 6):
   its time; ev->fired the indicators crossed there; y_new the state there. */
SC_FN double sl_locate(sl_work *w, const sl_events *ev, double t, double t_new, double h,
                       const double *p, double *z) {
    double low = t, high = t_new, tolerance = sl_time_tolerance(t, t_new);
    while (high - low > tolerance) {
        double middle = low + 0.5 * (high - low);
        if (middle <= low || middle >= high) break;
        sl_dense(w, t, h, middle, w->stage);
        springc_zero_crossings(middle, w->stage, p, z, ev->gt);
        if (sl_crossed(ev, ev->g0, ev->gt, ev->trial)) {
            high = middle;
            for (sl_int i = 0; i < ev->n_g; i++) ev->fired[i] = ev->trial[i];
        } else {
            low = middle;
        }
    }
    if (high < t_new) sl_dense(w, t, h, high, w->y_new);
    return high;
}

/* The output times in (t, t_event) and t_event itself unless the run stops there (at
   an event): the states there; the new number filled. */
SC_FN sl_int sl_fill(const sl_work *w, sl_int filled, sl_int m, const double *grid,
                     double t, double t_new, double h, double t_event, int stops,
                     double *states) {
    while (filled < m && (grid[filled] < t_event || (grid[filled] == t_event && !stops))) {
        double *row = states + filled * SC_NX;
        if (grid[filled] == t_new) sl_copy(row, w->y_new);
        else sl_dense(w, t, h, grid[filled], row);
        filled += 1;
    }
    return filled;
}

/* The steps from (t, y) until the end of the grid, the time event or the first
   crossing (adaptive_loop's Step 3 on). */
SC_FN int sl_steps(sl_work *w, const sl_events *ev, sl_int m, const double *grid,
                   const double *p, double *z, double rtol, const double *atol,
                   double max_step, sl_int max_steps, double *states, sl_int *filled,
                   double *t_io, double *h_abs, sl_record *rec) {
    sl_int *counts = rec->counts;
    double t = *t_io, t_end = grid[m - 1], limit = sc_min(t_end, ev->t_stop), t_fail = t;
    int status = SC_SUCCESS;
    while (t < limit) {
        if (max_steps > 0 && counts[SL_ACCEPTED] + counts[SL_REJECTED] >= max_steps) {
            status = SC_MAX_STEPS;
            sl_copy(rec->end, w->y);
            t_fail = t;
            break;
        }
        double min_step = 10 * fabs(nextafter(t, SL_HUGE) - t), h_proposed = *h_abs;
        if (*h_abs > max_step) *h_abs = max_step;
        else if (*h_abs < min_step) *h_abs = min_step;
        double t_new, h;
        if (w->implicit)
            status = si_step(w->implicit, t, w->y, h_proposed, h_abs, min_step, limit, p, z,
                             rtol, atol, counts, w->y_new, rec->end, &t_new, &h, &t_fail);
        else
            status = sl_step(w, t, h_abs, min_step, limit, p, z, rtol, atol, counts,
                             rec->end, &t_new, &h, &t_fail);
        if (status != SC_SUCCESS) break;
        counts[SL_ACCEPTED] += 1;
        int event = 0;
        if (ev->n_g > 0) {
            springc_zero_crossings(t_new, w->y_new, p, z, ev->g1);
            if (sc_flagged(z)) {
                status = SC_MODEL_FAILED;
                t_fail = t_new;
                sl_copy(rec->end, w->y_new);
                break;
            }
            event = sl_crossed(ev, ev->g0, ev->g1, ev->fired);
        }
        if (event || (*filled < m && grid[*filled] <= t_new)) {
            status = sl_prepare_dense(w, t, h, p, z, counts, rec->end, &t_fail);
            if (status != SC_SUCCESS) break;
        }
        double t_event = event ? sl_locate(w, ev, t, t_new, h, p, z) : t_new;
        int stops = event || (t_new == ev->t_stop && ev->t_stop < t_end);
        *filled = sl_fill(w, *filled, m, grid, t, t_new, h, t_event, stops, states);
        if (event) {
            status = SC_STATE_EVENT;
            t_fail = t_event;
            sl_copy(rec->end, w->y_new);
            break;
        }
        t = t_new;
        sl_copy(w->y, w->y_new);
        for (sl_int i = 0; i < ev->n_g; i++) ev->g0[i] = ev->g1[i];
    }
    rec->reals[0] = t_fail;
    *t_io = t;
    return status;
}

/* The whole run (adaptive_loop): see springc.native.runner for the arguments. */
SC_FN int sl_run(sl_work *w, const sl_events *ev, sl_int m, const double *grid,
                 const double *x0, const double *p, double *z, double rtol,
                 const double *atol, double max_step, double first_step, sl_int max_steps,
                 double *states, sl_record *rec) {
    sl_int *counts = rec->counts, filled = 1;
    double t = grid[0], h_abs = 0.0, t_fail = t, limit = sc_min(grid[m - 1], ev->t_stop);
    int status = SC_SUCCESS;
    sl_copy(w->y, x0);
    sl_copy(rec->end, x0);
    sl_copy(states, x0);
    if (ev->n_g > 0 && !sc_flagged(z)) springc_zero_crossings(t, w->y, p, z, ev->g0);
    if (SPRINGC_HYBRID) sl_copy_z(w->z_step, z);  /* an accepted point (sl_rhs) */
    if (sc_flagged(z)) {
        status = SC_MODEL_FAILED;
        filled = 0;
    }
    int running = status == SC_SUCCESS && m > 1 && SC_NX > 0;
    if (status == SC_SUCCESS && !running) {
        for (sl_int k = 1; k < m; k++) sl_copy(states + k * SC_NX, w->y);
        filled = m;
    }
    if (running) {
        int order = w->method == SL_DOP853 ? 7 : w->method == SL_RK45 ? 4
                    : w->method == SL_RADAU ? 3 : 1;  /* of the error estimator */
        double *f = w->implicit ? w->K
                    : w->K + (w->method == SL_DOP853 ? SC_STAGES : SL_RK_STAGES) * SC_NXS;
        springc_rhs(t, w->y, p, z, f);
        counts[SL_RHS_CALLS] += 1;
        status = sc_verdict(f, z);
        if (status == SC_SUCCESS) {
            if (first_step > 0.0) {
                h_abs = first_step;
            } else {
                status = sl_initial_step(t, w->y, f, limit, p, z, rtol, atol,
                                         max_step, 1.0 / (order + 1), w, rec->end, counts,
                                         &h_abs, &t_fail);
            }
        }
        if (status == SC_SUCCESS && w->implicit)
            status = si_begin(w->implicit, t, w->y, f, h_abs, p, z, rtol, counts, rec->end);
        if (status == SC_SUCCESS) {
            status = sl_steps(w, ev, m, grid, p, z, rtol, atol, max_step, max_steps,
                              states, &filled, &t, &h_abs, rec);
            t_fail = rec->reals[0];
        }
    }
    if (status == SC_SUCCESS) {
        if (running && limit < grid[m - 1]) status = SC_TIME_EVENT;
        t_fail = t;
        sl_copy(rec->end, w->y);
    }
    rec->reals[0] = t_fail;
    rec->reals[1] = h_abs;
    counts[4] = filled;
    return status;
}

SPRINGC_LOOP_EXPORT int springc_loop_abi(void) { return SL_ABI; }

/* The model's sizes: states, parameters, z, observed, initial conditions, hybrid. */
SPRINGC_LOOP_EXPORT void springc_loop_sizes(sl_int *n) {
    n[0] = SPRINGC_N_STATES;
    n[1] = SPRINGC_N_PARAMS;
    n[2] = SPRINGC_N_Z;
    n[3] = SPRINGC_N_OBSERVED;
    n[4] = SPRINGC_INITIAL_CONDITIONS;
    n[5] = SPRINGC_HYBRID;
}

/* The model's zero-crossing indicators (a hybrid model's relations; 0 otherwise). */
SPRINGC_LOOP_EXPORT sl_int springc_loop_crossings(void) { return SPRINGC_N_CROSSINGS; }

/* Entry i of a name table (0: states, 1: parameters, 2: observed; 3: the model's name),
   NULL past its end. */
SPRINGC_LOOP_EXPORT const char *springc_loop_name(int table, sl_int i) {
    switch (table) {
    case 0: return i >= 0 && i < SPRINGC_N_STATES ? springc_state_names[i] : 0;
    case 1: return i >= 0 && i < SPRINGC_N_PARAMS ? springc_parameter_names[i] : 0;
    case 2: return i >= 0 && i < SPRINGC_N_OBSERVED ? springc_observed_names[i] : 0;
    case 3: return i == 0 ? springc_model_name : 0;
    default: return 0;
    }
}

SPRINGC_LOOP_EXPORT void springc_loop_parameters(double *p, const int *given) {
    springc_parameters(p, given);
}

SPRINGC_LOOP_EXPORT int springc_loop_start(const double *p, double *x, double *z) {
    return springc_start(p, x, z);
}

/* One run of method (0: DOP853, 1: RK45, 2: Radau IIA, 3: BDF) on the output grid (m
   times, increasing): states (m x n) rows 0..filled-1 written; counts: accepted,
   rejected, rhs evaluations, Jacobian evaluations, filled; reals: failure (or stop)
   time, next step size; end: the state there; z updated in place. first_step 0:
   scipy's initial step; max_steps 0: no limit. order: the implicit methods' ordering of
   the states in their band LU above 64 states (position -> state; NULL: state order).
   Events (a hybrid model): with signs (the held sign of each of the model's
   SPRINGC_N_CROSSINGS zero-crossing indicators; NULL: none) the run stops at the first
   crossing (STATE_EVENT: reals[0] its time, end the state there, fired[i] +1 rising,
   -1 falling, 0), and a t_stop before the grid's end is a time event (TIME_EVENT at
   t_stop; INFINITY: none); the output rows before the event are written.
   Returns a springc.integrate.Status code, or -1 if the work arrays could not be
   allocated. */
SPRINGC_LOOP_EXPORT int springc_loop_run(int method, sl_int m, const double *grid,
                                         const double *x0, const double *p, double *z,
                                         double rtol, const double *atol, double max_step,
                                         double first_step, sl_int max_steps,
                                         double *states, sl_int *counts, double *reals,
                                         double *end, const sl_int *order,
                                         const double *signs, double t_stop,
                                         sl_int *fired) {
    sl_work w;
    sl_int n_g = signs != NULL ? SPRINGC_N_CROSSINGS : 0, n_gs = n_g > 0 ? n_g : 1;
    double *block = (double *)malloc(((size_t)32 * SC_NXS + 5 * (size_t)n_gs
                                      + 2 * (size_t)SPRINGC_N_Z) * sizeof(double));
    if (block == NULL) return -1;
    double *g_block = block + 32 * SC_NXS;
    w.z_step = g_block + 5 * n_gs;
    w.z_end = w.z_step + SPRINGC_N_Z;
    sl_events ev = {n_g, signs, fired, (sl_int *)(g_block + 3 * n_gs), g_block,
                    g_block + n_gs, g_block + 2 * n_gs, t_stop};
    if (n_g > 0) {
        for (sl_int i = 0; i < n_g; i++) fired[i] = 0;
    }
    w.method = method >= SL_RK45 && method <= SL_BDF ? method : SL_DOP853;
    w.implicit = NULL;
    if (w.method == SL_RADAU || w.method == SL_BDF) {
        w.implicit = si_create(w.method, order);
        if (w.implicit == NULL) {
            free(block);
            return -1;
        }
    }
    w.K = block;
    w.F = block + 16 * SC_NXS;
    w.stage = block + 23 * SC_NXS;
    w.sums = block + 24 * SC_NXS;
    w.scale = block + 25 * SC_NXS;
    w.err5 = block + 26 * SC_NXS;
    w.err3 = block + 27 * SC_NXS;
    w.y = block + 28 * SC_NXS;
    w.y_new = block + 29 * SC_NXS;
    for (int k = 0; k < 5; k++) counts[k] = 0;
    sl_record rec = {counts, reals, end};
    int status = sl_run(&w, &ev, m, grid, x0, p, z, rtol, atol, max_step, first_step,
                        max_steps, states, &rec);
    if (w.implicit) si_free(w.implicit);
    free(block);
    return status;
}

/* The observed variables at the m rows (ts[k], states[k]) into out (m x n_observed), z
   warm-starting each row from the one before; -1, or the first row whose evaluation
   set the model's failure flag (rows before it written). */
SPRINGC_LOOP_EXPORT sl_int springc_loop_observed(sl_int m, const double *ts,
                                                 const double *states, const double *p,
                                                 double *z, double *out) {
    double row[SPRINGC_N_OBSERVED > 0 ? SPRINGC_N_OBSERVED : 1];
    for (sl_int k = 0; k < m; k++) {
        springc_observed(ts[k], states + k * SC_NX, p, z, row);
        if (sc_flagged(z)) return k;
        for (int j = 0; j < SPRINGC_N_OBSERVED; j++) out[k * SPRINGC_N_OBSERVED + j] = row[j];
    }
    return -1;
}
