/* springc's batched ensemble kernel: DOP853, one run per loop iteration or GPU thread.

   One text, two compilations (springc.integrate.native_ensemble puts it together):
   - plain C (the system compiler, a shared library loaded with ctypes): the entry
     springc_ensemble loops over the runs, in parallel over the cores with OpenMP;
   - CUDA (SC_CUDA defined, through CuPy's NVRTC): the entry is a __global__ kernel,
     one thread per run.
   Before this text come: the sizes of the model (SPRINGC_N_STATES, as SC_NX and SC_NXS, SPRINGC_N_PARAMS,
   SPRINGC_N_Z, SPRINGC_N_OBSERVED), the tableau of springc.integrate.dop853_tableau
   (DOP_C, and the weighted sums of the stages written out: sc_a_row, sc_b_sum,
   sc_e5_sum, sc_e3_sum, sc_d_row), the status codes of
   springc.integrate.Status (SC_SUCCESS ...) and the model's C functions
   (springc_parameters, springc_start, springc_rhs, springc_observed: the cmodel
   interface), then dop853_core.c (DOP853's step arithmetic, shared with the
   single-run loop).

   The arithmetic is springc.integrate.dop853_kernel's with plain-loop sums (the same
   controller, error norm, initial step and dense output, every sum in the same order).
   Each run reads its own inputs and writes only its own rows of the outputs; nothing
   is reduced across runs, so the results are the same bytes whatever the number of
   threads.

   A hybrid model (SPRINGC_HYBRID 1) runs springc.simulation.hybrid_compiled's event
   loop inside the kernel, each run with its own events: the event at the start
   (springc_event_update with z[SPRINGC_Z_INITIAL] set, twice with
   SPRINGC_AFTER_INITIAL); steps up to the next time event (springc_next_time_event,
   a step ends on it exactly); after each accepted step the zero-crossing functions
   against the held relations (SC_POSITIVE: relation k is > or >=), the earliest
   crossing located by bisection on the dense output to springc.integrate.crossings'
   time tolerance, the output times before it filled, then the event update and a
   restart with a fresh initial step; the rows at an event's time get the values after
   it; at the stop time its time event and, with SPRINGC_USES_TERMINAL, the terminal
   event before the last row. More than SC_BURST events within SC_ZENO of the span is
   chattering (SC_CHATTERING), an event iteration that does not settle SC_UNSETTLED,
   and terminate() ends the run there (ok, its statistics up to that time). */

#ifndef SC_LANES
#define SC_LANES 1
#endif
#define SC_NPS (SPRINGC_N_PARAMS > 0 ? SPRINGC_N_PARAMS : 1)
#define SC_NOS (SPRINGC_N_OBSERVED > 0 ? SPRINGC_N_OBSERVED : 1)
/* per-run work: K (16 rows), F (7 rows), y_new, work, sums, scale, err5, err3, the
   state at an output time, y (30 rows in all); then p, z and the observed variables */
#define SC_AT_Y (30 * SC_NXS)
#define SC_AT_P (31 * SC_NXS)
#define SC_AT_Z (SC_AT_P + SC_NPS)
#define SC_AT_OBS (SC_AT_Z + SC_NZS)
#ifndef SPRINGC_HYBRID
#define SPRINGC_HYBRID 0
#endif
#if SPRINGC_HYBRID
#define SC_NGS (SPRINGC_N_CROSSINGS > 0 ? SPRINGC_N_CROSSINGS : 1)
#define SC_BURST 100      /* springc.simulation.events.EVENT_BURST */
#define SC_ZENO 1e-6      /* springc.simulation.events.ZENO_FRACTION */
#define SC_AT_G (SC_AT_OBS + SC_NOS)          /* g at the step's start, end, a trial */
#define SC_AT_RING (SC_AT_G + 3 * SC_NGS)     /* the times of the last SC_BURST events */
#define SC_WORK (SC_AT_RING + SC_BURST)
#else
#define SC_WORK (SC_AT_OBS + SC_NOS)
#endif
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

