/* springc's own ModelicaUtilities (Modelica Language Specification 12.9.6), compiled
   into every library of foreign functions springc builds (springc/native/foreign.py).

   ModelicaError and its formatting variants never abort the process: they copy the
   message into springc_error_text and jump back to the wrapper of the call in
   progress (springc_error_jump, set by the wrapper with setjmp), which returns 1;
   springc then raises a located error with the message. Messages and warnings go to
   stderr. Strings allocated for a call are kept in a list and freed by
   springc_release_strings once springc has copied the results. */

#include <setjmp.h>
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
