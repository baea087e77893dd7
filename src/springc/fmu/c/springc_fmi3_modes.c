/* springc: the FMI 3.0 functions of the event, continuous-time and step modes, and
 * the optional functions this FMU declares it lacks (they return fmi3Error). */
#include <math.h>
#include <string.h>

#include "springc_fmi3_api.h"

static fmi3Status unsupported(fmi3Instance instance, const char *what) {
    if (instance) fmi3_log(INST, SMI_ERROR, what);
    return fmi3Error;
}

FMI3_Export fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance,
                                                           fmi3ValueReference valueReference,
                                                           size_t *nDependencies) {
    (void)valueReference; (void)nDependencies;
    return unsupported(instance, "variable dependencies are in modelDescription.xml only");
}

FMI3_Export fmi3Status fmi3GetVariableDependencies(
    fmi3Instance instance, fmi3ValueReference dependent, size_t elementIndicesOfDependent[],
    fmi3ValueReference independents[], size_t elementIndicesOfIndependents[],
    fmi3DependencyKind dependencyKinds[], size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents;
    (void)elementIndicesOfIndependents; (void)dependencyKinds; (void)nDependencies;
    return unsupported(instance, "variable dependencies are in modelDescription.xml only");
}

FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    (void)FMUState;
    return unsupported(instance, "canGetAndSetFMUState is false");
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    (void)FMUState;
    return unsupported(instance, "canGetAndSetFMUState is false");
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    (void)FMUState;
    return unsupported(instance, "canGetAndSetFMUState is false");
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance,
                                                  fmi3FMUState FMUState, size_t *size) {
    (void)FMUState; (void)size;
    return unsupported(instance, "canSerializeFMUState is false");
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                             fmi3Byte serializedState[], size_t size) {
    (void)FMUState; (void)serializedState; (void)size;
    return unsupported(instance, "canSerializeFMUState is false");
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance instance,
                                               const fmi3Byte serializedState[], size_t size,
                                               fmi3FMUState *FMUState) {
    (void)serializedState; (void)size; (void)FMUState;
    return unsupported(instance, "canSerializeFMUState is false");
}

#define SPRINGC_NO_DERIVATIVE(NAME)                                                       \
    FMI3_Export fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference unknowns[],\
                                size_t nUnknowns, const fmi3ValueReference knowns[],      \
                                size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,   \
                                fmi3Float64 sensitivity[], size_t nSensitivity) {         \
        (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed;         \
        (void)nSeed; (void)sensitivity; (void)nSensitivity;                               \
        return unsupported(instance, "providesAdjointDerivatives is false");               \
    }

SPRINGC_NO_DERIVATIVE(fmi3GetAdjointDerivative)

FMI3_Export fmi3Status fmi3GetDirectionalDerivative(
    fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    if (nSeed != nKnowns || nSensitivity != nUnknowns) return fmi3Error;
    return (fmi3Status)smi_directional(INST, unknowns, nUnknowns, knowns, nKnowns, seed,
                                       sensitivity);
}

FMI3_Export fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return unsupported(instance, "the FMU has no structural parameters");
}

FMI3_Export fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return unsupported(instance, "the FMU has no structural parameters");
}

#define SPRINGC_NO_CLOCK(NAME, ...)                                                       \
    FMI3_Export fmi3Status NAME(fmi3Instance instance,                                    \
                                const fmi3ValueReference valueReferences[],               \
                                size_t nValueReferences, __VA_ARGS__) {                   \
        (void)valueReferences;                                                            \
        return nValueReferences ? unsupported(instance, "the FMU has no clocks") : fmi3OK;\
    }

SPRINGC_NO_CLOCK(fmi3GetIntervalDecimal, fmi3Float64 intervals[],
                 fmi3IntervalQualifier qualifiers[])
SPRINGC_NO_CLOCK(fmi3GetIntervalFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                 fmi3IntervalQualifier qualifiers[])
SPRINGC_NO_CLOCK(fmi3GetShiftDecimal, fmi3Float64 shifts[])
SPRINGC_NO_CLOCK(fmi3GetShiftFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
SPRINGC_NO_CLOCK(fmi3SetIntervalDecimal, const fmi3Float64 intervals[])
SPRINGC_NO_CLOCK(fmi3SetIntervalFraction, const fmi3UInt64 counters[],
                 const fmi3UInt64 resolutions[])
SPRINGC_NO_CLOCK(fmi3SetShiftDecimal, const fmi3Float64 shifts[])
SPRINGC_NO_CLOCK(fmi3SetShiftFraction, const fmi3UInt64 counters[],
                 const fmi3UInt64 resolutions[])

FMI3_Export fmi3Status fmi3ActivateModelPartition(fmi3Instance instance,
                                                  fmi3ValueReference clockReference,
                                                  fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return unsupported(instance, "this FMU does not support Scheduled Execution");
}

FMI3_Export fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return (fmi3Status)smi_refresh(INST);
}

