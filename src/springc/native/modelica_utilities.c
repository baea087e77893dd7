/* springc's own ModelicaUtilities (Modelica Language Specification 12.9.6), compiled
   into every library of foreign functions springc builds (springc/native/foreign.py).

   ModelicaError and its formatting variants never abort the process: they copy the
   message into springc_error_text and jump back to the wrapper of the call in
   progress (springc_error_jump, set by the wrapper with setjmp), which returns 1;
   springc then raises a located error with the message. Messages and warnings go to
   stderr. Strings allocated for a call are kept in a list and freed by
   springc_release_strings once springc has copied the results. */

#define _XOPEN_SOURCE 700 /* sigaction, SA_NODEFER */

#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SPRINGC_MESSAGE_SIZE 2048

jmp_buf springc_error_jump;
char springc_error_text[SPRINGC_MESSAGE_SIZE];

typedef struct springc_string { struct springc_string *next; } springc_string;
static springc_string *springc_strings = NULL;

const char *springc_error_message(void) { return springc_error_text; }

/* A call that crashes (an invalid memory access, an arithmetic trap...) jumps back to
   the wrapper as a ModelicaError does, instead of ending springc without a word: the
   wrapper installs these handlers for the call (springc_guard_begin) and restores the
   previous ones after it (springc_guard_end). SA_NODEFER: the signal is not left
   blocked by the jump out of the handler. */
#define SPRINGC_CRASH_SIGNALS 4
static const int springc_crash_signal[SPRINGC_CRASH_SIGNALS] = {SIGSEGV, SIGBUS, SIGFPE,
                                                                 SIGILL};
static const char *springc_crash_text[SPRINGC_CRASH_SIGNALS] = {
    "the C code crashed: an invalid memory access (segmentation fault)",
    "the C code crashed: an invalid memory access (bus error)",
    "the C code crashed: an arithmetic exception",
    "the C code crashed: an illegal instruction"};
static struct sigaction springc_previous[SPRINGC_CRASH_SIGNALS];

static void springc_crashed(int sig) {
    const char *text = springc_crash_text[0];
    for (int k = 0; k < SPRINGC_CRASH_SIGNALS; k++) {
        if (springc_crash_signal[k] == sig) {
            text = springc_crash_text[k];
        }
    }
    size_t n = 0;
    while (text[n] != '\0' && n + 1 < SPRINGC_MESSAGE_SIZE) {
        springc_error_text[n] = text[n];
        n++;
    }
    springc_error_text[n] = '\0';
    longjmp(springc_error_jump, 1);
}

void springc_guard_begin(void) {
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = springc_crashed;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_NODEFER;
    for (int k = 0; k < SPRINGC_CRASH_SIGNALS; k++) {
        sigaction(springc_crash_signal[k], &action, &springc_previous[k]);
    }
}

void springc_guard_end(void) {
    for (int k = 0; k < SPRINGC_CRASH_SIGNALS; k++) {
        sigaction(springc_crash_signal[k], &springc_previous[k], NULL);
    }
}

void springc_release_strings(void) {
    while (springc_strings != NULL) {
        springc_string *next = springc_strings->next;
        free(springc_strings);
        springc_strings = next;
    }
}

void ModelicaMessage(const char *string) { fprintf(stderr, "%s", string); }

void ModelicaVFormatMessage(const char *format, va_list args) {
    vfprintf(stderr, format, args);
}

void ModelicaFormatMessage(const char *format, ...) {
    va_list args;
    va_start(args, format);
    ModelicaVFormatMessage(format, args);
    va_end(args);
}

void ModelicaWarning(const char *string) { fprintf(stderr, "warning: %s\n", string); }

void ModelicaVFormatWarning(const char *format, va_list args) {
    fprintf(stderr, "warning: ");
    vfprintf(stderr, format, args);
    fprintf(stderr, "\n");
}

void ModelicaFormatWarning(const char *format, ...) {
    va_list args;
    va_start(args, format);
    ModelicaVFormatWarning(format, args);
    va_end(args);
}

void ModelicaVFormatError(const char *format, va_list args) {
    vsnprintf(springc_error_text, SPRINGC_MESSAGE_SIZE, format, args);
    longjmp(springc_error_jump, 1);
}

void ModelicaFormatError(const char *format, ...) {
    va_list args;
    va_start(args, format);
    ModelicaVFormatError(format, args);
    va_end(args);
}

void ModelicaError(const char *string) { ModelicaFormatError("%s", string); }

char *ModelicaAllocateStringWithErrorReturn(size_t len) {
    springc_string *block = malloc(sizeof(springc_string) + len + 1);
    if (block == NULL) {
        return NULL;
    }
    block->next = springc_strings;
    springc_strings = block;
    char *text = (char *)(block + 1);
    text[len] = '\0';
    return text;
}

char *ModelicaAllocateString(size_t len) {
    char *text = ModelicaAllocateStringWithErrorReturn(len);
    if (text == NULL) {
        ModelicaFormatError("out of memory allocating a string of %lu characters",
                            (unsigned long)len);
    }
    return text;
}

char *ModelicaDuplicateStringWithErrorReturn(const char *str) {
    size_t len = strlen(str);
    char *text = ModelicaAllocateStringWithErrorReturn(len);
    if (text != NULL) {
        memcpy(text, str, len + 1);
    }
    return text;
}

char *ModelicaDuplicateString(const char *str) {
    char *text = ModelicaAllocateString(strlen(str));
    memcpy(text, str, strlen(str) + 1);
    return text;
}
