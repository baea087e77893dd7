/* springc's implicit methods in C, Radau IIA (order 5) and BDF (orders 1-5): the hooks
   of the single-run loop (single_loop.c) for stiff models.

   springc.integrate.native_loop puts this text after single_loop.c, and before both
   the methods' constants (si_radau_*, si_bdf_*: radau_tableau's and bdf_steps' values
   printed by Python). The arithmetic is that of the numba hooks, operation for
   operation: integrate.radau_steps (scipy's Radau: the simplified Newton iteration of
   the collocation system transformed into one real and one complex system, Jacobian
   reuse, refactorisation on a step-size change, Gustafsson's predictive controller,
   the collocation polynomial as dense output) and integrate.bdf_steps (scipy's BDF:
   the NDF/BDF formulas in backward-difference form, order selection, Newton iteration
   of I - c J). The Newton matrices are factorised by a banded LU with partial
   pivoting (integrate.banded_lu's gbtrf-style elimination, real and complex C99
   double complex, written here once as a macro): the library links nothing but libc
   and libm, so that it loads with the standard library and ctypes alone (no numpy,
   scipy or LAPACK). Up to SI_DENSE_LIMIT states the band is the whole matrix in state
   order (a dense LU, as integrate.ordering.band_layout); above, in the ordering the
   caller gives (its reverse Cuthill-McKee, NULL: state order) with the bandwidths of
   the Jacobian's pattern there.

   The Jacobian is the C model's analytic springc_jacobian (non-zeros in CSC order); a
   model printed without one (over codegen.c_model.JACOBIAN_LIMIT non-zeros) gets a
   dense forward-difference Jacobian here (each column's evaluation counted as a
   right-hand-side evaluation; the numba loops always have the analytic one).
   Complex division is CPython's (and numba's) algorithm, not the C library's, so that
   the factors equal the numba loop's. */

#define SI_DENSE_LIMIT 64
#define SI_MIN_FACTOR 0.2
#define SI_MAX_FACTOR 10.0
#define SI_EPS 2.220446049250313e-16

typedef double complex si_complex;

/* The model's right-hand side for the implicit methods: one copy of it, not inlined
   into each of their call sites (the C compiler's time on the library doubled with
   them; a call per evaluation is nothing beside a Newton iteration's work). */
__attribute__((noinline)) static void si_rhs(double t, const double *x, const double *p,
                                             double *z, double *dx) {
    springc_rhs(t, x, p, z, dx);
}

struct si_work {
    int method;
    sl_int n, nnz, kl, ku, width;
    sl_int *order, *positions, *diagonal, *pivots, *pivots2, *solve_order;
    double *J, *real, *D, *Z0, *Z, *Q, *W, *F, *dW, *vec, *tmp, *rescaled;
    si_complex *cplx, *f_complex, *work_complex;
    double newton_tol, h_abs_old, error_norm_old, t_old, h_dense, t_new, h_now;
    int current_jac, factored, have_dense, bdf_order, n_equal;
};

/* numba's float ** int (exponentiation by squaring). */
SC_FN double si_ipow(double a, sl_int b) {
    double r = 1.0;
    int invert = b < 0;
    sl_int e = invert ? -b : b;
    if (e > 0x10000) return pow(a, (double)b);
    while (e != 0) {
        if (e & 1) r *= a;
        e >>= 1;
        a *= a;
    }
    return invert ? 1.0 / r : r;
}

/* CPython's complex division (numba's), not the C library's. */
SC_FN si_complex si_cdiv(si_complex a, si_complex b) {
    double ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b), re, im;
    if (fabs(br) >= fabs(bi)) {
        if (br == 0.0) return NAN + NAN * I;
        double ratio = bi / br, denom = br + bi * ratio;
        re = (ar + ai * ratio) / denom;
        im = (ai - ar * ratio) / denom;
    } else {
        double ratio = br / bi, denom = br * ratio + bi;
        re = (ar * ratio + ai) / denom;
        im = (ai * ratio - ar) / denom;
    }
    si_complex v = im * I;
    return v + re;
}

SC_FN double si_real_div(double a, double b) { return a / b; }
SC_FN double si_real_abs(double a) { return fabs(a); }
SC_FN double si_complex_abs(si_complex a) { return hypot(creal(a), cimag(a)); }

/* The banded LU (integrate.banded_lu): B row-major, n rows of width 2 kl + ku + 1,
   B[i][j - i + kl] = A[i][j]; factor (0 if a pivot is zero) and solve in place. */
