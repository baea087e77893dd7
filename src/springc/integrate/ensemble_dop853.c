/* springc's batched ensemble kernel: DOP853, one run per loop iteration or GPU thread.

   One text, two compilations (springc.integrate.native_ensemble puts it together):
   - plain C (the system compiler, a shared library loaded with ctypes): the entry
     springc_ensemble loops over the runs, in parallel over the cores with OpenMP;
   - CUDA (SC_CUDA defined, through CuPy's NVRTC): the entry is a __global__ kernel,
     one thread per run.
   Before this text come: the sizes of the model (SPRINGC_N_STATES, SPRINGC_N_PARAMS,
   SPRINGC_N_Z, SPRINGC_N_OBSERVED), the tableau of springc.integrate.dop853_tableau
   (DOP_A, DOP_B, DOP_C, DOP_E3, DOP_E5, DOP_D), the status codes of
   springc.integrate.Status (SC_SUCCESS ...) and the model's C functions
   (springc_parameters, springc_start, springc_rhs, springc_observed: the cmodel
   interface).

   The arithmetic is springc.integrate.dop853_kernel's with plain-loop sums (the same
   controller, error norm, initial step and dense output, every sum in the same order),
   without zero crossings. Each run reads its own inputs and writes only its own rows
   of the outputs; nothing is reduced across runs, so the results are the same bytes
   whatever the number of threads. */

#ifdef SC_CUDA
#define SC_FN static __device__
#else
#define SC_FN static
#endif

#define SC_NX SPRINGC_N_STATES
#define SC_NXS (SPRINGC_N_STATES > 0 ? SPRINGC_N_STATES : 1)
#define SC_NPS (SPRINGC_N_PARAMS > 0 ? SPRINGC_N_PARAMS : 1)
#define SC_NZS (SPRINGC_N_Z > 0 ? SPRINGC_N_Z : 1)
#define SC_NOS (SPRINGC_N_OBSERVED > 0 ? SPRINGC_N_OBSERVED : 1)
#define SC_STAGES 12
#define SC_EXTENDED 16
#define SC_ROWS 7
/* per-run work: K (16 rows), F (7 rows), y_new, work, sums, scale, err5, err3, the
   state at an output time, y (30 rows in all); then p, z and the observed variables */
#define SC_AT_Y (30 * SC_NXS)
#define SC_AT_P (31 * SC_NXS)
#define SC_AT_Z (SC_AT_P + SC_NPS)
#define SC_AT_OBS (SC_AT_Z + SC_NZS)
#define SC_WORK (SC_AT_OBS + SC_NOS)
#define SC_HUGE 1.7976931348623157e308

typedef long long sc_int;

/* What every run shares (the settings) and where run r's rows are. */
typedef struct {
    const double *grid;
    sc_int m;
    double rtol;
    const double *atol;
    double max_step;
    sc_int max_steps;
    const sc_int *columns;      /* statistics of these [states | observed] columns */
    sc_int n_columns;
    const sc_int *traj_columns; /* trajectories of these */
    sc_int n_traj;
    sc_int every;               /* every k-th output time (and the last) */
    sc_int n_traj_points;
    int need_observed;
} sc_settings;

typedef struct {
    double *summary;   /* n_columns x 5: final, min, max, mean, time of the max */
    double *traj;      /* n_traj_points x n_traj */
    double *final;     /* the states at the end (or where the run stopped) */
    sc_int *status;
    sc_int *counts;    /* accepted, rejected, evaluations, the model's flag */
    double *failure_time;
} sc_outputs;

SC_FN double sc_min(double a, double b) { return b < a ? b : a; }  /* Python's min */
SC_FN double sc_max(double a, double b) { return b > a ? b : a; }  /* Python's max */

SC_FN int sc_flagged(const double *z) {
    return SPRINGC_N_Z > 0 && z[SC_NZS - 1] != 0.0;
}

/* SC_SUCCESS, or why the evaluation that wrote d (and set z) is unusable. */
SC_FN int sc_verdict(const double *d, const double *z) {
    if (sc_flagged(z)) return SC_MODEL_FAILED;
    for (int i = 0; i < SC_NX; i++)
        if (!isfinite(d[i])) return SC_NON_FINITE_DERIVATIVE;
    return SC_SUCCESS;
}

/* out = sum_{j<s} w[j] K[j], each entry summed over j in order from 0.0 */
SC_FN void sc_wsum(const double *K, int s, const double *w, double *out) {
    for (int i = 0; i < SC_NX; i++) out[i] = 0.0;
    for (int j = 0; j < s; j++) {
        double wj = w[j];
        for (int i = 0; i < SC_NX; i++) out[i] += K[j * SC_NXS + i] * wj;
    }
}

