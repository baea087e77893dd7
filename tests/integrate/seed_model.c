/* The seed (models/SpringMass.mdl) written by hand against the cmodel interface
   (/work/notes/CMODEL_INTERFACE.md): the test fixture of the batched C ensemble. */
#ifndef SPRINGC_FN
#define SPRINGC_FN static
#endif
#define SPRINGC_N_STATES 4
#define SPRINGC_N_PARAMS 11
#define SPRINGC_N_Z 1
#define SPRINGC_Z_FLAG 0
#define SPRINGC_N_OBSERVED 3
#define SPRINGC_N_CROSSINGS 0
#define SPRINGC_N_NEWTON 0
#define SPRINGC_HYBRID 0
#define SPRINGC_INITIAL_CONDITIONS 0

/* p: m, xy[1], xy[2], u[1], u[2], k, l, center[1], center[2], g[1], g[2] */
SPRINGC_FN void springc_parameters(double *p, const int *given) {
    static const double model[11] = {1.0, 1.0, -1.0, 0.0, 0.0, 1e4, 1.0, 0.0, 0.0, 0.0,
                                     -9.81};
    for (int i = 0; i < 11; i++)
        if (given == 0 || !given[i]) p[i] = model[i];
}

SPRINGC_FN int springc_start(const double *p, double *x, double *z) {
    x[0] = p[1]; x[1] = p[2]; x[2] = p[3]; x[3] = p[4];
    z[0] = 0.0;
    return 0;
}

SPRINGC_FN int springc_rhs(double t, const double *x, const double *p, double *z,
                           double *dx) {
    double dir1 = x[0] - p[7], dir2 = x[1] - p[8];
    double len = sqrt(dir1 * dir1 + dir2 * dir2);
    (void)t; (void)z;
    dx[0] = x[2];
    dx[1] = x[3];
    dx[2] = -p[5] * dir1 * (len - p[6]) / len / p[0] + p[9];
    dx[3] = -p[5] * dir2 * (len - p[6]) / len / p[0] + p[10];
    return 0;
}

SPRINGC_FN int springc_observed(double t, const double *x, const double *p, double *z,
                                double *out) {
    (void)t; (void)z;
    out[0] = x[0] - p[7];
    out[1] = x[1] - p[8];
    out[2] = sqrt(out[0] * out[0] + out[1] * out[1]);
    return 0;
}