#define SI_BAND_LU(FACTOR, SOLVE, TYPE, ABS, DIV)                                         \
    SC_FN int FACTOR(TYPE *B, sl_int n, sl_int kl, sl_int ku, sl_int *pivots) {         \
        sl_int w = 2 * kl + ku + 1, width = kl + ku;                                     \
        for (sl_int k = 0; k < n; k++) {                                                 \
            sl_int last = n - 1 < k + kl ? n - 1 : k + kl, p = k;                       \
            double best = ABS(B[k * w + kl]);                                            \
            for (sl_int i = k + 1; i <= last; i++) {                                     \
                double size = ABS(B[i * w + k - i + kl]);                                \
                if (size > best) {                                                       \
                    best = size;                                                         \
                    p = i;                                                               \
                }                                                                        \
            }                                                                            \
            pivots[k] = p;                                                               \
            if (best == 0.0) return 0;                                                   \
            sl_int right = n - 1 < k + width ? n - 1 : k + width;                        \
            if (p != k) {                                                                \
                for (sl_int j = k; j <= right; j++) {                                    \
                    TYPE a = B[k * w + j - k + kl];                                      \
                    B[k * w + j - k + kl] = B[p * w + j - p + kl];                       \
                    B[p * w + j - p + kl] = a;                                           \
                }                                                                        \
            }                                                                            \
            TYPE pivot = B[k * w + kl];                                                  \
            for (sl_int i = k + 1; i <= last; i++) {                                     \
                TYPE m = DIV(B[i * w + k - i + kl], pivot);                              \
                B[i * w + k - i + kl] = m;                                               \
                if (m != 0.0) {                                                          \
                    for (sl_int j = k + 1; j <= right; j++)                              \
                        B[i * w + j - i + kl] -= m * B[k * w + j - k + kl];              \
                }                                                                        \
            }                                                                            \
        }                                                                                \
        return 1;                                                                        \
    }                                                                                    \
    SC_FN void SOLVE(const TYPE *B, sl_int n, sl_int kl, sl_int ku, const sl_int *pivots, \
                     TYPE *b) {                                                          \
        sl_int w = 2 * kl + ku + 1, width = kl + ku;                                     \
        for (sl_int k = 0; k < n; k++) {                                                 \
            sl_int p = pivots[k];                                                        \
            if (p != k) {                                                                \
                TYPE a = b[k];                                                           \
                b[k] = b[p];                                                             \
                b[p] = a;                                                                \
            }                                                                            \
            TYPE bk = b[k];                                                              \
            sl_int last = n - 1 < k + kl ? n - 1 : k + kl;                               \
            for (sl_int i = k + 1; i <= last; i++) b[i] -= B[i * w + k - i + kl] * bk;  \
        }                                                                                \
        for (sl_int k = n - 1; k >= 0; k--) {                                            \
            TYPE s = b[k];                                                               \
            sl_int right = n - 1 < k + width ? n - 1 : k + width;                        \
            for (sl_int j = k + 1; j <= right; j++) s -= B[k * w + j - k + kl] * b[j];   \
            b[k] = DIV(s, B[k * w + kl]);                                                \
        }                                                                                \
    }

SI_BAND_LU(si_factor_real, si_solve_real, double, si_real_abs, si_real_div)
SI_BAND_LU(si_factor_complex, si_solve_complex, si_complex, si_complex_abs, si_cdiv)

/* Solve with the band factors of the reordered matrix, b in state order, in place
   (radau_steps.solve_in_order); real and complex. */
SC_FN void si_solve_in_order(const struct si_work *s, const double *B, const sl_int *piv,
                             double *b, double *work) {
    for (sl_int i = 0; i < s->n; i++) work[i] = b[s->order[i]];
    si_solve_real(B, s->n, s->kl, s->ku, piv, work);
    for (sl_int i = 0; i < s->n; i++) b[s->order[i]] = work[i];
}

SC_FN void si_solve_in_order_complex(const struct si_work *s, si_complex *b) {
    for (sl_int i = 0; i < s->n; i++) s->work_complex[i] = b[s->order[i]];
    si_solve_complex(s->cplx, s->n, s->kl, s->ku, s->pivots2, s->work_complex);
    for (sl_int i = 0; i < s->n; i++) b[s->order[i]] = s->work_complex[i];
}

/* The Jacobian's non-zeros at (t, y) into s->J (analytic, or forward differences),
   and its verdict. */
SC_FN int si_jacobian(struct si_work *s, double t, const double *y, const double *p,
                      double *z, sl_int *counts, double *scratch) {
    counts[3] += 1;
#if SPRINGC_HAS_JACOBIAN
    (void)scratch;
    springc_jacobian(t, y, p, z, s->J);
#else
    double *f0 = scratch, *f1 = scratch + SC_NXS, *x = scratch + 2 * SC_NXS;
    si_rhs(t, y, p, z, f0);
    counts[SL_RHS_CALLS] += 1;
    for (int j = 0; j < SC_NX && !sc_flagged(z); j++) {
        sl_copy(x, y);
        double h = sqrt(SI_EPS) * sc_max(1.0, fabs(y[j]));
        x[j] = y[j] + h;
        h = x[j] - y[j];
        si_rhs(t, x, p, z, f1);
        counts[SL_RHS_CALLS] += 1;
        for (int i = 0; i < SC_NX; i++) s->J[j * SC_NX + i] = (f1[i] - f0[i]) / h;
    }
#endif
    if (sc_flagged(z)) return SC_MODEL_FAILED;
    for (sl_int k = 0; k < s->nnz; k++)
        if (!isfinite(s->J[k])) return SC_NON_FINITE_DERIVATIVE;
    return SC_SUCCESS;
}

SC_FN double si_rms(const double *x, sl_int size) {
    double total = 0.0;
    for (sl_int i = 0; i < size; i++) total += x[i] * x[i];
    return sqrt(total) / pow((double)size, 0.5);
}

/* rms(weight * x / scale) (bdf_steps.scaled_rms). */
SC_FN double si_scaled_rms(const double *x, double weight, const double *scale) {
    double total = 0.0;
    for (int j = 0; j < SC_NX; j++) {
        double value = weight * x[j] / scale[j];
        total += value * value;
    }
    return sqrt(total) / pow((double)SC_NX, 0.5);
}

/* ---- Radau IIA (radau_steps) ---- */

/* MU_REAL / h I - J and MU_COMPLEX / h I - J in their bands, factorised; 0 if either
   is singular. */
