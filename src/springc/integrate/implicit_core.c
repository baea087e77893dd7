/* springc's implicit methods in C, Radau IIA (order 5) and BDF (orders 1-5): the hooks
   of the single-run loop (single_loop.c) for stiff models. This file holds what they
   share (the work, the banded LU, the Jacobian, the setup and the hooks' dispatch);
   radau_steps.c and bdf_steps.c the methods.

   springc.integrate.native_loop puts this text after single_loop.c and the methods'
   constants (SI_RADAU_*, SI_BDF_*: radau_tableau's and bdf_tableau's values printed
   by Python), then radau_steps.c and bdf_steps.c. The arithmetic is that of the numba hooks, operation for
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
   model printed without one (over codegen.c_model.JACOBIAN_LIMIT non-zeros) gets
   forward differences here (each evaluation counted as a right-hand-side evaluation;
   the numba loops always have the analytic one): grouped by the pattern of the
   generated module's Jacobian where native_loop.loop_text printed it (SI_PATTERN_NNZ,
   si_pattern_indptr, si_pattern_indices: CSC), columns that share no row perturbed in
   one evaluation (a greedy colouring in column order; a chain's banded pattern needs a
   handful of evaluations, not one per state), else dense (one column per evaluation,
   n*n non-zeros).
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
    sl_int n_colours, *colour_start, *colour_cols; /* forward differences' groups */
    double *J, *real, *D, *Z0, *Z, *Q, *W, *F, *dW, *vec, *tmp, *rescaled;
    si_complex *cplx, *f_complex, *work_complex;
    double newton_tol, h_abs_old, error_norm_old, t_old, h_dense, t_new, h_now;
    int current_jac, factored, have_dense, bdf_order, n_equal;
};

/* The rows of the work vectors (vec, n each): Radau's state at the last step's start,
   error weights, error estimate, its collocation part, a work vector, the derivative
   at the step's start (radau_steps' Y_OLD ... F); BDF's are in bdf_steps.c. */
#define SI_Y_OLD 0
#define SI_SCALE 1
#define SI_ERROR 2
#define SI_ERROR_Z 3
#define SI_STAGE 4
#define SI_F 5
#define SI_ROW(s, r) ((s)->vec + (r) * (s)->n)

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

#if !SPRINGC_HAS_JACOBIAN
/* The differenced Jacobian's pattern (CSC): where column j starts, the row of the
   non-zero k. */
#ifdef SI_PATTERN_NNZ
#define SI_NNZ ((sl_int)SI_PATTERN_NNZ)
SC_FN sl_int si_column_start(sl_int j) { return si_pattern_indptr[j]; }
SC_FN sl_int si_row_of(sl_int k) { return si_pattern_indices[k]; }
#else
#define SI_NNZ ((sl_int)SC_NX * SC_NX)
SC_FN sl_int si_column_start(sl_int j) { return j * SC_NX; }
SC_FN sl_int si_row_of(sl_int k) { return k % SC_NX; }
#endif

/* The forward differences' groups (s->colour_start, s->colour_cols: the columns
   colour by colour, each in column order): column j takes the first colour that no
   earlier column sharing a row with it has (greedy, in column order; the dense
   pattern: one column per colour). 0 where the work could not be allocated. */