/* the state of stage s: y + (sum_j A[s, j] K[j]) * h */
SC_FN void sc_stage(const double *y, const double *K, int s, double h, double *sums,
                    double *out) {
    sc_wsum(K, s, DOP_A + s * SC_EXTENDED, sums);
    for (int i = 0; i < SC_NX; i++) out[i] = y[i] + sums[i] * h;
}

SC_FN double sc_rms_scaled(const double *x, const double *scale) {
    double total = 0.0;
    for (int i = 0; i < SC_NX; i++) {
        double v = x[i] / scale[i];
        total += v * v;
    }
    return sqrt(total) / pow((double)SC_NX, 0.5);
}

SC_FN double sc_error_norm(const double *y, const double *y_new, const double *K, double h,
                           double rtol, const double *atol, double *scale, double *err5,
                           double *err3) {
    for (int i = 0; i < SC_NX; i++)
        scale[i] = atol[i] + sc_max(fabs(y[i]), fabs(y_new[i])) * rtol;
    sc_wsum(K, SC_STAGES + 1, DOP_E5, err5);
    sc_wsum(K, SC_STAGES + 1, DOP_E3, err3);
    double e5 = 0.0, e3 = 0.0;
    for (int i = 0; i < SC_NX; i++) {
        err5[i] /= scale[i];
        err3[i] /= scale[i];
    }
    for (int i = 0; i < SC_NX; i++) e5 += err5[i] * err5[i];
    for (int i = 0; i < SC_NX; i++) e3 += err3[i] * err3[i];
    if (e5 == 0.0 && e3 == 0.0) return 0.0;
    return fabs(h) * e5 / sqrt((e5 + 0.01 * e3) * SC_NX);
}

/* the 7 coefficient rows of the dense output over the step (needs K[13..15]) */
SC_FN void sc_interpolant(const double *y, const double *y_new, const double *K, double h,
                          double *F, double *sums) {
    for (int r = 0; r < SC_ROWS - 3; r++) {
        sc_wsum(K, SC_EXTENDED, DOP_D + r * SC_EXTENDED, sums);
        for (int i = 0; i < SC_NX; i++) F[(3 + r) * SC_NXS + i] = h * sums[i];
    }
    for (int i = 0; i < SC_NX; i++) {
        double delta = y_new[i] - y[i];
        F[i] = delta;
        F[SC_NXS + i] = h * K[i] - delta;
        F[2 * SC_NXS + i] = 2 * delta - h * (K[SC_STAGES * SC_NXS + i] + K[i]);
    }
}

SC_FN void sc_interpolate(const double *F, const double *y, double theta, double *out) {
    for (int i = 0; i < SC_NX; i++) {
        double value = 0.0;
        for (int r = SC_ROWS - 1; r >= 0; r--) {
            value += F[r * SC_NXS + i];
            value *= (SC_ROWS - 1 - r) % 2 == 0 ? theta : 1 - theta;
        }
        out[i] = value + y[i];
    }
}

/* Output time k reached with states x (observed obs): the statistics and trajectories. */
SC_FN void sc_emit(const sc_settings *s, const sc_outputs *o, sc_int k, const double *x,
                   const double *obs) {
    const double *grid = s->grid;
    for (sc_int c = 0; c < s->n_columns; c++) {
        sc_int j = s->columns[c];
        double v = j < SC_NX ? x[j] : obs[j - SC_NX];
        double *out = o->summary + 5 * c;  /* final (the last value), min, max, area, t */
        if (k == 0) {
            out[0] = v; out[1] = v; out[2] = v; out[3] = 0.0; out[4] = grid[0];
            continue;
        }
        if (v < out[1]) out[1] = v;
        if (v > out[2]) { out[2] = v; out[4] = grid[k]; }
        out[3] += 0.5 * (v + out[0]) * (grid[k] - grid[k - 1]);
        out[0] = v;
    }
    if (s->n_traj > 0 && (k % s->every == 0 || k == s->m - 1)) {
        sc_int slot = k % s->every == 0 ? k / s->every : s->n_traj_points - 1;
        double *row = o->traj + slot * s->n_traj;
        for (sc_int c = 0; c < s->n_traj; c++) {
            sc_int j = s->traj_columns[c];
            row[c] = j < SC_NX ? x[j] : obs[j - SC_NX];
        }
    }
}

