/* Reading the reference file written by c_job_reference (C99, shared by the host checker and
 * the simavr harness). Format: see c_job_reference.cpp. */
#ifndef ONESHOT_C_JOB_REFERENCE_FILE_H
#define ONESHOT_C_JOB_REFERENCE_FILE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REF_MAX_STATES 16
#define REF_MAX_VARIANTS 8

/* One job: inputs and the C++ core's outputs (raw mantissas or IEEE bit patterns). */
typedef struct {
  long tau_us;
  int adc, setpoint;
  int pwm, status, saturated;
  long long x[REF_MAX_STATES], k[REF_MAX_STATES], u;
} ref_job_t;

/* The jobs of one variant. */
typedef struct {
  char name[32];
  int pwm0;
  int count;
  ref_job_t *jobs;
} ref_variant_t;

/* The whole file. */
typedef struct {
  int states;
  int variant_count;
  ref_variant_t variants[REF_MAX_VARIANTS];
} ref_file_t;

/* Reads `path`; returns 0 on success, prints why and returns -1 otherwise. */
static int ref_read(const char *path, ref_file_t *f) {
  FILE *in = fopen(path, "r");
  char magic[64];
  int version = 0;
  memset(f, 0, sizeof *f);
  if (in == NULL) {
    fprintf(stderr, "%s: cannot read\n", path);
    return -1;
  }
  if (fscanf(in, "%63s %d n %d", magic, &version, &f->states) != 3 || strcmp(magic, "oneshot-c-job-reference") != 0 ||
      version != 1 || f->states < 1 || f->states > REF_MAX_STATES) {
    fprintf(stderr, "%s: not a reference file\n", path);
    fclose(in);
    return -1;
  }
  while (f->variant_count < REF_MAX_VARIANTS) {
    ref_variant_t *v = &f->variants[f->variant_count];
    int j, i;
    if (fscanf(in, " variant %31s %d %d", v->name, &v->count, &v->pwm0) != 3) break;
    if (v->count <= 0) break;
    v->jobs = (ref_job_t *)calloc((size_t)v->count, sizeof(ref_job_t));
    if (v->jobs == NULL) break;
    for (j = 0; j < v->count; ++j) {
      ref_job_t *r = &v->jobs[j];
      int ok = fscanf(in, " %ld %d %d | %d %d %d", &r->tau_us, &r->adc, &r->setpoint, &r->pwm, &r->status,
                      &r->saturated) == 6;
      for (i = 0; ok && i < f->states; ++i) ok = fscanf(in, " %lld", &r->x[i]) == 1;
      for (i = 0; ok && i < f->states; ++i) ok = fscanf(in, " %lld", &r->k[i]) == 1;
      ok = ok && fscanf(in, " %lld", &r->u) == 1;
      if (!ok) {
        fprintf(stderr, "%s: variant %s: job %d unreadable\n", path, v->name, j);
        fclose(in);
        return -1;
      }
    }
    ++f->variant_count;
  }
  fclose(in);
  if (f->variant_count == 0) {
    fprintf(stderr, "%s: no variant\n", path);
    return -1;
  }
  return 0;
}

#endif