SC_FN int si_colour(struct si_work *s) {
    sl_int n = s->n, nnz = s->nnz;
    sl_int *work = (sl_int *)calloc((size_t)(4 * n + nnz + 4), sizeof(sl_int));
    if (work == NULL) return 0;
    sl_int *colour = work, *mark = colour + n + 1;
    s->n_colours = 0;
#ifdef SI_PATTERN_NNZ
    sl_int *row_start = mark + n + 1, *row_cols = row_start + n + 1;
    for (sl_int k = 0; k < nnz; k++) row_start[si_row_of(k) + 1] += 1;
    for (sl_int i = 0; i < n; i++) row_start[i + 1] += row_start[i];
    for (sl_int i = 0; i < n; i++) mark[i] = row_start[i];  /* each row's next slot */
    for (sl_int j = 0; j < n; j++)
        for (sl_int k = si_column_start(j); k < si_column_start(j + 1); k++)
            row_cols[mark[si_row_of(k)]++] = j;
    for (sl_int i = 0; i < n; i++) mark[i] = -1;
    for (sl_int j = 0; j < n; j++) {
        for (sl_int k = si_column_start(j); k < si_column_start(j + 1); k++) {
            sl_int r = si_row_of(k);
            for (sl_int q = row_start[r]; q < row_start[r + 1] && row_cols[q] < j; q++)
                mark[colour[row_cols[q]]] = j;
        }
        sl_int c = 0;
        while (c < s->n_colours && mark[c] == j) c++;
        colour[j] = c;
        if (c == s->n_colours) s->n_colours += 1;
    }
#else
    for (sl_int j = 0; j < n; j++) colour[j] = j;
    s->n_colours = n;
#endif
    for (sl_int c = 0; c <= s->n_colours; c++) s->colour_start[c] = 0;
    for (sl_int j = 0; j < n; j++) s->colour_start[colour[j] + 1] += 1;
    for (sl_int c = 0; c < s->n_colours; c++) s->colour_start[c + 1] += s->colour_start[c];
    for (sl_int c = 0; c < s->n_colours; c++) mark[c] = s->colour_start[c];
    for (sl_int j = 0; j < n; j++) s->colour_cols[mark[colour[j]]++] = j;
    free(work);
    return 1;
}
#endif

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
    for (sl_int c = 0; c < s->n_colours && !sc_flagged(z); c++) {
        sl_copy(x, y);
        for (sl_int q = s->colour_start[c]; q < s->colour_start[c + 1]; q++) {
            sl_int j = s->colour_cols[q];
            x[j] = y[j] + sqrt(SI_EPS) * sc_max(1.0, fabs(y[j]));
        }
        si_rhs(t, x, p, z, f1);
        counts[SL_RHS_CALLS] += 1;
        for (sl_int q = s->colour_start[c]; q < s->colour_start[c + 1]; q++) {
            sl_int j = s->colour_cols[q];
            double h = x[j] - y[j];
            for (sl_int k = si_column_start(j); k < si_column_start(j + 1); k++)
                s->J[k] = (f1[si_row_of(k)] - f0[si_row_of(k)]) / h;
        }
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

/* The methods' steps and dense outputs (radau_steps.c, bdf_steps.c, after this file's
   text). */
struct si_work;
SC_FN int si_step_radau(struct si_work *s, double t, const double *y, double h_proposed,
                        double *h_abs, double min_step, double limit, const double *p,
                        double *z, double rtol, const double *atol, sl_int *counts,
                        double *y_new, double *end, double *t_new, double *h,
                        double *t_fail);
SC_FN int si_step_bdf(struct si_work *s, double t, const double *y, double h_proposed,
                      double *h_abs, double min_step, double limit, const double *p,
                      double *z, double rtol, const double *atol, sl_int *counts,
                      double *y_new, double *end, double *t_new, double *h, double *t_fail);
SC_FN void si_radau_dense(const double *Q, const double *y_old, double x, double *out);
SC_FN void si_bdf_dense(const struct si_work *s, double at, double *out);

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
    for (sl_int j = 0; j < n; j++)
        for (sl_int k = si_column_start(j); k < si_column_start(j + 1); k++) {
            rows[k] = (int)si_row_of(k);
            cols[k] = (int)j;
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
    sl_int nnz = SI_NNZ;
#endif
    s->method = method;
    s->n = n;
    s->nnz = nnz;
    s->n_colours = 0;
    s->order = (sl_int *)malloc((size_t)(9 * nx + nnz + 2) * sizeof(sl_int));
    s->J = NULL;
    s->cplx = NULL;
    if (s->order == NULL) return 0;
    s->positions = s->order + nx;
    s->diagonal = s->positions + nnz + 1;
    s->pivots = s->diagonal + nx;
    s->pivots2 = s->pivots + nx;
    sl_int *where = s->pivots2 + nx;
    s->colour_start = where + nx;
    s->colour_cols = s->colour_start + nx + 1;
#if !SPRINGC_HAS_JACOBIAN
    if (!si_colour(s)) return 0;
#endif
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
