#ifndef FOREIGNLIB_H
#define FOREIGNLIB_H

double foreignlib_stats(const double *u, int n, int k, int neg, double *scaled,
                        int *count);
void foreignlib_transpose(const double *a, int rows, int columns, double *t);
double foreignlib_root(double x);
double cube(double x);

#endif
