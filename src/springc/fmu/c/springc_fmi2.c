/* springc: the FMI 2.0 functions (Model Exchange and Co-Simulation) around one
 * instance of springc_fmu.c. Integer and Boolean values are held as doubles. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "springc_fmi2.h"
#include "springc_fmu.h"

typedef struct {
    fmi2CallbackLogger log;
    fmi2ComponentEnvironment environment;
    int logging;
    double last_time;
    int terminated;
} Fmi2Api;

#define INST ((SmInstance *)c)
#define API2(inst) ((Fmi2Api *)(inst)->api)

static void fmi2_log(SmInstance *inst, int status, const char *message) {
    Fmi2Api *api = API2(inst);
    if (api && api->log && (api->logging || status >= SMI_DISCARD))
        api->log(api->environment, inst->name, (fmi2Status)status,
                 status >= SMI_ERROR ? "logStatusError" : "logEvents", message);
}

static fmi2Status refuse(fmi2Component c, const char *what) {
    if (c) fmi2_log(INST, SMI_ERROR, what);
    return fmi2Error;
}

FMI2_Export const char *fmi2GetTypesPlatform(void) { return "default"; }
FMI2_Export const char *fmi2GetVersion(void) { return "2.0"; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn,
                                           size_t nCategories, const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    API2(INST)->logging = loggingOn;
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                          fmi2String fmuGUID, fmi2String fmuResourceLocation,
                                          const fmi2CallbackFunctions *functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn) {
    Fmi2Api *api;
    SmInstance *inst;
    (void)fmuResourceLocation;
    (void)visible;
    if (fmuGUID && strcmp(fmuGUID, sm_token) != 0) {
        if (functions && functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error,
                              "logStatusError", "the GUID does not match modelDescription.xml");
        return NULL;
    }
    api = (Fmi2Api *)calloc(1, sizeof(Fmi2Api));
    if (!api) return NULL;
    api->log = functions ? functions->logger : NULL;
    api->environment = functions ? functions->componentEnvironment : NULL;
    api->logging = loggingOn;
    inst = smi_new(instanceName, fmuType == fmi2CoSimulation, fmi2_log, api);
    if (!inst) free(api);
    return inst;
}

FMI2_Export void fmi2FreeInstance(fmi2Component c) {
    if (!c) return;
    free(INST->api);
    smi_free(INST);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                           fmi2Real tolerance, fmi2Real startTime,
                                           fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    smi_enter_initialization(INST, toleranceDefined, tolerance, startTime, stopTimeDefined,
                             stopTime);
    INST->mode = SMI_INSTANTIATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    INST->mode = SMI_INIT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    int status = smi_exit_initialization(INST);
    API2(INST)->last_time = INST->v[0];
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component c) {
    INST->mode = SMI_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component c) {
    smi_reset(INST);
    return fmi2OK;
}

static fmi2Status get_values(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                             double *out) {
    size_t i;
    for (i = 0; i < nvr; ++i) {
        double *slot = smi_slot(INST, vr[i], 0);
        if (!slot) return refuse(c, "a value reference is unknown or cannot be read now");
        out[i] = *slot;
    }
    return fmi2OK;
}

static fmi2Status set_value(fmi2Component c, fmi2ValueReference vr, double value) {
    double *slot = smi_slot(INST, vr, 1);
    if (!slot) return refuse(c, "a value reference is unknown or cannot be set now");
    *slot = value;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                   fmi2Real value[]) {
    return get_values(c, vr, nvr, value);
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[],
                                      size_t nvr, fmi2Integer value[]) {
    size_t i;
    for (i = 0; i < nvr; ++i) {
        double v;
        if (get_values(c, vr + i, 1, &v) != fmi2OK) return fmi2Error;
        value[i] = (fmi2Integer)floor(v + 0.5);
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[],
                                      size_t nvr, fmi2Boolean value[]) {
    size_t i;
    for (i = 0; i < nvr; ++i) {
        double v;
        if (get_values(c, vr + i, 1, &v) != fmi2OK) return fmi2Error;
        value[i] = v != 0.0;
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[],
                                     size_t nvr, fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? refuse(c, "the FMU has no String variables") : fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                   const fmi2Real value[]) {
    size_t i;
    for (i = 0; i < nvr; ++i)
        if (set_value(c, vr[i], value[i]) != fmi2OK) return fmi2Error;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[],
                                      size_t nvr, const fmi2Integer value[]) {
    size_t i;
    for (i = 0; i < nvr; ++i)
        if (set_value(c, vr[i], (double)value[i]) != fmi2OK) return fmi2Error;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[],
                                      size_t nvr, const fmi2Boolean value[]) {
    size_t i;
    for (i = 0; i < nvr; ++i)
        if (set_value(c, vr[i], value[i] ? 1.0 : 0.0) != fmi2OK) return fmi2Error;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[],
                                     size_t nvr, const fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? refuse(c, "the FMU has no String variables") : fmi2OK;
}

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)state;
    return refuse(c, "canGetAndSetFMUstate is false");
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    (void)state;
    return refuse(c, "canGetAndSetFMUstate is false");
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)state;
    return refuse(c, "canGetAndSetFMUstate is false");
}

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state,
                                                  size_t *size) {
    (void)state; (void)size;
    return refuse(c, "canSerializeFMUstate is false");
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state,
                                             fmi2Byte serializedState[], size_t size) {
    (void)state; (void)serializedState; (void)size;
    return refuse(c, "canSerializeFMUstate is false");
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c,
                                               const fmi2Byte serializedState[], size_t size,
                                               fmi2FMUstate *state) {
    (void)serializedState; (void)size; (void)state;
    return refuse(c, "canSerializeFMUstate is false");
}

FMI2_Export fmi2Status fmi2GetDirectionalDerivative(
    fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
    const fmi2ValueReference vKnown_ref[], size_t nKnown, const fmi2Real dvKnown[],
    fmi2Real dvUnknown[]) {
    return (fmi2Status)smi_directional(INST, vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                       dvKnown, dvUnknown);
}

/* Model Exchange */