SC_FN int si_factor_radau(struct si_work *s, double h) {
    sl_int cells = s->n * s->width;
    for (sl_int k = 0; k < cells; k++) {
        s->real[k] = 0.0;
        s->cplx[k] = 0.0;
    }
    si_complex mu = si_radau_mu_complex();
    for (sl_int k = 0; k < s->n; k++) {
        s->real[s->diagonal[k]] = SI_MU_REAL / h;
        s->cplx[s->diagonal[k]] = si_cdiv(mu, h + 0.0 * I);
    }
    for (sl_int k = 0; k < s->nnz; k++) {
        s->real[s->positions[k]] -= s->J[k];
        s->cplx[s->positions[k]] -= s->J[k];
    }
    return si_factor_real(s->real, s->n, s->kl, s->ku, s->pivots)
           && si_factor_complex(s->cplx, s->n, s->kl, s->ku, s->pivots2);
}

/* Gustafsson's predictive step-size factor (h_abs_old < 0: no history). */
SC_FN double si_predict_factor(double h_abs, double h_abs_old, double error_norm,
                               double error_norm_old) {
    double multiplier;
    if (error_norm_old < 0 || h_abs_old < 0 || error_norm == 0) multiplier = 1.0;
    else multiplier = h_abs / h_abs_old * pow(error_norm_old / error_norm, 0.25);
    if (error_norm == 0) return INFINITY;
    return sc_min(1.0, multiplier) * pow(error_norm, -0.25);
}

/* The simplified Newton iteration of the collocation system from Z0 (radau_steps.newton):
   the stage increments in Z; *converged, *iterations, *rate; the status. */
SC_FN int si_newton_radau(struct si_work *s, double t, const double *y, double h,
                          const double *scale, const double *p, double *z,
                          sl_int *counts, int *converged, int *iterations, double *rate) {
    sl_int n = s->n;
    double *W = s->W, *Fs = s->F, *dW = s->dW, *Z = s->Z, *Z0 = s->Z0;
    double *f_real = s->tmp, *work_real = s->tmp + n, *stage = s->tmp + 2 * n;
    si_complex *f_complex = s->f_complex;
    double m_real = SI_MU_REAL / h;
    si_complex m_complex = si_cdiv(si_radau_mu_complex(), h + 0.0 * I);
    for (sl_int k = 0; k < 3 * n; k++) W[k] = 0.0;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            for (sl_int j = 0; j < n; j++) W[r * n + j] += SI_RADAU_TI[r][c] * Z0[c * n + j];
    for (sl_int k = 0; k < 3 * n; k++) Z[k] = Z0[k];
    double dW_norm_old = -1.0;
    *rate = -1.0;
    *converged = 0;
    *iterations = 0;
    for (int k = 0; k < SI_NEWTON_RADAU; k++) {
        *iterations = k + 1;
        int finite = 1;
        for (int i = 0; i < 3; i++) {
            for (sl_int j = 0; j < n; j++) stage[j] = y[j] + Z[i * n + j];
            si_rhs(t + h * SI_RADAU_C[i], stage, p, z, Fs + i * n);
            counts[SL_RHS_CALLS] += 1;
            if (sc_flagged(z)) return SC_MODEL_FAILED;
            for (sl_int j = 0; j < n; j++)
                if (!isfinite(Fs[i * n + j])) finite = 0;
        }
        if (!finite) break;
        for (sl_int j = 0; j < n; j++) {
            f_real[j] = Fs[j] * SI_RADAU_TI[0][0] + Fs[n + j] * SI_RADAU_TI[0][1]
                        + Fs[2 * n + j] * SI_RADAU_TI[0][2] - m_real * W[j];
            f_complex[j] = Fs[j] * si_radau_ti_complex(0) + Fs[n + j] * si_radau_ti_complex(1)
                           + Fs[2 * n + j] * si_radau_ti_complex(2)
                           - m_complex * (W[n + j] + W[2 * n + j] * I);
        }
        si_solve_in_order(s, s->real, s->pivots, f_real, work_real);
        si_solve_in_order_complex(s, f_complex);
        for (sl_int j = 0; j < n; j++) {
            dW[j] = f_real[j] / scale[j];
            dW[n + j] = creal(f_complex[j]) / scale[j];
            dW[2 * n + j] = cimag(f_complex[j]) / scale[j];
        }
        double dW_norm = si_rms(dW, 3 * n);
        if (dW_norm_old >= 0) *rate = dW_norm / dW_norm_old;
        if (*rate >= 0 && (*rate >= 1 || si_ipow(*rate, SI_NEWTON_RADAU - k) / (1 - *rate)
                                                 * dW_norm > s->newton_tol))
            break;
        for (sl_int j = 0; j < n; j++) {
            W[j] += f_real[j];
            W[n + j] += creal(f_complex[j]);
            W[2 * n + j] += cimag(f_complex[j]);
        }
        for (int r = 0; r < 3; r++)
            for (sl_int j = 0; j < n; j++)
                Z[r * n + j] = SI_RADAU_T[r][0] * W[j] + SI_RADAU_T[r][1] * W[n + j]
                               + SI_RADAU_T[r][2] * W[2 * n + j];
        if (dW_norm == 0 || (*rate >= 0 && *rate / (1 - *rate) * dW_norm < s->newton_tol)) {
            *converged = 1;
            return SC_SUCCESS;
        }
        dW_norm_old = dW_norm;
    }
    return SC_SUCCESS;
}

/* The collocation system of the step h solved by Newton's method, the matrices
   factorised again (and the Jacobian evaluated again once) where needed
   (radau_steps.converge). */
