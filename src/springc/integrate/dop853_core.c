/* DOP853's step arithmetic in C, one copy for springc's C kernels: the batched ensemble
   (ensemble_dop853.c) and the single-run loop of the compiled engine (single_loop.c).

   Before this text come the model's sizes (SC_NX, SC_NXS), the tableau's weighted sums
   written out (sc_a_row, sc_b_sum, sc_e5_sum, sc_e3_sum, sc_d_row; see
   springc.integrate.native_ensemble.prelude), the status codes (SC_SUCCESS ...) and
   the model's functions. The arithmetic is springc.integrate.dop853_steps' with
   plain-loop sums, every operation in the same order (compiled without contraction
   into fused multiply-adds), so that the results equal the numba loop's. */
#ifdef SC_CUDA
#define SC_FN static __device__
#else
#define SC_FN static
#endif

#define SC_STAGES 12
#define SC_EXTENDED 16
#define SC_ROWS 7
#define SC_NZS (SPRINGC_N_Z > 0 ? SPRINGC_N_Z : 1)

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

/* the state of stage s: y + (sum_j A[s, j] K[j]) * h */
SC_FN void sc_stage(const double *y, const double *K, int s, double h, double *sums,
                    double *out) {
    sc_a_row(s, K, sums);
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
    sc_e5_sum(K, err5);
    sc_e3_sum(K, err3);
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
        sc_d_row(r, K, sums);
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