/* The end of a run: its status, counts, time and state. */
SC_FN void sc_finish(const sc_settings *s, const sc_outputs *o, int status, sc_int accepted,
                     sc_int rejected, sc_int nfev, double t, const double *x,
                     const double *z) {
    o->status[0] = status;
    o->counts[0] = accepted;
    o->counts[1] = rejected;
    o->counts[2] = nfev;
    o->counts[3] = SPRINGC_N_Z > 0 ? (sc_int)z[SC_NZS - 1] : 0;
    o->failure_time[0] = t;
    for (int i = 0; i < SC_NX; i++) o->final[i] = x[i];
    double span = s->grid[s->m - 1] - s->grid[0];
    for (sc_int c = 0; c < s->n_columns; c++) {
        double *out = o->summary + 5 * c;
        if (status != SC_SUCCESS) {
            for (int q = 0; q < 5; q++) out[q] = 0.0 / 0.0;
        } else {
            out[3] = s->m > 1 ? out[3] / span : out[0];
        }
    }
}

/* The output times in (t, t_new]: the states there (and the observed variables). */
SC_FN int sc_outputs_in_step(const sc_settings *s, const sc_outputs *o, sc_int *filled,
                             double t, double t_new, double h, const double *y,
                             const double *y_new, const double *F, double *xo, double *obs,
                             const double *p, double *z) {
    while (*filled < s->m && s->grid[*filled] <= t_new) {
        double tk = s->grid[*filled];
        if (tk == t_new) {
            for (int i = 0; i < SC_NX; i++) xo[i] = y_new[i];
        } else {
            sc_interpolate(F, y, (tk - t) / h, xo);
        }
        if (s->need_observed) {
            springc_observed(tk, xo, p, z, obs);
            if (sc_flagged(z)) return SC_MODEL_FAILED;
        }
        sc_emit(s, o, *filled, xo, obs);
        *filled += 1;
    }
    return SC_SUCCESS;
}

/* The initial step (Hairer's algorithm, as scipy's select_initial_step); 0 on failure
   with *status set. */
SC_FN double sc_first_step(const sc_settings *s, double t, const double *y, double *K,
                           double *work, double *scale, const double *p, double *z,
                           double interval, int *status, sc_int *nfev, double *h0_out) {
    for (int i = 0; i < SC_NX; i++) scale[i] = s->atol[i] + fabs(y[i]) * s->rtol;
    double d0 = sc_rms_scaled(y, scale), d1 = sc_rms_scaled(K, scale);
    double h0 = d0 < 1e-5 || d1 < 1e-5 ? 1e-6 : 0.01 * d0 / d1;
    h0 = sc_min(h0, interval);
    *h0_out = h0;
    for (int i = 0; i < SC_NX; i++) work[i] = y[i] + h0 * K[i];
    double *d = K + SC_NXS;  /* stage 1's row, free until the first step */
    springc_rhs(t + h0, work, p, z, d);
    *nfev += 1;
    *status = sc_verdict(d, z);
    if (*status != SC_SUCCESS) return 0.0;
    double total = 0.0;
    for (int i = 0; i < SC_NX; i++) {
        double v = (d[i] - K[i]) / scale[i];
        total += v * v;
    }
    double d2 = sqrt(total) / pow((double)SC_NX, 0.5) / h0;
    double h1 = d1 <= 1e-15 && d2 <= 1e-15 ? sc_max(1e-6, h0 * 1e-3)
                                           : pow(0.01 / sc_max(d1, d2), 0.125);
    double h = sc_min(sc_min(sc_min(100 * h0, h1), interval), s->max_step);
    if (!(h > 0.0)) *status = SC_STEP_TOO_SMALL;
    return h;
}

