/* wincount: a QEMU TCG plugin that counts the guest instructions executed in windows.
 *
 * A window opens each time the guest executes the instruction at `start` and closes at the
 * next execution of the instruction at `end`; each closed window is reported as
 *   wincount: end window N insns=COUNT
 * and the run's total at exit as
 *   wincount: total insns=COUNT
 * slf brackets the code it measures with two never-inlined marker functions (`bench_begin`,
 * `bench_end` in the device binary) and passes their addresses (see scripts/budgets.sh):
 *   qemu-system-arm ... -plugin ./libwincount.so,start=0xADDR,end=0xADDR -d plugin
 *
 * With `prof=FIRST:LAST` it also counts, per instruction address in flash, the instructions
 * executed inside windows FIRST..=LAST (1-based), and prints each address's count at exit as
 *   wincount: prof 0xADDR COUNT
 * which scripts/device-profile.py adds up per function from the ELF's symbols: where a
 * window's instructions go.
 *
 * Counting is exact and repeatable (it does not depend on the host's load), which is why the
 * budgets use it instead of cycle timers: qemu's DWT cycle counter reads 0.
 *
 * Build: gcc -O2 -shared -fPIC -fvisibility=hidden -o libwincount.so wincount.c
 *
 * The plugin API is QEMU's (include/qemu/qemu-plugin.h, API version 1 as in QEMU 7.2, the
 * Debian bookworm package). Its header is not packaged, so the few declarations used are
 * written out below; they are the API's, unchanged since version 1. */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
typedef struct qemu_info_t qemu_info_t;

extern void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
extern size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
extern struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
extern uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
extern void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                                   enum qemu_plugin_cb_flags flags, void *userdata);
extern void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
extern void qemu_plugin_outs(const char *string);

/* QEMU refuses a plugin that does not export the API version it was written for. */
__attribute__((visibility("default"))) int qemu_plugin_version = 1;

/* An address no Thumb instruction has (instructions are 2-byte aligned) until set. */
#define UNSET UINT64_MAX

static uint64_t start_pc = UNSET;
static uint64_t end_pc = UNSET;
static uint64_t total;     /* instructions in the whole run */
static uint64_t in_window; /* instructions in the open window */
static uint64_t windows;   /* windows closed so far */
static int open;           /* a window is open */

/* The profile: one counter per 2-byte instruction address of the 1 MiB flash, at memory.x's
 * FLASH origin on the emulator (mps2-an500: its ZBT SSRAM1 at 0; an H743's 0x08000000 is not
 * where qemu runs the code, and a profile there counted nothing). */
#define FLASH_BASE 0x00000000u
#define FLASH_SIZE 0x00100000u
static uint64_t *prof;     /* NULL without prof= */
static uint64_t prof_first, prof_last;

/* One callback per executed instruction; the instruction's address is its user data. The
 * emulated Cortex-M has one vCPU, so plain counters suffice. */
static void on_exec(unsigned int vcpu_index, void *userdata)
{
    uint64_t pc = (uint64_t)(uintptr_t)userdata;
    (void)vcpu_index;
    total++;
    if (open && pc == end_pc) {
        char line[128];
        open = 0;
        windows++;
        snprintf(line, sizeof line, "wincount: end window %" PRIu64 " insns=%" PRIu64 "\n", windows, in_window);
        qemu_plugin_outs(line);
    }
    if (pc == start_pc) {
        open = 1;
        in_window = 0;
    }
    if (open) {
        in_window++;
        if (prof && windows + 1 >= prof_first && windows + 1 <= prof_last && pc >= FLASH_BASE &&
            pc < FLASH_BASE + FLASH_SIZE) {
            prof[(pc - FLASH_BASE) / 2]++;
        }
    }
}

/* At translation, hook every instruction of the new block. */
static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    (void)id;
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t pc = qemu_plugin_insn_vaddr(insn);
        qemu_plugin_register_vcpu_insn_exec_cb(insn, on_exec, QEMU_PLUGIN_CB_NO_REGS, (void *)(uintptr_t)pc);
    }
}

static void on_run_end(qemu_plugin_id_t id, void *userdata)
{
    char line[96];
    (void)id;
    (void)userdata;
    snprintf(line, sizeof line, "wincount: total insns=%" PRIu64 "\n", total);
    qemu_plugin_outs(line);
    if (prof) {
        for (uint64_t i = 0; i < FLASH_SIZE / 2; i++) {
            if (prof[i]) {
                snprintf(line, sizeof line, "wincount: prof 0x%08" PRIx64 " %" PRIu64 "\n", FLASH_BASE + 2 * i, prof[i]);
                qemu_plugin_outs(line);
            }
        }
    }
}

/* Parses `name=0xADDR`; a Thumb symbol's address has bit 0 set, the instruction's does not. */
static int parse(const char *arg, const char *name, uint64_t *out)
{
    size_t len = strlen(name);
    char *rest;
    if (strncmp(arg, name, len) != 0 || arg[len] != '=') {
        return 0;
    }
    *out = strtoull(arg + len + 1, &rest, 0) & ~(uint64_t)1;
    return *rest == '\0';
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                                               int argc, char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "prof=", 5) == 0) {
            char *rest;
            prof_first = strtoull(argv[i] + 5, &rest, 10);
            prof_last = *rest == ':' ? strtoull(rest + 1, &rest, 10) : prof_first;
            prof = calloc(FLASH_SIZE / 2, sizeof *prof);
            if (*rest != '\0' || prof_first == 0 || prof_last < prof_first || !prof) {
                fprintf(stderr, "wincount: prof=%s is not FIRST[:LAST] windows, 1-based\n", argv[i] + 5);
                return -1;
            }
            continue;
        }
        if (!parse(argv[i], "start", &start_pc) && !parse(argv[i], "end", &end_pc)) {
            fprintf(stderr, "wincount: unknown or malformed argument %s (expected start=ADDR, end=ADDR, prof=N[:M])\n",
                    argv[i]);
            return -1;
        }
    }
    if (start_pc == UNSET || end_pc == UNSET) {
        fprintf(stderr, "wincount: needs start=ADDR and end=ADDR\n");
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_run_end, NULL);
    return 0;
}
