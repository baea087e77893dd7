/* springc: what the FMU wrapper calls of a model. springc_glue.c (written per model by
 * springc) includes the model's generated C code (model.c, see the cmodel interface)
 * and defines these names around it.
 *
 * Arrays: x continuous states, dx their derivatives, p parameters, w the observed
 * (algebraic and discrete) variables, z the model's working values (Newton warm
 * starts and the held event values), g the zero-crossing functions. Functions return
 * 0 on success; k > 0 where the torn nonlinear system k-1 did not converge. */
#ifndef SPRINGC_GLUE_H
#define SPRINGC_GLUE_H

extern const int sm_nx;            /* continuous states */
extern const int sm_np;            /* parameters */
extern const int sm_nw;            /* observed variables */
extern const int sm_nz;            /* working values (z) */
extern const int sm_ng;            /* zero-crossing functions */
extern const int sm_z_initial;     /* the slot of initial() in z, -1: no events */
extern const int sm_z_terminate;   /* the slot of terminate()'s flag in z, -1: none */
extern const int sm_after_initial; /* an event right after the initial one */
extern const int sm_has_x_initial; /* sm_x_initial holds springc's initial values */
extern const double sm_nominals[]; /* nominal value of each state (at least one entry) */
extern const double sm_x_initial[];/* consistent initial states at the default parameters */
extern const int sm_z_relations;  /* the first held relation value in z, -1: none */
extern const unsigned char sm_true_below[]; /* relation k holds for g[k] < 0 (<, <=) */
extern const int sm_has_jacobian; /* sm_jacobian computes d(dx)/dx */
extern const int sm_njac;          /* its non-zeros */
extern const double sm_tolerance; /* Co-Simulation's tolerance where none is given */
extern const char *const sm_token; /* the instantiation token of modelDescription.xml */

void sm_parameters(double *p, const int *given);
int sm_start(const double *p, double *x, double *z);
int sm_rhs(double t, const double *x, const double *p, double *z, double *dx);
int sm_observed(double t, const double *x, const double *p, double *z, double *w);
int sm_crossings(double t, const double *x, const double *p, double *z, double *g);
double sm_next_time_event(double t, const double *x, const double *p, double *z);
int sm_event_update(double t, double *x, const double *p, double *z);
void sm_jacobian_pattern(int *rows, int *cols);
int sm_jacobian(double t, const double *x, const double *p, double *z, double *jv);

#endif
