/* Radau IIA in C (integrate.radau_steps' hooks, operation for operation): the Newton
   matrices, the simplified Newton iteration of the collocation system, Gustafsson's
   controller, the collocation polynomial. After implicit_core.c (see there). */

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

