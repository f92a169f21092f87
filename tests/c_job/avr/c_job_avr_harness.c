/* Runs c_job_avr_main.c's firmware in simavr (libsimavr) on the reference file: feeds every
 * job's inputs through the mailbox, compares the AVR's outputs with the C++ core's bit for
 * bit, and counts the cycles of each job between the GPIOR0 markers (minus the markers' own).
 * Usage: c_job_avr_harness FIRMWARE.elf MCU REFERENCE_FILE MAX_JOBS_PER_VARIANT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_io.h"

#include "../c_job_reference_file.h"

#define GPIOR0_ADDR 0x3E /* data-space addresses (I/O 0x1E, 0x2A, 0x2B) on the ATmega1284/2560 */
#define GPIOR1_ADDR 0x4A
#define GPIOR2_ADDR 0x4B

static ref_file_t ref;
static int max_jobs;
static uint16_t mailbox;
static int variant = -1, job = -1, last_command = -1, done;
static avr_cycle_count_t window_start, overhead = ~(avr_cycle_count_t)0;
static int first_window = 1;
static struct {
  long jobs, identical;
  avr_cycle_count_t cycles, min, max;
} stats[REF_MAX_VARIANTS];

static int variant_id(const char *name) {
  if (strcmp(name, "fixed_table") == 0) return 0;
  if (strcmp(name, "fixed_nearest") == 0) return 1;
  if (strcmp(name, "float_table") == 0) return 2;
  if (strcmp(name, "float_nearest") == 0) return 3;
  if (strcmp(name, "q15_table") == 0) return 4;
  if (strcmp(name, "q15_nearest") == 0) return 5;
  if (strcmp(name, "float_poly") == 0) return 6;
  return -1;
}