/* One run from (grid[0], y): springc.integrate.dop853_kernel.dop853_run without events. */
SC_FN void sc_run(const sc_settings *s, const sc_outputs *o, double *y, const double *p,
                  double *z, double *w) {
    double *K = w, *F = K + SC_EXTENDED * SC_NXS, *y_new = F + SC_ROWS * SC_NXS;
    double *work = y_new + SC_NXS, *sums = work + SC_NXS, *scale = sums + SC_NXS;
    double *err5 = scale + SC_NXS, *err3 = err5 + SC_NXS, *xo = err3 + SC_NXS;
    double *obs = w + SC_AT_OBS;
    const double *grid = s->grid;
    double t = grid[0], t_end = grid[s->m - 1], rtol = s->rtol;
    sc_int accepted = 0, rejected = 0, nfev = 0, filled = 1;
    int status = SC_SUCCESS;

    /* Step 1: the start and its outputs. */
    if (s->need_observed) {
        springc_observed(t, y, p, z, obs);
        if (sc_flagged(z)) { sc_finish(s, o, SC_MODEL_FAILED, 0, 0, 0, t, y, z); return; }
    }
    sc_emit(s, o, 0, y, obs);
    if (s->m == 1 || SC_NX == 0) {
        for (sc_int k = 1; k < s->m; k++) sc_emit(s, o, k, y, obs);
        sc_finish(s, o, SC_SUCCESS, 0, 0, 0, t, y, z);
        return;
    }
    springc_rhs(t, y, p, z, K);
    nfev = 1;
    status = sc_verdict(K, z);
    if (status != SC_SUCCESS) { sc_finish(s, o, status, 0, 0, nfev, t, y, z); return; }

    /* Step 2: the initial step. */
    double h0 = 0.0;
    double h_abs = sc_first_step(s, t, y, K, work, scale, p, z, fabs(t_end - t), &status,
                                 &nfev, &h0);
    if (status != SC_SUCCESS) {
        int small = status == SC_STEP_TOO_SMALL;
        sc_finish(s, o, status, 0, 0, nfev, small ? t : t + h0, small ? y : work, z);
        return;
    }

    /* Step 3: steps until the end, each filling the output times it passes. */
    while (t < t_end) {
        if (s->max_steps > 0 && accepted + rejected >= s->max_steps) {
            sc_finish(s, o, SC_MAX_STEPS, accepted, rejected, nfev, t, y, z);
            return;
        }
        double min_step = 10 * fabs(nextafter(t, SC_HUGE) - t);
        if (h_abs > s->max_step) h_abs = s->max_step;
        else if (h_abs < min_step) h_abs = min_step;
        int step_rejected = 0;
        double t_new, h;
        for (;;) {
            if (h_abs < min_step) {
                sc_finish(s, o, SC_STEP_TOO_SMALL, accepted, rejected, nfev, t, y, z);
                return;
            }
            t_new = t + h_abs;
            if (t_new - t_end > 0) t_new = t_end;
            h = t_new - t;
            h_abs = fabs(h);
            for (int st = 1; st < SC_STAGES; st++) {
                sc_stage(y, K, st, h, sums, work);
                springc_rhs(t + DOP_C[st] * h, work, p, z, K + st * SC_NXS);
                nfev += 1;
                status = sc_verdict(K + st * SC_NXS, z);
                if (status != SC_SUCCESS) {
                    sc_finish(s, o, status, accepted, rejected, nfev, t + DOP_C[st] * h,
                              work, z);
                    return;
                }
            }
            sc_wsum(K, SC_STAGES, DOP_B, sums);
            for (int i = 0; i < SC_NX; i++) y_new[i] = y[i] + h * sums[i];
            springc_rhs(t + h, y_new, p, z, K + SC_STAGES * SC_NXS);
            nfev += 1;
            status = sc_verdict(K + SC_STAGES * SC_NXS, z);
            if (status != SC_SUCCESS) {
                sc_finish(s, o, status, accepted, rejected, nfev, t + h, y_new, z);
                return;
            }
            double error = sc_error_norm(y, y_new, K, h, rtol, s->atol, scale, err5, err3);
            if (error < 1) {
                double factor = error == 0 ? 10.0 : sc_min(10.0, 0.9 * pow(error, -0.125));
                if (step_rejected) factor = sc_min(1.0, factor);
                h_abs *= factor;
                break;
            }
            h_abs *= sc_max(0.2, 0.9 * pow(error, -0.125));
            step_rejected = 1;
            rejected += 1;
        }
        accepted += 1;

        /* Step 5: the dense output, where an output time falls in the step. */
        if (filled < s->m && grid[filled] <= t_new) {
            for (int st = SC_STAGES + 1; st < SC_EXTENDED; st++) {
                sc_stage(y, K, st, h, sums, work);
                springc_rhs(t + DOP_C[st] * h, work, p, z, K + st * SC_NXS);
                nfev += 1;
                status = sc_verdict(K + st * SC_NXS, z);
                if (status != SC_SUCCESS) {
                    sc_finish(s, o, status, accepted, rejected, nfev, t + DOP_C[st] * h,
                              work, z);
                    return;
                }
            }
            sc_interpolant(y, y_new, K, h, F, sums);
            status = sc_outputs_in_step(s, o, &filled, t, t_new, h, y, y_new, F, xo, obs,
                                        p, z);
            if (status != SC_SUCCESS) {
                sc_finish(s, o, status, accepted, rejected, nfev, grid[filled], xo, z);
                return;
            }
        }
        t = t_new;
        for (int i = 0; i < SC_NX; i++) {
            y[i] = y_new[i];
            K[i] = K[SC_STAGES * SC_NXS + i];
        }
    }
    sc_finish(s, o, SC_SUCCESS, accepted, rejected, nfev, t, y, z);
}

