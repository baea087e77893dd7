/* springc: one FMU instance around a model's generated code (springc_glue.h),
 * shared by the FMI 3.0 and FMI 2.0 function sets: the values by value reference,
 * initialization, the event iteration, and Co-Simulation's embedded solver (explicit
 * Runge-Kutta, Dormand-Prince 5(4), with error control, time events and state events
 * located by bisection inside doStep). */
#ifndef SPRINGC_FMU_H
#define SPRINGC_FMU_H

#include <stddef.h>

#include "springc_glue.h"

/* value references: 0 time, then states, derivatives, parameters, observed
 * variables, event indicators (the order of modelDescription.xml) */
#define SMI_OK 0
#define SMI_WARNING 1
#define SMI_DISCARD 2
#define SMI_ERROR 3

enum smi_mode { SMI_INSTANTIATED, SMI_INIT, SMI_EVENT, SMI_CONTINUOUS, SMI_STEP,
                SMI_TERMINATED };

typedef struct SmInstance SmInstance;
typedef void (*smi_logger)(SmInstance *inst, int status, const char *message);

struct SmInstance {
    char *name;
    int cosimulation;
    enum smi_mode mode;
    double *v;                /* every value, indexed by value reference */
    int nv;
    double *x, *dx, *p, *w;
    double *z;                /* the model's working values */
    int *given;               /* per value reference: set by the importer */
    double *g, *g_prev;       /* event indicators: now and at the last event/step */
    int dirty;                /* dx and w need computing */
    double start_time, stop_time, tolerance;
    int stop_defined;
    double next_event;        /* the model's next time event, as last asked */
    double h;                 /* Co-Simulation: the step size carried between steps */
    double *work;             /* Co-Simulation: the Runge-Kutta stages */
    int terminated_by_model;
    smi_logger log;
    void *api;                /* the FMI layer's data (callbacks, environment) */
};

SmInstance *smi_new(const char *name, int cosimulation, smi_logger log, void *api);
void smi_free(SmInstance *inst);
void smi_reset(SmInstance *inst);
int smi_refresh(SmInstance *inst);
int smi_crossings(SmInstance *inst, double t, const double *x, double *g);
double *smi_slot(SmInstance *inst, unsigned int vr, int for_writing);
int smi_enter_initialization(SmInstance *inst, int tolerance_defined, double tolerance,
                             double start_time, int stop_defined, double stop_time);
int smi_exit_initialization(SmInstance *inst);
int smi_event_iteration(SmInstance *inst, int *states_changed, int *next_defined,
                        double *next_time);
int smi_completed_step(SmInstance *inst, int *enter_event);
int smi_do_step(SmInstance *inst, double t0, double step, int *terminate,
                double *last_time);
int smi_directional(SmInstance *inst, const unsigned int *unknowns, size_t n_unknowns,
                    const unsigned int *knowns, size_t n_knowns, const double *seed,
                    double *sensitivity);
void smi_set_time(SmInstance *inst, double t);
void smi_set_states(SmInstance *inst, const double *x);

#endif