SC_FN int si_converge_radau(struct si_work *s, double t, const double *y, double h,
                            const double *scale, const double *p, double *z,
                            sl_int *counts, int *converged, int *n_iter, double *rate) {
    *converged = 0;
    *n_iter = 0;
    *rate = -1.0;
    while (!*converged) {
        if (!s->factored) s->factored = si_factor_radau(s, h);
        if (s->factored) {
            int status = si_newton_radau(s, t, y, h, scale, p, z, counts, converged, n_iter,
                                         rate);
            if (status != SC_SUCCESS) {
                *converged = 0;
                return status;
            }
        }
        if (*converged || s->current_jac) break;
        int status = si_jacobian(s, t, y, p, z, counts, s->tmp);
        if (status != SC_SUCCESS) return status;
        s->current_jac = 1;
        s->factored = 0;
    }
    return SC_SUCCESS;
}

/* The dense output of the last step's collocation polynomial at step fraction x. */
SC_FN void si_radau_dense(const double *Q, const double *y_old, double x, double *out) {
    double x2 = x * x, x3 = x2 * x;
    for (int j = 0; j < SC_NX; j++)
        out[j] = y_old[j] + Q[j * 3] * x + Q[j * 3 + 1] * x2 + Q[j * 3 + 2] * x3;
}

#define SI_Y_OLD 0
#define SI_SCALE 1
#define SI_ERROR 2
#define SI_ERROR_Z 3
#define SI_STAGE 4
#define SI_F 5
#define SI_ROW(s, r) ((s)->vec + (r) * (s)->n)

/* After an accepted step (radau_steps.after_step): the next step size, the derivative
   at the new state, the Jacobian there if Newton converged slowly, the step's
   collocation polynomial. */
SC_FN int si_after_radau(struct si_work *s, double t, const double *y, double t_new,
                         double h, double *h_abs, double h_proposed, double step_h_old,
                         double step_error_old, int n_iter, double rate, double error_norm,
                         double safety, const double *p, double *z, sl_int *counts,
                         const double *y_new, double *end, double *t_fail) {
    sl_int n = s->n;
    int recompute_jac = n_iter > 2 && rate > 1e-3;
    double factor = sc_min(SI_MAX_FACTOR, safety * si_predict_factor(*h_abs, step_h_old,
                                                                    error_norm,
                                                                    step_error_old));
    if (!recompute_jac && factor < 1.2) factor = 1.0;
    else s->factored = 0;
    double *f = SI_ROW(s, SI_F);
    si_rhs(t_new, y_new, p, z, f);
    counts[SL_RHS_CALLS] += 1;
    int status = sc_verdict(f, z);
    *t_fail = t_new;
    if (status != SC_SUCCESS) {
        sl_copy(end, y_new);
        return status;
    }
    if (recompute_jac) {
        status = si_jacobian(s, t_new, y_new, p, z, counts, s->tmp);
        if (status != SC_SUCCESS) {
            sl_copy(end, y_new);
            return status;
        }
        s->current_jac = 1;
    } else {
        s->current_jac = 0;
    }
    s->h_abs_old = h_proposed;
    s->error_norm_old = error_norm;
    sl_copy(SI_ROW(s, SI_Y_OLD), y);
    s->t_old = t;
    s->h_dense = h;
    for (sl_int j = 0; j < n; j++)
        for (int c = 0; c < 3; c++)
            s->Q[j * 3 + c] = s->Z[j] * SI_RADAU_P[0][c] + s->Z[n + j] * SI_RADAU_P[1][c]
                              + s->Z[2 * n + j] * SI_RADAU_P[2][c];
    s->have_dense = 1;
    *h_abs = *h_abs * factor;
    *t_fail = t;
    return SC_SUCCESS;
}

/* The last step's collocation polynomial extrapolated to the stages of the step h. */
SC_FN void si_radau_predict(struct si_work *s, double t, const double *y, double h) {
    sl_int n = s->n;
    double *stage = SI_ROW(s, SI_STAGE);
    for (int i = 0; i < 3; i++) {
        if (s->have_dense) {
            si_radau_dense(s->Q, SI_ROW(s, SI_Y_OLD),
                           (t + h * SI_RADAU_C[i] - s->t_old) / s->h_dense, stage);
            for (sl_int j = 0; j < n; j++) s->Z0[i * n + j] = stage[j] - y[j];
        } else {
            for (sl_int j = 0; j < n; j++) s->Z0[i * n + j] = 0.0;
        }
    }
}

/* The error estimate of the converged step (radau_steps.step), its norm. */
SC_FN double si_radau_error(struct si_work *s, const double *y, const double *y_new,
                            double h, double rtol, const double *atol) {
    sl_int n = s->n;
    double *Z = s->Z, *error = SI_ROW(s, SI_ERROR), *ZE = SI_ROW(s, SI_ERROR_Z);
    double *stage = SI_ROW(s, SI_STAGE), *scale = SI_ROW(s, SI_SCALE), *f = SI_ROW(s, SI_F);
    for (sl_int j = 0; j < n; j++) {
        ZE[j] = (Z[j] * SI_RADAU_E[0] + Z[n + j] * SI_RADAU_E[1] + Z[2 * n + j] * SI_RADAU_E[2])
                / h;
        error[j] = f[j] + ZE[j];
    }
    si_solve_in_order(s, s->real, s->pivots, error, stage);
    for (sl_int j = 0; j < n; j++) {
        scale[j] = atol[j] + sc_max(fabs(y[j]), fabs(y_new[j])) * rtol;
        stage[j] = error[j] / scale[j];
    }
    return si_rms(stage, n);
}

/* One accepted step of Radau IIA from (t, y), rejected ones before it
   (radau_steps.step); the hook contract of sl_step. */
