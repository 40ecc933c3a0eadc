// SPDX-License-Identifier: MIT
// dynaqpc: a QEMU TCG plugin (API version 1) that counts guest instructions between marks.
//
// The guest calls marker functions; their addresses come as arguments:
//   -plugin libinsn_count.so,begin=0x...,end=0x...,report=0x...
// Counting switches on when the block at `begin` runs (the marker's own return instruction is
// counted) and off when the block at `end` runs; at `report` the plugin prints
//   insn_count=<instructions counted> windows=<begin marks seen> max_window=<the most in one window>
// on stderr and starts again from zero. With top=<n> it also prints the n blocks that executed
// the most counted instructions, as `hot pc=0x<block start> insns=<n>` (a profile: the
// benchmark script maps the addresses to functions). A marker is a whole function entered by a call, so its
// address always starts a translation block: counting whole blocks is exact. (The plugin runs
// on the host inside QEMU, not on the MCU: its malloc is QEMU's process heap.)
//
// Debian's QEMU accepts plugins but ships no plugin header: the few declarations used here are
// written from the API's documentation (include/qemu/qemu-plugin.h in QEMU 7.2, version 1).
#include <inttypes.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;  // not looked at
struct qemu_plugin_tb;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS };

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id,
                                           void (*cb)(qemu_plugin_id_t id,
                                                      struct qemu_plugin_tb *tb));
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb,
                                          void (*cb)(unsigned int vcpu, void *udata),
                                          enum qemu_plugin_cb_flags flags, void *udata);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
uint64_t qemu_plugin_tb_vaddr(const struct qemu_plugin_tb *tb);

EXPORT extern int qemu_plugin_version;
EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc,
                               char **argv);

EXPORT int qemu_plugin_version = 1;

enum { KIND_PLAIN = 0, KIND_BEGIN = 1, KIND_END = 2, KIND_REPORT = 3 };

static uint64_t begin_addr_, end_addr_, report_addr_;
static bool counting_;
static uint64_t count_;
static uint64_t windows_;
static uint64_t window_start_;  // count_ when the current window began
static uint64_t max_window_;    // the most instructions one window counted

// Per-block profile (top=<n>): open addressing on the block's start address.
#define PROFILE_SLOTS 16384u
typedef struct block_count {
    uint64_t pc;
    uint64_t insns;
} block_count_t;
static block_count_t profile_[PROFILE_SLOTS];
static uint64_t top_;

static void profile_add_(uint64_t pc, uint64_t n)
{
    for (uint32_t i = 0; i < PROFILE_SLOTS; i++) {
        block_count_t *b = &profile_[(uint32_t)((pc >> 1) + i) % PROFILE_SLOTS];
        if (b->pc == pc || b->insns == 0) {
            b->pc = pc;
            b->insns += n;
            return;
        }
    }
}

static void profile_print_(void)
{
    for (uint64_t k = 0; k < top_; k++) {
        block_count_t *best = NULL;
        for (uint32_t i = 0; i < PROFILE_SLOTS; i++) {
            if (profile_[i].insns > 0 && (best == NULL || profile_[i].insns > best->insns)) {
                best = &profile_[i];
            }
        }
        if (best == NULL) {
            break;
        }
        fprintf(stderr, "hot pc=0x%" PRIx64 " insns=%" PRIu64 "\n", best->pc, best->insns);
        best->insns = 0;  // taken: the next round finds the next largest
    }
    memset(profile_, 0, sizeof profile_);
}

typedef struct block_info {
    uint64_t pc;
    uint64_t n;
    int kind;
} block_info_t;

static void block_exec_(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    const block_info_t *b = (const block_info_t *)udata;
    const uint64_t n = b->n;
    switch (b->kind) {
    case KIND_BEGIN:
        counting_ = true;
        windows_++;
        window_start_ = count_;
        count_ += n;
        break;
    case KIND_END:
        if (counting_ && count_ - window_start_ > max_window_) {
            max_window_ = count_ - window_start_;
        }
        counting_ = false;
        break;
    case KIND_REPORT:
        fprintf(stderr, "insn_count=%" PRIu64 " windows=%" PRIu64 " max_window=%" PRIu64 "\n", count_, windows_,
                max_window_);
        profile_print_();
        fflush(stderr);
        count_ = 0;
        windows_ = 0;
        max_window_ = 0;
        counting_ = false;
        break;
    default:
        if (counting_) {
            count_ += n;
            if (top_ > 0) {
                profile_add_(b->pc, n);
            }
        }
        break;
    }
}

static void block_trans_(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    const uint64_t pc = qemu_plugin_tb_vaddr(tb);
    int kind = KIND_PLAIN;
    if (pc == begin_addr_) {
        kind = KIND_BEGIN;
    } else if (pc == end_addr_) {
        kind = KIND_END;
    } else if (pc == report_addr_) {
        kind = KIND_REPORT;
    }
    // One record per translation, never freed: a bare-metal image translates a few thousand
    // blocks (QEMU may translate a block again after its cache fills; that costs a few bytes).
    block_info_t *info = malloc(sizeof *info);
    if (info == NULL) {
        fprintf(stderr, "insn_count: out of memory\n");
        abort();
    }
    info->pc = pc;
    info->n = qemu_plugin_tb_n_insns(tb);
    info->kind = kind;
    qemu_plugin_register_vcpu_tb_exec_cb(tb, block_exec_, QEMU_PLUGIN_CB_NO_REGS, info);
}

static bool arg_(const char *arg, const char *key, uint64_t *out)
{
    const size_t n = strlen(key);
    if (strncmp(arg, key, n) != 0 || arg[n] != '=') {
        return false;
    }
    *out = strtoull(arg + n + 1, NULL, 0);
    return true;
}

int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (!arg_(argv[i], "begin", &begin_addr_) && !arg_(argv[i], "end", &end_addr_) &&
            !arg_(argv[i], "report", &report_addr_) && !arg_(argv[i], "top", &top_)) {
            fprintf(stderr, "insn_count: unknown argument '%s'\n", argv[i]);
            return -1;
        }
    }
    begin_addr_ &= ~(uint64_t)1;  // a Thumb function's symbol has bit 0 set; its code does not
    end_addr_ &= ~(uint64_t)1;
    report_addr_ &= ~(uint64_t)1;
    if (begin_addr_ == 0 || end_addr_ == 0 || report_addr_ == 0) {
        fprintf(stderr, "insn_count: needs begin=, end= and report= addresses\n");
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, block_trans_);
    return 0;
}
