// SPDX-License-Identifier: MIT
// dynaqpc on the emulated robot board (QEMU netduinoplus2, hal/ports/stm32f4/boards/netduinoplus2):
// the paper-lab robot's firmware, the same application, scheduler, drivers and flash store as
// targets/stm32f4-robot, started the way robot_app_run() starts it, and reporting its own
// counters over the board's console (semihosting) every few seconds.
//
// Options come from QEMU's -append (key=value, space separated; the defaults are the image's):
//   seed=N        the agent's seed (1)
//   step_cap=N    real steps after which an episode ends (the scenario's, 200)
//   planning=N    planning updates per real step, 0 = idle time (the scenario's: 0)
//   agent=K       0 Q-learning, 1 Dyna-Q, 2 Dyna-QPC (the scenario's: 2)
//   persist=0     no saving at episode ends (the control task's worst run is then its own: the
//                 save of ~51 KB at an episode's end is the longest run otherwise)
//   speed=X       firmware time runs X times faster than QEMU's clock (1; X divides 168): with
//                 the devices at --speed X (dynaqpc-emu run --speed X)
//   duration_s=N  end the emulation after N s of firmware time (0: never)
//   report_s=N    a report line every N s of firmware time (5)
// The emulation ends with exit code 0, or 1 when a deadline was missed (netduinoplus2/board.h);
// a fault ends it with 3 at once.
#include <stdbool.h>
#include <string.h>

#include "hal/hal_can.h"
#include "hal/hal_time.h"
#include "netduinoplus2/board.h"
#include "robot/agent_profiles.h"
#include "robot/learned_store.h"
#include "robot/robot_app.h"
#include "stm32f4/semihost.h"

// The largest record the agent can save; the linker script checks it fits a slot.
#define LEARNED_RECORD_BOUND (sizeof(learned_header_t) + sizeof(agent_memory_paper_lab_t))
__attribute__((used)) static void publish_learned_record_bound_(void)
{
    __asm__(".global dynaqpc_learned_record_bound\n\t"
            ".equ dynaqpc_learned_record_bound, %c0" ::"i"(LEARNED_RECORD_BOUND));
}

static uint32_t option_(const char *cmdline, const char *key, uint32_t dflt)
{
    const size_t k = strlen(key);
    for (const char *p = cmdline; *p != '\0'; p++) {
        if ((p == cmdline || p[-1] == ' ') && strncmp(p, key, k) == 0 && p[k] == '=') {
            uint32_t v = 0;
            for (p += k + 1u; *p >= '0' && *p <= '9'; p++) {
                v = v * 10u + (uint32_t)(*p - '0');
            }
            return v;
        }
    }
    return dflt;
}

static void report_(const char *what)
{
    sched_stats_t ss;
    sched_get_stats(robot_app_sched(), &ss);
    robot_app_stats_t st;
    robot_app_get_stats(&st);
    hal_can_stats_t cs;
    hal_can_get_stats(&cs);
    const agent_stats_t *as = &agent_paper_lab.stats;
    uint32_t misses = 0;
    for (uint32_t i = 0; i < ss.task_count; i++) {
        misses += ss.task[i].misses;
    }
    semihost_puts(what);
    semihost_kv("t_ms", hal_time_us() / 1000u);
    semihost_kv("episodes", st.episodes);
    semihost_kv("real_steps", as->real_steps);
    semihost_kv("planning_updates", as->planning_updates);
    semihost_kv("idle_loop_updates", ss.idle_steps);
    semihost_kv("control_runs", ss.task[0].runs);
    semihost_kv("control_worst_run_us", ss.task[0].worst_run_us);
    semihost_kv("control_worst_lateness_us", ss.task[0].worst_lateness_us);
    semihost_kv("misses", misses);
    semihost_kv("idle_permille", hal_time_us() == 0u ? 0u : (uint32_t)(ss.idle_us * 1000u / hal_time_us()));
    semihost_kv("events_dropped", ss.events_dropped);
    semihost_kv("events_high_water", ss.events_high_water);
    semihost_kv("frames_rx", st.frames_rx);
    semihost_kv("frames_bad", st.frames_bad);
    semihost_kv("can_tx", cs.tx_frames);
    semihost_kv("can_tx_dropped", cs.tx_dropped);
    semihost_kv("slcan_errors", nd2_slcan_errors());
    semihost_kv("saves", st.saves);
    semihost_kv("save_errors", st.save_errors);
    semihost_kv("stack_unused", nd2_stack_unused_bytes());
    semihost_puts("\n");
}

int main(void)
{
    (void)nd2_board_init();
    static char cmdline[160];
    semihost_cmdline(cmdline, sizeof cmdline);
    if (nd2_set_time_speed(option_(cmdline, "speed", 1u)) != 0) {
        semihost_puts("netduinoplus2: speed= must divide 168\n");
        semihost_exit(ND2_EXIT_INIT);
    }
    static robot_config_t cfg;
    cfg = robot_config_paper_lab;
    cfg.step_cap = option_(cmdline, "step_cap", cfg.step_cap);
    cfg.planning = option_(cmdline, "planning", cfg.planning);
    const uint32_t kind = option_(cmdline, "agent", (uint32_t)cfg.agent);
    cfg.agent = kind < (uint32_t)AGENT_KINDS ? (agent_kind_t)kind : cfg.agent;
    const uint64_t duration_us = (uint64_t)option_(cmdline, "duration_s", 0u) * 1000000u;
    const uint64_t report_us = (uint64_t)option_(cmdline, "report_s", 5u) * 1000000u;

    robot_app_options_t opt = {0};
    opt.cfg = &cfg;
    opt.agent = &agent_paper_lab;
    opt.storage = &agent_storage_paper_lab;
    opt.seed = option_(cmdline, "seed", 1u);
    opt.persist = option_(cmdline, "persist", 1u) != 0u;
    opt.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    const int rc = robot_app_init(&opt);
    if (rc != FW_OK) {
        semihost_kv("netduinoplus2: robot_app_init failed, rc", (uint64_t)(uint32_t)-rc);
        semihost_puts("\n");
        semihost_exit(ND2_EXIT_INIT);
    }
    semihost_puts("netduinoplus2: paper-lab firmware running; ");
    semihost_kv("step_cap", cfg.step_cap);
    semihost_kv("planning", cfg.planning);
    semihost_kv("agent", (uint32_t)cfg.agent);
    semihost_kv("seed", opt.seed);
    semihost_puts("\n");
    uint64_t next_report = report_us;
    for (;;) {
        robot_app_step();
        const uint64_t now = hal_time_us();
        if (report_us != 0u && now >= next_report) {
            report_("report: ");
            next_report += report_us;
        }
        if (duration_us != 0u && now >= duration_us) {
            report_("final: ");
            sched_stats_t ss;
            sched_get_stats(robot_app_sched(), &ss);
            uint32_t misses = 0;
            for (uint32_t i = 0; i < ss.task_count; i++) {
                misses += ss.task[i].misses;
            }
            semihost_exit(misses == 0u ? ND2_EXIT_OK : ND2_EXIT_FAILED);
        }
    }
}
