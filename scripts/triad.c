/* STREAM-like triad a[i] = b[i] + s c[i] on 3 x 40 MB (one thread): the memory bandwidth one core
   reaches, the limit of a sparse mat-vec. Prints the best of 10 repetitions in GB/s, counting
   24 bytes per element (two loads, one store; write-allocate not counted, as STREAM does).
   Built and run by scripts/bench_solvers.py. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(void) {
  const size_t n = 5000000;
  double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
  if (!a || !b || !c) return 1;
  for (size_t i = 0; i < n; i++) { a[i] = 0.0; b[i] = 1.0; c[i] = 2.0; }
  double best = 1e30;
  for (int r = 0; r < 10; r++) {
    double t0 = now();
    for (size_t i = 0; i < n; i++) a[i] = b[i] + 3.0 * c[i];
    double t = now() - t0;
    if (t < best) best = t;
  }
  double check = 0.0;
  for (size_t i = 0; i < n; i += 4096) check += a[i];
  printf("%.3f %g\n", 24.0 * n / best / 1e9, check);
  free(a); free(b); free(c);
  return 0;
}