/* The end of a run: its status, counts, time and state; `last` is the time of its
   last output (the stop time, or where terminate() ended it). */
SC_FN void sc_finish(const sc_settings *s, const sc_outputs *o, int status, sc_int accepted,
                     sc_int rejected, sc_int nfev, double t, const double *x,
                     const double *z, double last) {
    o->status[0] = status;
    o->counts[0] = accepted;
    o->counts[1] = rejected;
    o->counts[2] = nfev;
    o->counts[3] = SPRINGC_N_Z > 0 ? (sc_int)z[SC_NZS - 1] : 0;
    o->failure_time[0] = t;
    for (int i = 0; i < SC_NX; i++) o->final[i] = x[i];
    double span = last - s->grid[0];
    for (sc_int c = 0; c < s->n_columns; c++) {
        double *out = o->summary + 5 * c;
        if (status != SC_SUCCESS) {
            for (int q = 0; q < 5; q++) out[q] = NAN;
        } else {
            out[3] = s->m > 1 && span > 0 ? out[3] / span : out[0];
        }
    }
}

/* The output times in (t, t_new] (below row `last`; before an event at t_event that
   `stops` the step: in (t, t_event)): the states there (and the observed variables). */
SC_FN int sc_outputs_in_step(const sc_settings *s, const sc_outputs *o, sc_int *filled,
                             double t, double t_new, double h, const double *y,
                             const double *y_new, const double *F, double *xo, double *obs,
                             const double *p, double *z, double t_event, int stops,
                             sc_int last) {
    while (*filled < last && (s->grid[*filled] < t_event
                              || (s->grid[*filled] == t_event && !stops))) {
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

/* Where the runs come from: the chunk's inputs, shared by every lane. */
typedef struct {
    sc_settings s;
    sc_outputs all;
    int prepared;
    const double *V;
    sc_int n_v;
    const sc_int *v_index;
    const double *base;
    const int *given;
    const double *P, *X0, *Z;
    sc_int runs;
    sc_int stride;    /* CUDA: the threads of the launch; this thread's runs step by it */
    sc_int next;      /* CUDA: this thread's next run */
    sc_int *counter;  /* C: the next run not taken, shared by the threads */
} sc_job;

/* A run in progress: a lane. A thread keeps SC_LANES of them and takes them through
   each step together (their model evaluations interleave: independent work for the
   processor while one waits on a division or a square root). */
typedef struct {
    sc_int run;  /* -1: idle */
    int retry;   /* the last attempt was rejected */
    int ready;   /* between the start of an attempt and its end */
    double t, h_abs, h, t_new, min_step;
    double t_stop;  /* the next time event (SC_HUGE: none before the stop time) */
    double last;    /* the time of the run's last output */
    sc_int accepted, rejected, nfev, filled, events;
    sc_outputs o;
    double *w;   /* its work array (layout SC_AT_*) */
} sc_lane;

SC_FN sc_int sc_take(sc_job *job) {
#ifdef SC_CUDA
    sc_int r = job->next;
    job->next += job->stride;
#else
    sc_int r;
#ifdef _OPENMP
#pragma omp atomic capture
#endif
    r = (*job->counter)++;
#endif
    return r < job->runs ? r : -1;
}

SC_FN void sc_end(sc_lane *L, const sc_job *job, int status, double t, const double *x) {
    sc_finish(&job->s, &L->o, status, L->accepted, L->rejected, L->nfev, t, x,
              L->w + SC_AT_Z, L->last);
    L->run = -1;
    L->ready = 0;
}

/* Run r's parameters and start (see springc_ensemble); 0 if they are not finite. */
SC_FN int sc_inputs(const sc_job *job, sc_int r, double *y, double *p, double *z) {
    int code = 0;
    if (job->prepared) {
        for (int i = 0; i < SPRINGC_N_PARAMS; i++) p[i] = job->P[r * SPRINGC_N_PARAMS + i];
        for (int i = 0; i < SC_NX; i++) y[i] = job->X0[r * SC_NX + i];
        for (int i = 0; i < SPRINGC_N_Z; i++) z[i] = job->Z[r * SPRINGC_N_Z + i];
    } else {
        for (int i = 0; i < SPRINGC_N_PARAMS; i++) p[i] = job->base[i];
        for (sc_int j = 0; j < job->n_v; j++) p[job->v_index[j]] = job->V[r * job->n_v + j];
        springc_parameters(p, job->given);
        for (int i = 0; i < SPRINGC_N_Z; i++) z[i] = 0.0;
        code = springc_start(p, y, z);
    }
    for (int i = 0; i < SPRINGC_N_PARAMS; i++) code |= !isfinite(p[i]);
    for (int i = 0; i < SC_NX; i++) code |= !isfinite(y[i]);
    return code == 0;
}

#if SPRINGC_HYBRID
/* The side of relation k's zero-crossing function that its held value assumes: +1 where
   the relation holds for g > 0 (springc.simulation.hybrid_compiled.held_signs). */
SC_FN double sc_sign(const double *z, int k) {
    int held = z[SPRINGC_Z_RELATIONS + k] != 0.0, positive = SC_POSITIVE[k] != 0.0;
    return held == positive ? 1.0 : -1.0;
}

/* Whether a function crossed from g0 to g1 against its held sign (.crossings). */
SC_FN int sc_crossed(const double *g0, const double *g1, const double *z) {
    int any = 0;
    for (int k = 0; k < SPRINGC_N_CROSSINGS; k++) {
        double sign = sc_sign(z, k);
        if (sign * g0[k] >= 0.0 && sign * g1[k] < 0.0) any = 1;
    }
    return any;
}

/* The bracket width at which a crossing in (t, t_new] is located (.crossings). */
SC_FN double sc_time_tolerance(double t, double t_new) {
    double width = 1e-12 * sc_max(sc_max(fabs(t), fabs(t_new)), t_new - t);
    double ulp = nextafter(fabs(t_new), SC_HUGE) - fabs(t_new);
    return sc_max(width, 4.0 * ulp);
}

/* The event at L->t on the lane's state (the event iteration, in place): SC_SUCCESS or
   why the run ends; `counted` events (state and time events) are checked for
   chattering; *stop is set where terminate() was called. */
SC_FN int sc_event(sc_lane *L, const sc_job *job, int counted, int *stop) {
    double *w = L->w, *z = w + SC_AT_Z, *ring = w + SC_AT_RING;
    int code = springc_event_update(L->t, w + SC_AT_Y, w + SC_AT_P, z);
    if (code > 0 || sc_flagged(z)) return SC_MODEL_FAILED;
    if (code == -1) return SC_UNSETTLED;
    if (counted) {
        const sc_settings *s = &job->s;
        ring[L->events % SC_BURST] = L->t;
        L->events += 1;
        double oldest = ring[L->events % SC_BURST];
        if (L->events >= SC_BURST
            && L->t - oldest <= SC_ZENO * (s->grid[s->m - 1] - s->grid[0]))
            return SC_CHATTERING;
    }
    if (code == -2) *stop = 1;
    return SC_SUCCESS;
}

/* The rows at L->t (below row `last`) with the lane's state: the values after an event. */
SC_FN int sc_rows_at(sc_lane *L, const sc_job *job, sc_int last) {
    const sc_settings *s = &job->s;
    double *w = L->w, *y = w + SC_AT_Y, *obs = w + SC_AT_OBS;
    while (L->filled < last && s->grid[L->filled] <= L->t) {
        if (s->need_observed) {
            springc_observed(L->t, y, w + SC_AT_P, w + SC_AT_Z, obs);
            if (sc_flagged(w + SC_AT_Z)) return SC_MODEL_FAILED;
        }
        sc_emit(s, &L->o, L->filled, y, obs);
        L->filled += 1;
    }
    return SC_SUCCESS;
}

/* A run ended by terminate() at L->t: without a row at that time, one more (its
   values after the event) enters the statistics, as springc.simulate's result ends. */
SC_FN void sc_terminated(sc_lane *L, const sc_job *job) {
    const sc_settings *s = &job->s;
    double *w = L->w, *y = w + SC_AT_Y, *obs = w + SC_AT_OBS;
    double previous = s->grid[L->filled - 1];  /* row 0 is always written */
    L->last = previous;
    if (previous < L->t) {
        if (s->need_observed) {
            springc_observed(L->t, y, w + SC_AT_P, w + SC_AT_Z, obs);
            if (sc_flagged(w + SC_AT_Z)) { sc_end(L, job, SC_MODEL_FAILED, L->t, y); return; }
        }
        for (sc_int c = 0; c < s->n_columns; c++) {
            sc_int j = s->columns[c];
            double v = j < SC_NX ? y[j] : obs[j - SC_NX];
            double *out = L->o.summary + 5 * c;
            if (v < out[1]) out[1] = v;
            if (v > out[2]) { out[2] = v; out[4] = L->t; }
            out[3] += 0.5 * (v + out[0]) * (L->t - previous);
            out[0] = v;
        }
        L->last = L->t;
    }
    sc_end(L, job, SC_SUCCESS, L->t, y);
}

/* The end of a run at the stop time (with the time event there where `time_event`),
   the terminal event, then the last row. */
SC_FN void sc_final(sc_lane *L, const sc_job *job, int time_event) {
    const sc_settings *s = &job->s;
    double *w = L->w, *y = w + SC_AT_Y, *z = w + SC_AT_Z;
    int stop = 0, status = SC_SUCCESS;
    if (time_event) {
        double before = L->t - 2e-12 * sc_max(1.0, fabs(L->t));
        if (springc_next_time_event(before, y, w + SC_AT_P, z) == L->t)
            status = sc_event(L, job, 1, &stop);
    }
    if (status == SC_SUCCESS && stop) { sc_terminated(L, job); return; }
    if (status == SC_SUCCESS && SPRINGC_USES_TERMINAL) {
        z[SPRINGC_Z_TERMINAL] = 1.0;
        status = sc_event(L, job, 0, &stop);
    }
    if (status == SC_SUCCESS) status = sc_rows_at(L, job, s->m);
    sc_end(L, job, status, L->t, y);
}
#endif

/* From (L->t, y) at the start or after an event: the next time event and the
   zero-crossing functions there (hybrid), the derivative and a fresh initial step. 1
   if the run needs steps, 0 if it has ended. */
SC_FN int sc_restart(sc_lane *L, const sc_job *job) {
    const sc_settings *s = &job->s;
    double *w = L->w, *K = w, *work = w + 24 * SC_NXS, *scale = w + 26 * SC_NXS;
    double *y = w + SC_AT_Y, *p = w + SC_AT_P, *z = w + SC_AT_Z;
    double t_end = s->grid[s->m - 1];
    L->retry = 0;
    L->t_stop = SC_HUGE;
#if SPRINGC_HYBRID
    double t_event = springc_next_time_event(L->t, y, p, z);
    if (L->t < t_event && t_event < t_end) L->t_stop = t_event;
    springc_zero_crossings(L->t, y, p, z, w + SC_AT_G);
    if (sc_flagged(z)) { sc_end(L, job, SC_MODEL_FAILED, L->t, y); return 0; }
#endif
    springc_rhs(L->t, y, p, z, K);
    L->nfev += 1;
    int status = sc_verdict(K, z);
    if (status != SC_SUCCESS) { sc_end(L, job, status, L->t, y); return 0; }

    /* Step 2: the initial step. */
    double h0 = 0.0, limit = sc_min(t_end, L->t_stop);
    L->h_abs = sc_first_step(s, L->t, y, K, work, scale, p, z, fabs(limit - L->t), &status,
                             &L->nfev, &h0);
    if (status != SC_SUCCESS) {
        int small = status == SC_STEP_TOO_SMALL;
        sc_end(L, job, status, small ? L->t : L->t + h0, small ? y : work);
        return 0;
    }
    return 1;
}

/* Lane L takes run r: its inputs, outputs at the start, the initial step. 1 if the run
   needs steps, 0 if it has ended already. */
SC_FN int sc_start(sc_lane *L, const sc_job *job, sc_int r) {
    const sc_settings *s = &job->s;
    double *w = L->w;
    double *y = w + SC_AT_Y, *p = w + SC_AT_P, *z = w + SC_AT_Z, *obs = w + SC_AT_OBS;
    L->run = r;
    L->retry = 0;
    L->accepted = L->rejected = L->nfev = L->events = 0;
    L->filled = 1;
    L->t = s->grid[0];
    L->last = s->grid[s->m - 1];
    L->o.summary = job->all.summary + r * 5 * s->n_columns;
    L->o.traj = job->all.traj + r * s->n_traj_points * s->n_traj;
    L->o.final = job->all.final + r * SC_NX;
    L->o.status = job->all.status + r;
    L->o.counts = job->all.counts + 4 * r;
    L->o.failure_time = job->all.failure_time + r;
    if (!sc_inputs(job, r, y, p, z)) { sc_end(L, job, SC_BAD_START, L->t, y); return 0; }
#if SPRINGC_HYBRID
    /* Step 0: the event at the start (and the one after it for 'not initial()'). */
    int stop = 0;
    z[SPRINGC_Z_INITIAL] = 1.0;
    int code = sc_event(L, job, 0, &stop);
    if (code == SC_SUCCESS && SPRINGC_AFTER_INITIAL && !stop) code = sc_event(L, job, 0, &stop);
    if (code != SC_SUCCESS) { sc_end(L, job, code, L->t, y); return 0; }
#endif

    /* Step 1: the start and its outputs. */
    if (s->need_observed) {
        springc_observed(L->t, y, p, z, obs);
        if (sc_flagged(z)) { sc_end(L, job, SC_MODEL_FAILED, L->t, y); return 0; }
    }
    sc_emit(s, &L->o, 0, y, obs);
#if SPRINGC_HYBRID
    if (stop) { L->last = L->t; sc_end(L, job, SC_SUCCESS, L->t, y); return 0; }
#endif
    if (s->m == 1 || SC_NX == 0) {
        for (sc_int k = 1; k < s->m; k++) sc_emit(s, &L->o, k, y, obs);
        sc_end(L, job, SC_SUCCESS, L->t, y);
        return 0;
    }
    return sc_restart(L, job);
}

/* The start of an attempt (Step 3 of dop853_run): the step limit, the step size. 1 if
   the lane goes on to the stages, 0 if its run has ended. */
SC_FN int sc_attempt(sc_lane *L, const sc_job *job) {
    const sc_settings *s = &job->s;
    double *y = L->w + SC_AT_Y, limit = sc_min(s->grid[s->m - 1], L->t_stop);
    if (!L->retry) {
        if (s->max_steps > 0 && L->accepted + L->rejected >= s->max_steps) {
            sc_end(L, job, SC_MAX_STEPS, L->t, y);
            return 0;
        }
        L->min_step = 10 * fabs(nextafter(L->t, SC_HUGE) - L->t);
        if (L->h_abs > s->max_step) L->h_abs = s->max_step;
        else if (L->h_abs < L->min_step) L->h_abs = L->min_step;
    }
    if (L->h_abs < L->min_step) { sc_end(L, job, SC_STEP_TOO_SMALL, L->t, y); return 0; }
    L->t_new = L->t + L->h_abs;
    if (L->t_new - limit > 0) L->t_new = limit;
    L->h = L->t_new - L->t;
    L->h_abs = fabs(L->h);
    L->ready = 1;
    return 1;
}

/* A failed evaluation of an attempt: a non-finite derivative while a step 0.2 times
   shorter is allowed rejects the attempt (dop853_steps.shrinks: as scipy's NaN error
   norm does; the lane attempts again), else the run ends. Returns 0 either way. */
SC_FN int sc_failed_attempt(sc_lane *L, const sc_job *job, int status, double t,
                            const double *at) {
    if (status == SC_NON_FINITE_DERIVATIVE && L->h_abs * 0.2 >= L->min_step) {
        L->h_abs *= 0.2;
        L->retry = 1;
        L->rejected += 1;
        L->ready = 0;
        return 0;
    }
    sc_end(L, job, status, t, at);
    return 0;
}

/* Stage st of the attempt (trial: a failed evaluation rejects it where it may, see
   sc_failed_attempt) or of the dense output (the run ends); 0 if it failed. */
SC_FN int sc_stage_of(sc_lane *L, const sc_job *job, int st, int trial) {
    double *w = L->w, *K = w, *sums = w + 25 * SC_NXS, *work = w + 24 * SC_NXS;
    double *z = w + SC_AT_Z, t = L->t + DOP_C[st] * L->h;
    sc_stage(w + SC_AT_Y, K, st, L->h, sums, work);
    springc_rhs(t, work, w + SC_AT_P, z, K + st * SC_NXS);
    L->nfev += 1;
    int status = sc_verdict(K + st * SC_NXS, z);
    if (status == SC_SUCCESS) return 1;
    if (trial) return sc_failed_attempt(L, job, status, t, work);
    sc_end(L, job, status, t, work);
    return 0;
}

/* The end of an attempt: the new state, its error, accepted or rejected; an accepted
   step fills the output times it passes (Steps 5 and 7). 0 if the run has ended. */
SC_FN int sc_conclude(sc_lane *L, const sc_job *job) {
    const sc_settings *s = &job->s;
    double *w = L->w, *K = w, *F = w + 16 * SC_NXS, *y_new = w + 23 * SC_NXS;
    double *sums = w + 25 * SC_NXS, *scale = w + 26 * SC_NXS, *err5 = w + 27 * SC_NXS;
    double *err3 = w + 28 * SC_NXS, *xo = w + 29 * SC_NXS, *y = w + SC_AT_Y;
    double *p = w + SC_AT_P, *z = w + SC_AT_Z, h = L->h, t = L->t;
    L->ready = 0;
    sc_b_sum(K, sums);
    for (int i = 0; i < SC_NX; i++) y_new[i] = y[i] + h * sums[i];
    springc_rhs(t + h, y_new, p, z, K + SC_STAGES * SC_NXS);
    L->nfev += 1;
    int status = sc_verdict(K + SC_STAGES * SC_NXS, z);
    if (status != SC_SUCCESS) return sc_failed_attempt(L, job, status, t + h, y_new);
    double error = sc_error_norm(y, y_new, K, h, s->rtol, s->atol, scale, err5, err3);
    if (!(error < 1)) {
        L->h_abs *= sc_max(0.2, 0.9 * pow(error, -0.125));
        L->retry = 1;
        L->rejected += 1;
        return 1;
    }
    double factor = error == 0 ? 10.0 : sc_min(10.0, 0.9 * pow(error, -0.125));
    if (L->retry) factor = sc_min(1.0, factor);
    L->h_abs *= factor;
    L->retry = 0;
    L->accepted += 1;
    double t_end = s->grid[s->m - 1], t_event = L->t_new;
    int event = 0, stops = 0;
    sc_int last = s->m;
#if SPRINGC_HYBRID
    /* Step 4: a crossing in (t, t_new]? The last row waits for the events at the end. */
    double *g0 = w + SC_AT_G, *g1 = g0 + SC_NGS, *gt = g1 + SC_NGS;
    if (SPRINGC_N_CROSSINGS > 0) {
        springc_zero_crossings(L->t_new, y_new, p, z, g1);
        if (sc_flagged(z)) { sc_end(L, job, SC_MODEL_FAILED, L->t_new, y_new); return 0; }
        event = sc_crossed(g0, g1, z);
    }
    stops = event || (L->t_new == L->t_stop && L->t_stop < t_end);
    last = s->m - 1;
#endif
    if (event || (L->filled < last && s->grid[L->filled] <= L->t_new)) {
        for (int st = SC_STAGES + 1; st < SC_EXTENDED; st++)
            if (!sc_stage_of(L, job, st, 0)) return 0;
        sc_interpolant(y, y_new, K, h, F, sums);
    }
#if SPRINGC_HYBRID
    /* Step 6: the earliest crossing, by bisection on the dense output. */
    if (event) {
        double low = t, high = L->t_new, tolerance = sc_time_tolerance(t, L->t_new);
        double *at = w + 24 * SC_NXS;
        while (high - low > tolerance) {
            double middle = low + 0.5 * (high - low);
            if (middle <= low || middle >= high) break;
            sc_interpolate(F, y, (middle - t) / h, at);
            springc_zero_crossings(middle, at, p, z, gt);
            if (sc_crossed(g0, gt, z)) high = middle;
            else low = middle;
        }
        t_event = high;
        if (high < L->t_new) sc_interpolate(F, y, (high - t) / h, y_new);
    }
#endif
    if (L->filled < last && s->grid[L->filled] <= L->t_new) {
        status = sc_outputs_in_step(s, &L->o, &L->filled, t, L->t_new, h, y, y_new, F, xo,
                                    w + SC_AT_OBS, p, z, t_event, stops, last);
        if (status != SC_SUCCESS) {
            sc_end(L, job, status, s->grid[L->filled], xo);
            return 0;
        }
    }
    L->t = t_event;
    for (int i = 0; i < SC_NX; i++) {
        y[i] = y_new[i];
        K[i] = K[SC_STAGES * SC_NXS + i];
    }
#if SPRINGC_HYBRID
    for (int k = 0; k < SPRINGC_N_CROSSINGS; k++) g0[k] = g1[k];
    if (stops) {  /* Step 7: the event, the rows at its time, the restart */
        int stop = 0;
        status = sc_event(L, job, 1, &stop);
        if (status != SC_SUCCESS) { sc_end(L, job, status, L->t, y); return 0; }
        if (stop) {
            status = sc_rows_at(L, job, last);
            if (status != SC_SUCCESS) { sc_end(L, job, status, L->t, y); return 0; }
            sc_terminated(L, job);
            return 0;
        }
        if (!(L->t < t_end)) { sc_final(L, job, 0); return 0; }
        status = sc_rows_at(L, job, last);
        if (status != SC_SUCCESS) { sc_end(L, job, status, L->t, y); return 0; }
        return sc_restart(L, job);
    }
    if (!(L->t < t_end)) { sc_final(L, job, 1); return 0; }
#else
    if (!(L->t < t_end)) { sc_end(L, job, SC_SUCCESS, L->t, y); return 0; }
#endif
    return 1;
}

/* A thread's share of the runs, SC_LANES at a time: an idle lane takes the next run
   (and the next, while runs end at their start); the ready lanes go through each
   stage together. */
SC_FN void sc_work(sc_job *job, double *block) {
    sc_lane lanes[SC_LANES];
    int exhausted = 0;
    for (int l = 0; l < SC_LANES; l++) {
        lanes[l].w = block + l * SC_WORK;
        lanes[l].run = -1;
        lanes[l].ready = 0;
    }
    for (;;) {
        int any = 0;
        for (int l = 0; l < SC_LANES; l++) {
            sc_lane *L = &lanes[l];
            while (!exhausted || L->run >= 0) {
                if (L->run < 0) {
                    sc_int r = sc_take(job);
                    if (r < 0) { exhausted = 1; break; }
                    if (!sc_start(L, job, r)) continue;
                }
                if (sc_attempt(L, job)) break;
            }
            any |= L->ready;
        }
        if (!any) return;
        for (int st = 1; st < SC_STAGES; st++)
            for (int l = 0; l < SC_LANES; l++)
                if (lanes[l].ready) lanes[l].ready = sc_stage_of(&lanes[l], job, st, 1);
        for (int l = 0; l < SC_LANES; l++)
            if (lanes[l].ready) sc_conclude(&lanes[l], job);
    }
}

#define SC_ENTRY_ARGS                                                                     \
    sc_int runs, int prepared, const double *V, sc_int n_v, const sc_int *v_index,           \
    const double *base, const int *given, const double *P, const double *X0,              \
    const double *Z, const double *grid, sc_int m, double rtol, const double *atol,         \
    double max_step, sc_int max_steps, const sc_int *columns, sc_int n_columns,            \
    const sc_int *traj_columns, sc_int n_traj, sc_int every, sc_int n_traj_points,          \
    int need_observed, double *summary, double *traj, double *final, sc_int *status,        \
    sc_int *counts, double *failure_time

#define SC_ENTRY_NAMES                                                                    \
    runs, prepared, V, n_v, v_index, base, given, P, X0, Z, grid, m, rtol, atol, max_step,   \
    max_steps, columns, n_columns, traj_columns, n_traj, every, n_traj_points,              \
    need_observed, summary, traj, final, status, counts, failure_time

#define SC_SETUP(job)                                                                     \
    sc_job job = {{grid, m, rtol, atol, max_step, max_steps, columns, n_columns,             \
                   traj_columns, n_traj, every, n_traj_points, need_observed},              \
                  {summary, traj, final, status, counts, failure_time},                    \
                  prepared, V, n_v, v_index, base, given, P, X0, Z, runs, 1, 0, 0}

#ifdef SC_CUDA
/* One thread per run (runs beyond the launch's threads: every stride-th). */
extern "C" __global__ void springc_ensemble(SC_ENTRY_ARGS) {
    SC_SETUP(job);
    job.next = (sc_int)blockIdx.x * blockDim.x + threadIdx.x;
    job.stride = (sc_int)gridDim.x * blockDim.x;
    double block[SC_LANES * SC_WORK];
    sc_work(&job, block);
}
#ifdef SC_EMULATE_CUDA
#include SC_EMULATE_CUDA
#endif
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

/* Every run: `threads` threads (0: OpenMP's default) take runs one at a time, each
   keeping SC_LANES in progress. Run r's parameters: with `prepared`, row r of P, X0
   and Z; else `base` with the n_v varied ones (at v_index) from row r of V, completed
   by springc_parameters (`given` marks the parameters set by the user: the ones bound
   to them follow) and springc_start. A run whose parameters or start values are not
   finite ends with SC_BAD_START. Returns 0, or -1 if runs were left (no thread could
   allocate its work arrays). */
int springc_ensemble(SC_ENTRY_ARGS, int threads) {
    SC_SETUP(job);
    sc_int counter = 0;
    job.counter = &counter;
#ifdef _OPENMP
    if (threads <= 0) threads = omp_get_max_threads();
#pragma omp parallel num_threads(threads)
#endif
    {
        sc_job mine = job;
        double *block = (double *)malloc((size_t)SC_LANES * SC_WORK * sizeof(double));
        if (block != NULL) sc_work(&mine, block);
        free(block);
    }
    (void)threads;
    return counter < runs ? -1 : 0;
}
#endif