SC_FN int si_step_radau(struct si_work *s, double t, const double *y, double h_proposed,
                        double *h_abs, double min_step, double limit, const double *p,
                        double *z, double rtol, const double *atol, sl_int *counts,
                        double *y_new, double *end, double *t_new, double *h,
                        double *t_fail) {
    sl_int n = s->n;
    double *scale = SI_ROW(s, SI_SCALE), *error = SI_ROW(s, SI_ERROR);
    double *ZE = SI_ROW(s, SI_ERROR_Z), *stage = SI_ROW(s, SI_STAGE);
    double step_h_old = s->h_abs_old, step_error_old = s->error_norm_old;
    if (*h_abs != h_proposed) {
        step_h_old = -1.0;
        step_error_old = -1.0;
    }
    int step_rejected = 0, n_iter = 0, converged = 0;
    double rate = -1.0, error_norm = 0.0, safety = 0.9;
    *t_fail = t;
    for (;;) {
        if (*h_abs < min_step) {
            sl_copy(end, y);
            *t_new = t;
            *h = 0.0;
            return SC_STEP_TOO_SMALL;
        }
        *t_new = t + *h_abs;
        if (*t_new - limit > 0) *t_new = limit;
        *h = *t_new - t;
        *h_abs = fabs(*h);
        si_radau_predict(s, t, y, *h);
        for (sl_int j = 0; j < n; j++) scale[j] = atol[j] + fabs(y[j]) * rtol;
        int status = si_converge_radau(s, t, y, *h, scale, p, z, counts, &converged,
                                       &n_iter, &rate);
        if (status != SC_SUCCESS) {
            sl_copy(end, y);
            *t_new = t;
            return status;
        }
        if (!converged) {
            *h_abs *= 0.5;
            s->factored = 0;
            counts[SL_REJECTED] += 1;
            continue;
        }
        for (sl_int j = 0; j < n; j++) y_new[j] = y[j] + s->Z[2 * n + j];
        error_norm = si_radau_error(s, y, y_new, *h, rtol, atol);
        safety = 0.9 * (2 * SI_NEWTON_RADAU + 1) / (2 * SI_NEWTON_RADAU + n_iter);
        if (step_rejected && error_norm > 1) {
            for (sl_int j = 0; j < n; j++) stage[j] = y[j] + error[j];
            si_rhs(t, stage, p, z, s->tmp);
            counts[SL_RHS_CALLS] += 1;
            if (sc_flagged(z)) {
                sl_copy(end, stage);
                *t_new = t;
                return SC_MODEL_FAILED;
            }
            for (sl_int j = 0; j < n; j++) error[j] = s->tmp[j] + ZE[j];
            si_solve_in_order(s, s->real, s->pivots, error, stage);
            for (sl_int j = 0; j < n; j++) stage[j] = error[j] / scale[j];
            error_norm = si_rms(stage, n);
        }
        if (error_norm > 1) {
            double factor = si_predict_factor(*h_abs, step_h_old, error_norm, step_error_old);
            *h_abs *= sc_max(SI_MIN_FACTOR, safety * factor);
            s->factored = 0;
            step_rejected = 1;
            counts[SL_REJECTED] += 1;
            continue;
        }
        break;
    }
    return si_after_radau(s, t, y, *t_new, *h, h_abs, h_proposed, step_h_old,
                          step_error_old, n_iter, rate, error_norm, safety, p, z, counts,
                          y_new, end, t_fail);
}

/* ---- BDF (bdf_steps) ---- */

#define SI_PREDICT 0
#define SI_PSI 1
#define SI_CORRECTION 2
#define SI_BSCALE 3
#define SI_DY 4
#define SI_SOLVE 5

/* The matrix that rescales the differences of order to a step factor times longer
   (scipy's compute_R), into M (order + 1 columns, row-major). */
SC_FN void si_step_ratio(int order, double factor, double *M) {
    int w = order + 1;
    for (int i = 0; i < w * w; i++) M[i] = 0.0;
    for (int j = 0; j < w; j++) M[j] = 1.0;
    for (int i = 1; i <= order; i++)
        for (int j = 1; j <= order; j++) M[i * w + j] = (i - 1 - factor * j) / i;
    for (int i = 1; i <= order; i++)
        for (int j = 0; j < w; j++) M[i * w + j] *= M[(i - 1) * w + j];
}

/* D[:order + 1] rescaled to a step factor times longer (scipy's change_D). */
SC_FN void si_change_differences(struct si_work *s, int order, double factor) {
    double R[(SI_MAX_ORDER + 1) * (SI_MAX_ORDER + 1)], U[(SI_MAX_ORDER + 1) * (SI_MAX_ORDER + 1)];
    double RU[(SI_MAX_ORDER + 1) * (SI_MAX_ORDER + 1)];
    int w = order + 1;
    sl_int n = s->n;
    si_step_ratio(order, factor, R);
    si_step_ratio(order, 1.0, U);
    for (int i = 0; i < w * w; i++) RU[i] = 0.0;
    for (int i = 0; i < w; i++)
        for (int k = 0; k < w; k++)
            for (int j = 0; j < w; j++) RU[i * w + j] += R[i * w + k] * U[k * w + j];
    double *out = s->rescaled;
    for (sl_int k = 0; k < w * n; k++) out[k] = 0.0;
    for (int k = 0; k < w; k++)
        for (int i = 0; i < w; i++)
            for (sl_int j = 0; j < n; j++) out[i * n + j] += RU[k * w + i] * s->D[k * n + j];
    for (sl_int k = 0; k < w * n; k++) s->D[k] = out[k];
}

