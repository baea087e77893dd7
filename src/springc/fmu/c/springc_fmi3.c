/* springc: the FMI 3.0 functions (Model Exchange and Co-Simulation) around one
 * instance of springc_fmu.c. Values of every type are held as doubles; Int32 and
 * Boolean variables convert on the way in and out. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "springc_fmi3.h"
#include "springc_fmu.h"

#include "springc_fmi3_api.h"

void fmi3_log(SmInstance *inst, int status, const char *message) {
    Fmi3Api *api = API(inst);
    if (api && api->log && (api->logging || status >= SMI_DISCARD))
        api->log(api->environment, (fmi3Status)status,
                 status >= SMI_ERROR ? "logStatusError" : "logEvents", message);
}

static fmi3Instance instantiate(fmi3String token, int cosimulation, fmi3String name,
                                fmi3Boolean loggingOn, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback log) {
    Fmi3Api *api;
    SmInstance *inst;
    if (token && strcmp(token, sm_token) != 0) {
        if (log) log(environment, fmi3Error, "logStatusError",
                     "the instantiation token does not match modelDescription.xml");
        return NULL;
    }
    api = (Fmi3Api *)calloc(1, sizeof(Fmi3Api));
    if (!api) return NULL;
    api->log = log;
    api->environment = environment;
    api->logging = loggingOn;
    inst = smi_new(name, cosimulation, fmi3_log, api);
    if (!inst) free(api);
    return inst;
}

FMI3_Export const char *fmi3GetVersion(void) { return "3.0"; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn,
                                           size_t nCategories, const fmi3String categories[]) {
    (void)nCategories;
    (void)categories;
    API(INST)->logging = loggingOn;
    return fmi3OK;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage) {
    (void)resourcePath;
    (void)visible;
    return instantiate(instantiationToken, 0, instanceName, loggingOn, instanceEnvironment,
                       logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath;
    (void)visible;
    (void)eventModeUsed; /* events are handled inside doStep (hasEventMode="false") */
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    return instantiate(instantiationToken, 1, instanceName, loggingOn, instanceEnvironment,
                       logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn; (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                               "this FMU does not support Scheduled Execution");
    return NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance) {
    if (!instance) return;
    free(INST->api);
    smi_free(INST);
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance instance,
                                                   fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance, fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined,
                                                   fmi3Float64 stopTime) {
    return (fmi3Status)smi_enter_initialization(INST, toleranceDefined, tolerance, startTime,
                                                stopTimeDefined, stopTime);
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    return (fmi3Status)smi_exit_initialization(INST);
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    INST->mode = SMI_EVENT;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance instance) {
    INST->mode = SMI_TERMINATED;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance instance) {
    smi_reset(INST);
    return fmi3OK;
}

fmi3Status unknown_reference(SmInstance *inst, fmi3ValueReference vr) {
    (void)vr;
    fmi3_log(inst, SMI_ERROR, "a value reference is unknown or cannot be accessed now");
    return fmi3Error;
}

/* Get and Set by value reference: one per type, through doubles */
#define SPRINGC_GETTER(NAME, TYPE, CONVERT)                                               \
    FMI3_Export fmi3Status NAME(fmi3Instance instance,                                    \
                                const fmi3ValueReference valueReferences[],               \
                                size_t nValueReferences, TYPE values[], size_t nValues) { \
        size_t i;                                                                         \
        if (nValues < nValueReferences) return fmi3Error;                                 \
        for (i = 0; i < nValueReferences; ++i) {                                          \
            double *slot = smi_slot(INST, valueReferences[i], 0);                         \
            if (!slot) return unknown_reference(INST, valueReferences[i]);                \
            values[i] = (TYPE)(CONVERT(*slot));                                           \
        }                                                                                 \
        return fmi3OK;                                                                    \
    }

#define SPRINGC_SETTER(NAME, TYPE)                                                        \
    FMI3_Export fmi3Status NAME(fmi3Instance instance,                                    \
                                const fmi3ValueReference valueReferences[],               \
                                size_t nValueReferences, const TYPE values[],             \
                                size_t nValues) {                                         \
        size_t i;                                                                         \
        if (nValues < nValueReferences) return fmi3Error;                                 \
        for (i = 0; i < nValueReferences; ++i) {                                          \
            double *slot = smi_slot(INST, valueReferences[i], 1);                         \
            if (!slot) return unknown_reference(INST, valueReferences[i]);                \
            *slot = (double)values[i];                                                    \
        }                                                                                 \
        return fmi3OK;                                                                    \
    }

#define AS_IS(v) (v)
#define ROUNDED(v) floor((v) + 0.5)
#define TRUTH(v) ((v) != 0.0)

SPRINGC_GETTER(fmi3GetFloat64, fmi3Float64, AS_IS)
SPRINGC_GETTER(fmi3GetFloat32, fmi3Float32, AS_IS)
SPRINGC_GETTER(fmi3GetInt32, fmi3Int32, ROUNDED)
SPRINGC_GETTER(fmi3GetBoolean, fmi3Boolean, TRUTH)
SPRINGC_GETTER(fmi3GetInt8, fmi3Int8, ROUNDED)
SPRINGC_GETTER(fmi3GetUInt8, fmi3UInt8, ROUNDED)
SPRINGC_GETTER(fmi3GetInt16, fmi3Int16, ROUNDED)
SPRINGC_GETTER(fmi3GetUInt16, fmi3UInt16, ROUNDED)
SPRINGC_GETTER(fmi3GetUInt32, fmi3UInt32, ROUNDED)
SPRINGC_GETTER(fmi3GetInt64, fmi3Int64, ROUNDED)
SPRINGC_GETTER(fmi3GetUInt64, fmi3UInt64, ROUNDED)
SPRINGC_SETTER(fmi3SetFloat64, fmi3Float64)
SPRINGC_SETTER(fmi3SetFloat32, fmi3Float32)
SPRINGC_SETTER(fmi3SetInt32, fmi3Int32)
SPRINGC_SETTER(fmi3SetBoolean, fmi3Boolean)
SPRINGC_SETTER(fmi3SetInt8, fmi3Int8)
SPRINGC_SETTER(fmi3SetUInt8, fmi3UInt8)
SPRINGC_SETTER(fmi3SetInt16, fmi3Int16)
SPRINGC_SETTER(fmi3SetUInt16, fmi3UInt16)
SPRINGC_SETTER(fmi3SetUInt32, fmi3UInt32)
SPRINGC_SETTER(fmi3SetInt64, fmi3Int64)
SPRINGC_SETTER(fmi3SetUInt64, fmi3UInt64)

/* the FMU has no String, Binary or Clock variables */
FMI3_Export fmi3Status fmi3GetString(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3String values[],
                                     size_t nValues) {
    (void)valueReferences; (void)values; (void)nValues;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}

FMI3_Export fmi3Status fmi3SetString(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3String values[],
                                     size_t nValues) {
    (void)valueReferences; (void)values; (void)nValues;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, size_t valueSizes[],
                                     fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}

FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const size_t valueSizes[],
                                     const fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}

FMI3_Export fmi3Status fmi3GetClock(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}

FMI3_Export fmi3Status fmi3SetClock(fmi3Instance instance,
                                    const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences ? unknown_reference(INST, 0) : fmi3OK;
}
