/* springc: what the two FMI 3.0 translation units share (not part of the FMI API). */
#ifndef SPRINGC_FMI3_API_H
#define SPRINGC_FMI3_API_H

#include "springc_fmi3.h"
#include "springc_fmu.h"


typedef struct {
    fmi3LogMessageCallback log;
    fmi3InstanceEnvironment environment;
    int logging;
} Fmi3Api;

#define INST ((SmInstance *)instance)
#define API(inst) ((Fmi3Api *)(inst)->api)

void fmi3_log(SmInstance *inst, int status, const char *message);
fmi3Status unknown_reference(SmInstance *inst, fmi3ValueReference vr);

#endif