/* I - c J in its band, factorised; 0 if singular. */
SC_FN int si_factor_bdf(struct si_work *s, double c) {
    sl_int cells = s->n * s->width;
    for (sl_int k = 0; k < cells; k++) s->real[k] = 0.0;
    for (sl_int k = 0; k < s->n; k++) s->real[s->diagonal[k]] = 1.0;
    for (sl_int k = 0; k < s->nnz; k++) s->real[s->positions[k]] -= c * s->J[k];
    return si_factor_real(s->real, s->n, s->kl, s->ku, s->pivots);
}

/* The Newton iteration of the step from the predictor (bdf_steps.newton_bdf): the new
   state in y, its correction in the CORRECTION row. */
SC_FN int si_newton_bdf(struct si_work *s, double t_new, double c, const double *p,
                        double *z, sl_int *counts, double *y, int *converged,
                        int *iterations) {
    sl_int n = s->n;
    const double *y_predict = SI_ROW(s, SI_PREDICT), *psi = SI_ROW(s, SI_PSI);
    const double *scale = SI_ROW(s, SI_BSCALE);
    double *d = SI_ROW(s, SI_CORRECTION), *dy = SI_ROW(s, SI_DY), *f = s->tmp;
    sl_copy(y, y_predict);
    for (sl_int j = 0; j < n; j++) d[j] = 0.0;
    double dy_norm_old = -1.0, rate = -1.0;
    *converged = 0;
    *iterations = 0;
    for (int k = 0; k < SI_NEWTON_BDF; k++) {
        *iterations = k + 1;
        si_rhs(t_new, y, p, z, f);
        counts[SL_RHS_CALLS] += 1;
        if (sc_flagged(z)) return SC_MODEL_FAILED;
        int finite = 1;
        for (sl_int j = 0; j < n; j++) {
            if (!isfinite(f[j])) finite = 0;
            dy[j] = c * f[j] - psi[j] - d[j];
        }
        if (!finite) break;
        si_solve_in_order(s, s->real, s->pivots, dy, SI_ROW(s, SI_SOLVE));
        double dy_norm = si_scaled_rms(dy, 1.0, scale);
        rate = dy_norm_old >= 0 ? dy_norm / dy_norm_old : -1.0;
        if (rate >= 0 && (rate >= 1 || si_ipow(rate, SI_NEWTON_BDF - k) / (1 - rate) * dy_norm
                                           > s->newton_tol))
            break;
        for (sl_int j = 0; j < n; j++) {
            y[j] += dy[j];
            d[j] += dy[j];
        }
        if (dy_norm == 0 || (rate >= 0 && rate / (1 - rate) * dy_norm < s->newton_tol)) {
            *converged = 1;
            return SC_SUCCESS;
        }
        dy_norm_old = dy_norm;
    }
    return SC_SUCCESS;
}

/* Newton's iteration of the step to t_new, the matrix factorised again (and the
   Jacobian evaluated again once) where needed (bdf_steps.converge). */
SC_FN int si_converge_bdf(struct si_work *s, double t_new, double c, const double *p,
                          double *z, sl_int *counts, double *y_new, double *end,
                          int *converged, int *n_iter) {
    const double *y_predict = SI_ROW(s, SI_PREDICT);
    *converged = 0;
    *n_iter = 0;
    for (;;) {
        if (!s->factored) s->factored = si_factor_bdf(s, c);
        if (s->factored) {
            int status = si_newton_bdf(s, t_new, c, p, z, counts, y_new, converged, n_iter);
            if (status != SC_SUCCESS) {
                sl_copy(end, y_new);
                *converged = 0;
                return status;
            }
        }
        if (*converged || s->current_jac) return SC_SUCCESS;
        int status = si_jacobian(s, t_new, y_predict, p, z, counts, s->rescaled);
        if (status != SC_SUCCESS) {
            sl_copy(end, y_predict);
            return status;
        }
        s->factored = 0;
        s->current_jac = 1;
    }
}

/* The differences after an accepted step, and maybe another order and step size
   (bdf_steps.new_differences): the next step size. */
SC_FN double si_new_differences(struct si_work *s, double t_new, double h_abs,
                                double safety, double error_norm) {
    sl_int n = s->n;
    double *D = s->D, *d = SI_ROW(s, SI_CORRECTION), *scale = SI_ROW(s, SI_BSCALE);
    int order = s->bdf_order;
    s->n_equal += 1;
    for (sl_int i = 0; i < n; i++) {
        D[(order + 2) * n + i] = d[i] - D[(order + 1) * n + i];
        D[(order + 1) * n + i] = d[i];
    }
    for (int k = order; k >= 0; k--)
        for (sl_int i = 0; i < n; i++) D[k * n + i] += D[(k + 1) * n + i];
    if (s->n_equal >= order + 1) {
        double norms[3];
        norms[0] = order > 1 ? si_scaled_rms(D + order * n, SI_BDF_ERROR_CONST[order - 1], scale)
                             : INFINITY;
        norms[1] = error_norm;
        norms[2] = order < SI_MAX_ORDER
                   ? si_scaled_rms(D + (order + 2) * n, SI_BDF_ERROR_CONST[order + 1], scale)
                   : INFINITY;
        double best = -1.0;
        int delta = 0;
        for (int k = 0; k < 3; k++) {
            double grow = norms[k] == 0 ? INFINITY : pow(norms[k], -1.0 / (order + k));
            if (grow > best) {
                best = grow;
                delta = k - 1;
            }
        }
        order += delta;
        double factor = sc_min(SI_MAX_FACTOR, safety * best);
        h_abs *= factor;
        si_change_differences(s, order, factor);
        s->bdf_order = order;
        s->n_equal = 0;
        s->factored = 0;
    }
    s->t_new = t_new;
    s->h_now = h_abs;
    return h_abs;
}