FMI2_Export fmi2Status fmi2EnterEventMode(fmi2Component c) {
    INST->mode = SMI_EVENT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    int changed = 0, defined = 0;
    double next = 0.0;
    int status = smi_event_iteration(INST, &changed, &defined, &next);
    info->newDiscreteStatesNeeded = fmi2False; /* the iteration ran to its fixed point */
    info->terminateSimulation = INST->terminated_by_model != 0;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = changed != 0;
    info->nextEventTimeDefined = defined != 0;
    info->nextEventTime = defined ? next : 0.0;
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    INST->mode = SMI_CONTINUOUS;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CompletedIntegratorStep(fmi2Component c,
                                                   fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi2Boolean *enterEventMode,
                                                   fmi2Boolean *terminateSimulation) {
    int event = 0, status;
    (void)noSetFMUStatePriorToCurrentPoint;
    status = smi_completed_step(INST, &event);
    *enterEventMode = event != 0;
    *terminateSimulation = fmi2False;
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    smi_set_time(INST, time);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[],
                                               size_t nx) {
    if (nx != (size_t)sm_nx) return refuse(c, "wrong number of continuous states");
    smi_set_states(INST, x);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    int status;
    if (nx != (size_t)sm_nx) return refuse(c, "wrong number of continuous states");
    status = smi_refresh(INST);
    if (status == SMI_OK && sm_nx > 0)
        memcpy(derivatives, INST->dx, sizeof(double) * (size_t)sm_nx);
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[],
                                              size_t ni) {
    int status;
    if (ni != (size_t)sm_ng) return refuse(c, "wrong number of event indicators");
    status = smi_refresh(INST);
    if (status == SMI_OK && sm_ng > 0)
        memcpy(eventIndicators, INST->w + sm_nw, sizeof(double) * (size_t)sm_ng);
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    if (nx != (size_t)sm_nx) return refuse(c, "wrong number of continuous states");
    if (sm_nx > 0) memcpy(x, INST->x, sizeof(double) * (size_t)sm_nx);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[],
                                                         size_t nx) {
    if (nx != (size_t)sm_nx) return refuse(c, "wrong number of continuous states");
    if (sm_nx > 0) memcpy(x_nominal, sm_nominals, sizeof(double) * (size_t)sm_nx);
    return fmi2OK;
}

/* Co-Simulation */

FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c,
                                                   const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[],
                                                   const fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    return nvr ? refuse(c, "the FMU has no inputs") : fmi2OK;
}

FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c,
                                                    const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[],
                                                    fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    return nvr ? refuse(c, "maxOutputDerivativeOrder is 0") : fmi2OK;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize,
                                  fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    int terminate = 0, status;
    double last = currentCommunicationPoint;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (fabs(currentCommunicationPoint - INST->v[0]) > 1e-9 * (1.0 + fabs(INST->v[0])))
        return refuse(c, "doStep: currentCommunicationPoint is not the FMU's time");
    status = smi_do_step(INST, currentCommunicationPoint, communicationStepSize, &terminate,
                         &last);
    API2(INST)->last_time = last;
    API2(INST)->terminated = terminate;
    return (fmi2Status)status;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c) {
    return refuse(c, "doStep never returns fmi2Pending");
}

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s,
                                     fmi2Status *value) {
    (void)s; (void)value;
    return refuse(c, "doStep never returns fmi2Pending");
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s,
                                         fmi2Real *value) {
    if (s != fmi2LastSuccessfulTime) return refuse(c, "no such real status");
    *value = API2(INST)->last_time;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s,
                                            fmi2Integer *value) {
    (void)s; (void)value;
    return refuse(c, "no integer status");
}

FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s,
                                            fmi2Boolean *value) {
    if (s != fmi2Terminated) return refuse(c, "no such boolean status");
    *value = API2(INST)->terminated;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s,
                                           fmi2String *value) {
    (void)s; (void)value;
    return refuse(c, "no string status");
}