FMI3_Export fmi3Status fmi3UpdateDiscreteStates(
    fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
    fmi3Float64 *nextEventTime) {
    int changed = 0, defined = 0;
    double next = 0.0;
    int status = smi_event_iteration(INST, &changed, &defined, &next);
    *discreteStatesNeedUpdate = false; /* the iteration ran to its fixed point */
    *terminateSimulation = INST->terminated_by_model != 0;
    *nominalsOfContinuousStatesChanged = false;
    *valuesOfContinuousStatesChanged = changed != 0;
    *nextEventTimeDefined = defined != 0;
    *nextEventTime = defined ? next : 0.0;
    return (fmi3Status)status;
}

FMI3_Export fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    INST->mode = SMI_CONTINUOUS;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                                   fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi3Boolean *enterEventMode,
                                                   fmi3Boolean *terminateSimulation) {
    int event = 0, status;
    (void)noSetFMUStatePriorToCurrentPoint;
    status = smi_completed_step(INST, &event);
    *enterEventMode = event != 0;
    *terminateSimulation = false;
    return (fmi3Status)status;
}

FMI3_Export fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    smi_set_time(INST, time);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetContinuousStates(fmi3Instance instance,
                                               const fmi3Float64 continuousStates[],
                                               size_t nContinuousStates) {
    if (nContinuousStates != (size_t)sm_nx) return fmi3Error;
    smi_set_states(INST, continuousStates);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance,
                                                         fmi3Float64 derivatives[],
                                                         size_t nContinuousStates) {
    int status;
    if (nContinuousStates != (size_t)sm_nx) return fmi3Error;
    status = smi_refresh(INST);
    if (status == SMI_OK && sm_nx > 0)
        memcpy(derivatives, INST->dx, sizeof(double) * (size_t)sm_nx);
    return (fmi3Status)status;
}

FMI3_Export fmi3Status fmi3GetEventIndicators(fmi3Instance instance,
                                              fmi3Float64 eventIndicators[],
                                              size_t nEventIndicators) {
    int status;
    if (nEventIndicators != (size_t)sm_ng) return fmi3Error;
    status = smi_refresh(INST);
    if (status == SMI_OK && sm_ng > 0
        && smi_crossings(INST, INST->v[0], INST->x, eventIndicators) != 0)
        status = SMI_DISCARD;
    return (fmi3Status)status;
}

FMI3_Export fmi3Status fmi3GetContinuousStates(fmi3Instance instance,
                                               fmi3Float64 continuousStates[],
                                               size_t nContinuousStates) {
    if (nContinuousStates != (size_t)sm_nx) return fmi3Error;
    if (sm_nx > 0) memcpy(continuousStates, INST->x, sizeof(double) * (size_t)sm_nx);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance,
                                                         fmi3Float64 nominals[],
                                                         size_t nContinuousStates) {
    (void)instance;
    if (nContinuousStates != (size_t)sm_nx) return fmi3Error;
    if (sm_nx > 0) memcpy(nominals, sm_nominals, sizeof(double) * (size_t)sm_nx);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance,
                                                      size_t *nEventIndicators) {
    (void)instance;
    *nEventIndicators = (size_t)sm_ng;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance,
                                                       size_t *nContinuousStates) {
    (void)instance;
    *nContinuousStates = (size_t)sm_nx;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    INST->mode = SMI_STEP;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance,
                                                const fmi3ValueReference valueReferences[],
                                                size_t nValueReferences, const fmi3Int32 orders[],
                                                fmi3Float64 values[], size_t nValues) {
    (void)valueReferences; (void)orders; (void)values; (void)nValues;
    return nValueReferences ? unsupported(instance, "maxOutputDerivativeOrder is 0") : fmi3OK;
}

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance,
                                  fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize,
                                  fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded,
                                  fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                                  fmi3Float64 *lastSuccessfulTime) {
    int terminate = 0;
    double last = currentCommunicationPoint;
    int status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (fabs(currentCommunicationPoint - INST->v[0]) > 1e-9 * (1.0 + fabs(INST->v[0]))) {
        fmi3_log(INST, SMI_ERROR, "doStep: currentCommunicationPoint is not the FMU's time");
        return fmi3Error;
    }
    status = smi_do_step(INST, currentCommunicationPoint, communicationStepSize, &terminate,
                         &last);
    *eventHandlingNeeded = false;
    *terminateSimulation = terminate != 0;
    *earlyReturn = false;
    *lastSuccessfulTime = last;
    return (fmi3Status)status;
}