/* The predictor of the step, its psi and the error weights (bdf_steps.step). */
SC_FN void si_bdf_predict(struct si_work *s, int order, double rtol, const double *atol) {
    sl_int n = s->n;
    double *y_predict = SI_ROW(s, SI_PREDICT), *psi = SI_ROW(s, SI_PSI);
    double *scale = SI_ROW(s, SI_BSCALE);
    for (sl_int i = 0; i < n; i++) {
        double total = 0.0;
        for (int j = 0; j <= order; j++) total += s->D[j * n + i];
        y_predict[i] = total;
        scale[i] = atol[i] + rtol * fabs(total);
        double acc = 0.0;
        for (int j = 1; j <= order; j++) acc += s->D[j * n + i] * SI_BDF_GAMMA[j];
        psi[i] = acc / SI_BDF_ALPHA[order];
    }
}

/* One accepted step of BDF from (t, y), rejected ones before it (bdf_steps.step); the
   hook contract of sl_step. */
SC_FN int si_step_bdf(struct si_work *s, double t, const double *y, double h_proposed,
                      double *h_abs, double min_step, double limit, const double *p,
                      double *z, double rtol, const double *atol, sl_int *counts,
                      double *y_new, double *end, double *t_new, double *h, double *t_fail) {
    sl_int n = s->n;
    double *scale = SI_ROW(s, SI_BSCALE);
    if (*h_abs != h_proposed) {
        si_change_differences(s, s->bdf_order, *h_abs / h_proposed);
        s->n_equal = 0;
    }
    s->current_jac = 0;
    *t_fail = t;
    for (;;) {
        int order = s->bdf_order, converged, n_iter;
        if (*h_abs < min_step) {
            sl_copy(end, y);
            *t_new = t;
            *h = 0.0;
            return SC_STEP_TOO_SMALL;
        }
        *t_new = t + *h_abs;
        if (*t_new - limit > 0) {
            *t_new = limit;
            si_change_differences(s, order, fabs(*t_new - t) / *h_abs);
            s->n_equal = 0;
            s->factored = 0;
        }
        *h = *t_new - t;
        *h_abs = fabs(*h);
        si_bdf_predict(s, order, rtol, atol);
        int status = si_converge_bdf(s, *t_new, *h / SI_BDF_ALPHA[order], p, z, counts, y_new,
                                     end, &converged, &n_iter);
        if (status != SC_SUCCESS) {
            *t_fail = *t_new;
            *t_new = t;
            return status;
        }
        if (!converged) {
            *h_abs *= 0.5;
            si_change_differences(s, order, 0.5);
            s->n_equal = 0;
            s->factored = 0;
            counts[SL_REJECTED] += 1;
            continue;
        }
        double safety = 0.9 * (2 * SI_NEWTON_BDF + 1) / (2 * SI_NEWTON_BDF + n_iter);
        for (sl_int i = 0; i < n; i++) scale[i] = atol[i] + rtol * fabs(y_new[i]);
        double error_norm = si_scaled_rms(SI_ROW(s, SI_CORRECTION),
                                          SI_BDF_ERROR_CONST[order], scale);
        if (error_norm > 1) {
            double factor = sc_max(SI_MIN_FACTOR, safety * pow(error_norm, -1.0 / (order + 1)));
            *h_abs *= factor;
            si_change_differences(s, order, factor);
            s->n_equal = 0;
            counts[SL_REJECTED] += 1;
            continue;
        }
        *h_abs = si_new_differences(s, *t_new, *h_abs, safety, error_norm);
        return SC_SUCCESS;
    }
}

/* The interpolating polynomial of the last step at time at. */
SC_FN void si_bdf_dense(const struct si_work *s, double at, double *out) {
    sl_int n = s->n;
    double product = 1.0, h = s->h_now, t = s->t_new;
    sl_copy(out, s->D);
    for (int j = 0; j < s->bdf_order; j++) {
        product *= (at - (t - h * j)) / (h * (1 + j));
        for (sl_int i = 0; i < n; i++) out[i] += s->D[(j + 1) * n + i] * product;
    }
}

/* ---- the hooks' setup and start ---- */

SC_FN void si_free(struct si_work *s) {
    free(s->order);
    free(s->J);
    free(s->cplx);
    free(s);
}

/* The band of the Newton matrices (integrate.ordering.band_layout): up to
   SI_DENSE_LIMIT states the whole matrix in state order; above, in the caller's
   ordering (order: position -> state; NULL: state order) with the pattern's
   bandwidths there; where each non-zero and each diagonal entry lands. */
SC_FN void si_layout(struct si_work *s, const sl_int *order, sl_int *where, int *rows,
                     int *cols) {
    sl_int n = s->n;
#if SPRINGC_HAS_JACOBIAN
    springc_jacobian_pattern(rows, cols);
#else
    for (sl_int k = 0; k < s->nnz; k++) {
        rows[k] = (int)(k % n);
        cols[k] = (int)(k / n);
    }
#endif
    for (sl_int i = 0; i < n; i++) s->order[i] = n > SI_DENSE_LIMIT && order ? order[i] : i;
    for (sl_int i = 0; i < n; i++) where[s->order[i]] = i;
    sl_int kl = 0, ku = 0;
    for (sl_int k = 0; k < s->nnz; k++) {
        sl_int i = where[rows[k]], j = where[cols[k]];
        if (i - j > kl) kl = i - j;
        if (j - i > ku) ku = j - i;
    }
    if (n <= SI_DENSE_LIMIT) kl = ku = n - 1 > 0 ? n - 1 : 0;
    s->kl = kl;
    s->ku = ku;
    s->width = 2 * kl + ku + 1;
    for (sl_int k = 0; k < s->nnz; k++) {
        sl_int i = where[rows[k]], j = where[cols[k]];
        s->positions[k] = i * s->width + (j - i + kl);
    }
    for (sl_int i = 0; i < n; i++) s->diagonal[i] = i * s->width + kl;
}

