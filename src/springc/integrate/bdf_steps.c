/* BDF in C (integrate.bdf_steps' hooks, operation for operation): the differences'
   rescaling, the Newton iteration of I - c J, the order and step-size selection, the
   interpolating polynomial. After implicit_core.c and radau_steps.c (see there). */

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