static uint32_t get32(avr_t *avr, int offset) {
  const uint8_t *p = avr->data + mailbox + offset;
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static unsigned get16(avr_t *avr, int offset) {
  const uint8_t *p = avr->data + mailbox + offset;
  return (unsigned)p[0] | (unsigned)p[1] << 8;
}
static void put16(avr_t *avr, int offset, unsigned v) {
  avr->data[mailbox + offset] = (uint8_t)(v & 0xFFu);
  avr->data[mailbox + offset + 1] = (uint8_t)(v >> 8);
}
static void put32(avr_t *avr, int offset, uint32_t v) {
  int i;
  for (i = 0; i < 4; ++i) avr->data[mailbox + offset + i] = (uint8_t)(v >> (8 * i));
}

/* Compares the outputs of the job just run with the reference. */
static void check(avr_t *avr) {
  const ref_variant_t *v = &ref.variants[variant];
  const ref_job_t *e = &v->jobs[job];
  const int n = ref.states;
  const int id = variant_id(v->name);
  const int fixed = id < 2 || id == 4 || id == 5;
  int i, same;
  /* Fixed mantissas come back sign-extended to 32 bits; float bit patterns as they are. */
#define RAW(w) (fixed ? (long long)(int32_t)(w) : (long long)(w))
  same = (int)get16(avr, 10) == e->pwm && avr->data[mailbox + 12] == e->status &&
         avr->data[mailbox + 13] == e->saturated && RAW(get32(avr, 14 + 8 * n)) == e->u;
  for (i = 0; i < n; ++i)
    same = same && RAW(get32(avr, 14 + 4 * i)) == e->x[i] && RAW(get32(avr, 14 + 4 * n + 4 * i)) == e->k[i];
  ++stats[variant].jobs;
  if (same) {
    ++stats[variant].identical;
  } else if (stats[variant].jobs - stats[variant].identical <= 5) {
    fprintf(stderr, "%s job %d (tau %ld): AVR pwm %u status %u sat %u x0 %lld, core pwm %d status %d sat %d x0 %lld\n",
            v->name, job, e->tau_us, get16(avr, 10), avr->data[mailbox + 12], avr->data[mailbox + 13],
            RAW(get32(avr, 14)), e->pwm, e->status, e->saturated, e->x[0]);
  }
#undef RAW
}

/* The next command: init of the next variant, the next job, or stop. */
static void next_command(avr_t *avr) {
  if (last_command == 2) check(avr);
  if (variant >= 0 && job + 1 < ref.variants[variant].count && job + 1 < max_jobs) {
    const ref_job_t *e = &ref.variants[variant].jobs[++job];
    avr->data[mailbox + 0] = 2;
    avr->data[mailbox + 1] = (uint8_t)variant_id(ref.variants[variant].name);
    put32(avr, 2, (uint32_t)e->tau_us);
    put16(avr, 6, (unsigned)e->adc);
    put16(avr, 8, (unsigned)e->setpoint);
    last_command = 2;
    return;
  }
  if (++variant < ref.variant_count) {
    job = -1;
    avr->data[mailbox + 0] = 1;
    avr->data[mailbox + 1] = (uint8_t)variant_id(ref.variants[variant].name);
    put16(avr, 10, (unsigned)ref.variants[variant].pwm0);
    last_command = 1;
    return;
  }
  avr->data[mailbox + 0] = 0;
  last_command = 0;
}

static void on_gpior(struct avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param) {
  (void)param;
  if (addr == GPIOR1_ADDR) {
    mailbox = (uint16_t)((mailbox & 0xFF00u) | v);
  } else if (addr == GPIOR2_ADDR) {
    mailbox = (uint16_t)((mailbox & 0x00FFu) | (unsigned)v << 8);
  } else if (v == 1) {
    next_command(avr);
  } else if (v == 3) {
    window_start = avr->cycle;
  } else if (v == 4) {
    const avr_cycle_count_t c = avr->cycle - window_start;
    if (first_window) {
      overhead = c;
      first_window = 0;
    } else if (variant >= 0) {
      const avr_cycle_count_t net = c - overhead;
      stats[variant].cycles += net;
      if (stats[variant].min == 0 || net < stats[variant].min) stats[variant].min = net;
      if (net > stats[variant].max) stats[variant].max = net;
    }
  } else if (v == 5) {
    done = 1;
  }
}

int main(int argc, char **argv) {
  elf_firmware_t firmware;
  avr_t *avr;
  int v, failed = 0, state = cpu_Running;
  if (argc != 5) {
    fprintf(stderr, "usage: c_job_avr_harness FIRMWARE.elf MCU REFERENCE_FILE MAX_JOBS_PER_VARIANT\n");
    return 2;
  }
  max_jobs = atoi(argv[4]);
  if (ref_read(argv[3], &ref) != 0) return 1;
  memset(&firmware, 0, sizeof firmware);
  if (elf_read_firmware(argv[1], &firmware) != 0) {
    fprintf(stderr, "%s: cannot load\n", argv[1]);
    return 1;
  }
  avr = avr_make_mcu_by_name(argv[2]);
  if (avr == NULL) {
    fprintf(stderr, "simavr does not know the MCU %s\n", argv[2]);
    return 1;
  }
  avr_init(avr);
  avr->frequency = 16000000;
  avr->log = LOG_ERROR;
  avr_load_firmware(avr, &firmware);
  avr_register_io_write(avr, GPIOR0_ADDR, on_gpior, NULL);
  avr_register_io_write(avr, GPIOR1_ADDR, on_gpior, NULL);
  avr_register_io_write(avr, GPIOR2_ADDR, on_gpior, NULL);
  while (!done && state != cpu_Done && state != cpu_Crashed) state = avr_run(avr);
  if (!done) {
    fprintf(stderr, "the firmware stopped before finishing (state %d)\n", state);
    return 1;
  }
  for (v = 0; v < ref.variant_count; ++v) {
    const long n = stats[v].jobs;
    printf("avr %s: %s: %ld jobs, %ld bit-identical; cycles per job mean %.0f, min %lu, max %lu\n", argv[2],
           ref.variants[v].name, n, stats[v].identical, n > 0 ? (double)stats[v].cycles / (double)n : 0.0,
           (unsigned long)stats[v].min, (unsigned long)stats[v].max);
    if (n == 0 || stats[v].identical != n) ++failed;
  }
  printf("avr: marker overhead %lu cycles (subtracted)\n", (unsigned long)overhead);
  /* What elf_read_firmware allocated (the sanitizer build checks for leaks). */
  free(firmware.flash);
  free(firmware.eeprom);
#if ELF_SYMBOLS
  {
    uint32_t i;
    for (i = 0; i < firmware.symbolcount; ++i) free(firmware.symbol[i]);
    free(firmware.symbol);
  }
#endif
  return failed == 0 ? 0 : 1;
}