/* The work arrays of the method (SL_RADAU or SL_BDF) in s; 0 if they could not be
   allocated. */
SC_FN int si_setup(struct si_work *s, int method, const sl_int *order) {
    sl_int n = SC_NX, nx = SC_NXS;
#if SPRINGC_HAS_JACOBIAN
    sl_int nnz = SPRINGC_N_JAC;
#else
    sl_int nnz = n * n;
#endif
    s->method = method;
    s->n = n;
    s->nnz = nnz;
    s->order = (sl_int *)malloc((size_t)(7 * nx + nnz + 1) * sizeof(sl_int));
    s->J = NULL;
    s->cplx = NULL;
    if (s->order == NULL) return 0;
    s->positions = s->order + nx;
    s->diagonal = s->positions + nnz + 1;
    s->pivots = s->diagonal + nx;
    s->pivots2 = s->pivots + nx;
    sl_int *where = s->pivots2 + nx;
    int *pattern = (int *)malloc((size_t)(2 * nnz + 1) * sizeof(int));
    if (pattern == NULL) return 0;
    si_layout(s, order, where, pattern, pattern + nnz);
    free(pattern);
    sl_int band = n * s->width, rows = SI_MAX_ORDER + 3;
    /* J, the real band, D (or Z0, Z, Q, W, F, dW), the vectors, tmp, rescaled */
    sl_int doubles = nnz + band + 18 * nx + 6 * nx + 4 * nx + rows * nx + 1;
    s->J = (double *)malloc((size_t)doubles * sizeof(double));
    s->cplx = (si_complex *)malloc((size_t)(band + 2 * nx + 1) * sizeof(si_complex));
    if (s->J == NULL || s->cplx == NULL) return 0;
    s->real = s->J + nnz;
    s->Z0 = s->D = s->real + band;
    s->Z = s->Z0 + 3 * nx;
    s->Q = s->Z + 3 * nx;
    s->W = s->Q + 3 * nx;
    s->F = s->W + 3 * nx;
    s->dW = s->F + 3 * nx;
    s->vec = s->dW + 3 * nx;
    s->tmp = s->vec + 6 * nx;
    s->rescaled = s->tmp + 4 * nx;
    s->f_complex = s->cplx + band;
    s->work_complex = s->f_complex + nx;
    for (sl_int k = 0; k < 18 * nx; k++) s->Z0[k] = 0.0;
    return 1;
}

/* The method's work (si_free frees it), or NULL if it could not be allocated. */
SC_FN struct si_work *si_create(int method, const sl_int *order) {
    struct si_work *s = (struct si_work *)malloc(sizeof(struct si_work));
    if (s == NULL) return NULL;
    s->order = NULL;
    if (!si_setup(s, method, order)) {
        si_free(s);
        return NULL;
    }
    return s;
}

/* The method's start after the initial step (the begin hooks): the Newton tolerance,
   the Jacobian at the start; Radau no step history, BDF the differences of order 1. */
SC_FN int si_begin(struct si_work *s, double t, const double *y, const double *f,
                   double h_abs, const double *p, double *z, double rtol, sl_int *counts,
                   double *end) {
    s->newton_tol = sc_max(10 * SI_EPS / rtol, sc_min(0.03, pow(rtol, 0.5)));
    int status = si_jacobian(s, t, y, p, z, counts, s->rescaled);
    if (status != SC_SUCCESS) {
        sl_copy(end, y);
        return status;
    }
    s->factored = 0;
    if (s->method == SL_RADAU) {
        sl_copy(SI_ROW(s, SI_F), f);
        s->current_jac = 1;
        s->have_dense = 0;
        s->h_abs_old = -1.0;
        s->error_norm_old = -1.0;
        s->t_old = t;
        s->h_dense = 0.0;
        return SC_SUCCESS;
    }
    sl_copy(s->D, y);
    for (sl_int i = 0; i < s->n; i++) s->D[s->n + i] = f[i] * h_abs;
    s->bdf_order = 1;
    s->n_equal = 0;
    return SC_SUCCESS;
}

SC_FN int si_step(struct si_work *s, double t, const double *y, double h_proposed,
                  double *h_abs, double min_step, double limit, const double *p, double *z,
                  double rtol, const double *atol, sl_int *counts, double *y_new,
                  double *end, double *t_new, double *h, double *t_fail) {
    if (s->method == SL_RADAU)
        return si_step_radau(s, t, y, h_proposed, h_abs, min_step, limit, p, z, rtol, atol,
                             counts, y_new, end, t_new, h, t_fail);
    return si_step_bdf(s, t, y, h_proposed, h_abs, min_step, limit, p, z, rtol, atol,
                       counts, y_new, end, t_new, h, t_fail);
}

SC_FN void si_dense(const struct si_work *s, double t, double h, const double *y, double at,
                    double *out) {
    if (s->method == SL_RADAU) si_radau_dense(s->Q, y, (at - t) / h, out);
    else si_bdf_dense(s, at, out);
}