/* Run r: its parameters, start state and work array, then the run. With `prepared`,
   P, X0 and Z hold every run's rows; else run r's parameters are `base` with the
   `n_v` varied ones (at `v_index`) from V's row r, completed by springc_parameters
   (the parameters bound to them follow), and its start by springc_start. A run whose
   parameters or start are not finite gets status SC_BAD_START. */
SC_FN void sc_one(sc_int r, const sc_settings *s, int prepared, const double *V, sc_int n_v,
                  const sc_int *v_index, const double *base, const int *given,
                  const double *P, const double *X0, const double *Z, const sc_outputs *all,
                  double *w) {
    sc_outputs o;
    o.summary = all->summary + r * 5 * s->n_columns;
    o.traj = all->traj + r * s->n_traj_points * s->n_traj;
    o.final = all->final + r * SC_NX;
    o.status = all->status + r;
    o.counts = all->counts + 4 * r;
    o.failure_time = all->failure_time + r;
    double *y = w + SC_AT_Y, *p = w + SC_AT_P, *z = w + SC_AT_Z;
    int code = 0;
    if (prepared) {
        for (int i = 0; i < SPRINGC_N_PARAMS; i++) p[i] = P[r * SPRINGC_N_PARAMS + i];
        for (int i = 0; i < SC_NX; i++) y[i] = X0[r * SC_NX + i];
        for (int i = 0; i < SPRINGC_N_Z; i++) z[i] = Z[r * SPRINGC_N_Z + i];
    } else {
        for (int i = 0; i < SPRINGC_N_PARAMS; i++) p[i] = base[i];
        for (sc_int j = 0; j < n_v; j++) p[v_index[j]] = V[r * n_v + j];
        springc_parameters(p, given);
        for (int i = 0; i < SPRINGC_N_Z; i++) z[i] = 0.0;
        code = springc_start(p, y, z);
    }
    for (int i = 0; i < SPRINGC_N_PARAMS; i++) code |= !isfinite(p[i]);
    for (int i = 0; i < SC_NX; i++) code |= !isfinite(y[i]);
    if (code != 0) {
        sc_finish(s, &o, SC_BAD_START, 0, 0, 0, s->grid[0], y, z);
        return;
    }
    sc_run(s, &o, y, p, z, w);
}

#define SC_ENTRY_ARGS                                                                     \
    sc_int runs, int prepared, const double *V, sc_int n_v, const sc_int *v_index,           \
    const double *base, const int *given, const double *P, const double *X0,              \
    const double *Z, const double *grid, sc_int m, double rtol, const double *atol,         \
    double max_step, sc_int max_steps, const sc_int *columns, sc_int n_columns,            \
    const sc_int *traj_columns, sc_int n_traj, sc_int every, sc_int n_traj_points,          \
    int need_observed, double *summary, double *traj, double *final, sc_int *status,        \
    sc_int *counts, double *failure_time

#define SC_SETUP                                                                          \
    sc_settings s = {grid, m, rtol, atol, max_step, max_steps, columns, n_columns,          \
                     traj_columns, n_traj, every, n_traj_points, need_observed};           \
    sc_outputs all = {summary, traj, final, status, counts, failure_time}

#ifdef SC_CUDA
/* One thread per run. */
extern "C" __global__ void springc_ensemble(SC_ENTRY_ARGS) {
    sc_int r = (sc_int)blockIdx.x * blockDim.x + threadIdx.x;
    if (r >= runs) return;
    SC_SETUP;
    double w[SC_WORK];
    sc_one(r, &s, prepared, V, n_v, v_index, base, given, P, X0, Z, &all, w);
}
#else
#include <stdlib.h>
#ifdef _OPENMP
#include <omp.h>
#endif
int springc_ensemble_threads(void) {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

/* Every run, in parallel over `threads` threads (0: OpenMP's default). Returns 0, or
   -1 if a thread could not allocate its work array (its runs are not run). */
int springc_ensemble(SC_ENTRY_ARGS, int threads) {
    SC_SETUP;
    int lost = 0;
#ifdef _OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#pragma omp parallel num_threads(threads) reduction(|: lost)
#endif
    {
        double *w = (double *)malloc(SC_WORK * sizeof(double));
#ifdef _OPENMP
#pragma omp for schedule(dynamic, 4)
#endif
        for (sc_int r = 0; r < runs; r++) {
            if (w == NULL) { lost = 1; continue; }
            sc_one(r, &s, prepared, V, n_v, v_index, base, given, P, X0, Z, &all, w);
        }
        free(w);
    }
    (void)threads;
    return lost ? -1 : 0;
}
#endif
