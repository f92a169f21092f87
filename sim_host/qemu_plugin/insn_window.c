/* insn_window: a QEMU TCG plugin counting the guest instructions executed between two
 * addresses. Each time the instruction at `begin` executes the count restarts; each
 * time the instruction at `end` executes, the count so far is appended to `out`.
 *
 *   qemu-system-arm ... -plugin libinsn_window.so,begin=0x1234,end=0x1240,out=counts.txt
 *
 * With profile=FILE it also writes, at exit, how often each instruction address ran
 * inside the windows (for finding where a job's instructions go).
 *
 * The few declarations of the QEMU plugin API (version 1, QEMU 7.2) it needs are written
 * here from the API's documentation; Debian ships no plugin header. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS = 0 };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 = 0 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn, enum qemu_plugin_op op, void *ptr,
                                                uint64_t imm);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t executed;     /* every guest instruction, added inline */
static uint64_t window_start;
static uint64_t begin_pc = UINT64_MAX;
static uint64_t end_pc = UINT64_MAX;
static FILE *out;
/* Optional profile: executions per instruction address inside the windows. */
#define PROFILE_SLOTS 65536
static uint64_t profile_pc[PROFILE_SLOTS];
static uint64_t profile_count[PROFILE_SLOTS];
static int in_window;
static const char *profile_path;

static void on_begin(unsigned int vcpu_index, void *userdata) {
  (void)vcpu_index;
  (void)userdata;
  window_start = executed;
  in_window = 1;
}

static void on_end(unsigned int vcpu_index, void *userdata) {
  (void)vcpu_index;
  (void)userdata;
  in_window = 0;
  fprintf(out, "%llu\n", (unsigned long long)(executed - window_start));
  fflush(out);
}

static void on_profiled(unsigned int vcpu_index, void *userdata) {
  (void)vcpu_index;
  if (!in_window) return;
  const uint64_t pc = (uint64_t)(uintptr_t)userdata;
  size_t slot = (size_t)((pc >> 1) * 2654435761u) % PROFILE_SLOTS;
  while (profile_count[slot] != 0 && profile_pc[slot] != pc) slot = (slot + 1) % PROFILE_SLOTS;
  profile_pc[slot] = pc;
  ++profile_count[slot];
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
  (void)id;
  const size_t n = qemu_plugin_tb_n_insns(tb);
  for (size_t i = 0; i < n; ++i) {
    struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
    const uint64_t pc = qemu_plugin_insn_vaddr(insn);
    if (pc == begin_pc) qemu_plugin_register_vcpu_insn_exec_cb(insn, on_begin, QEMU_PLUGIN_CB_NO_REGS, NULL);
    if (pc == end_pc) qemu_plugin_register_vcpu_insn_exec_cb(insn, on_end, QEMU_PLUGIN_CB_NO_REGS, NULL);
    qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
    if (profile_path != NULL) {
      qemu_plugin_register_vcpu_insn_exec_cb(insn, on_profiled, QEMU_PLUGIN_CB_NO_REGS, (void *)(uintptr_t)pc);
    }
  }
}

static void on_plugin_exit(qemu_plugin_id_t id, void *userdata) {
  (void)id;
  (void)userdata;
  if (out != NULL) fclose(out);
  out = NULL;
  if (profile_path != NULL) {
    FILE *p = fopen(profile_path, "w");
    if (p != NULL) {
      for (size_t i = 0; i < PROFILE_SLOTS; ++i)
        if (profile_count[i] != 0) fprintf(p, "0x%llx %llu\n", (unsigned long long)profile_pc[i], (unsigned long long)profile_count[i]);
      fclose(p);
    }
  }
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                                               int argc, char **argv) {
  (void)info;
  const char *path = NULL;
  for (int i = 0; i < argc; ++i) {
    if (strncmp(argv[i], "begin=", 6) == 0) begin_pc = strtoull(argv[i] + 6, NULL, 0) & ~1ULL;
    else if (strncmp(argv[i], "end=", 4) == 0) end_pc = strtoull(argv[i] + 4, NULL, 0) & ~1ULL;
    else if (strncmp(argv[i], "out=", 4) == 0) path = argv[i] + 4;
    else if (strncmp(argv[i], "profile=", 8) == 0) profile_path = argv[i] + 8;
  }
  if (begin_pc == UINT64_MAX || end_pc == UINT64_MAX || path == NULL) {
    fprintf(stderr, "insn_window: needs begin=ADDR,end=ADDR,out=FILE\n");
    return -1;
  }
  out = fopen(path, "w");
  if (out == NULL) {
    fprintf(stderr, "insn_window: cannot write %s\n", path);
    return -1;
  }
  qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
  qemu_plugin_register_atexit_cb(id, on_plugin_exit, NULL);
  return 0;
}
