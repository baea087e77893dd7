/* The library ForeignLib of springc's tests (Library="ForeignLib"). */
#include <math.h>

#include "foreignlib.h"

void ModelicaFormatError(const char *format, ...);

double foreignlib_stats(const double *u, int n, int k, int neg, double *scaled,
                        int *count) {
    double total = 0.0;
    *count = 0;
    for (int i = 0; i < n; i++) {
        total += u[i];
        scaled[i] = (neg ? -k : k) * u[i];
        *count += u[i] > 0.0;
    }
    return total;
}

void foreignlib_transpose(const double *a, int rows, int columns, double *t) {
    for (int i = 0; i < rows; i++) {
        for (int j = 0; j < columns; j++) {
            t[j * rows + i] = a[i * columns + j];
        }
    }
}

double foreignlib_root(double x) {
    if (x < 0.0) {
        ModelicaFormatError("foreignlib_root: x = %g is negative", x);
    }
    return sqrt(x);
}

double cube(double x) {
    return x * x * x;
}
