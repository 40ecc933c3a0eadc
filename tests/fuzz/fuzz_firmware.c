// SPDX-License-Identifier: MIT
// Fuzz target: the whole firmware (robot_app on the host port in lock-step, flash included) fed
// CAN frames, TOOL_CMDs with valid CRCs, Cricket bytes and the passing of time, as a bus, a serial
// line and an operator could. The first byte picks paper-lab (Cricket pose, Dyna-QPC) or
// paper-sim (GPS pose), and evaluate mode. Ops, each a byte then its arguments:
//   0 a frame: id (an index into the ids the firmware listens to, or raw), dlc (bit 7: seal the
//     frame with its end-to-end Crc, so that sensor frames reach the firmware past the check), data
//   1 a TOOL_CMD: command (any of the seven, RESTORE_PREVIOUS too), argument (encoded as the
//     operator's tool would); a fourth SAVE_LEARNED or RESET_LEARNING and later ones are sent as
//     NOP (the slot orders are all reached by three)
//   2 Cricket bytes: length, bytes
//   3 time: the firmware runs for (byte + 1) ms
// Oracles: no sanitizer report, no hang; the event queue never grows past its capacity; in
// evaluate mode nothing is written to flash.
//
// The agents' tables are the profiles' spaces with fuzz-sized capacities (docs/fuzzing.md
// "Speed"): a SAVE_LEARNED erases, writes and CRC-checks every table, and with the shipped sizes
// (hundreds of KB) saves took 80 % of the time at 45 inputs a second. The hashed tables (Q rows,
// CMAC cells, queue, Dyna-Q records) are shrunk, which also fills them within one input and so
// reaches their eviction and refusal paths; the tables the state space sizes (places, situations,
// positions) keep the profile's sizes, since the agent requires them.
#include <string.h>

#include "robot/agent_profiles.h"
#include "drivers/candev.h"
#include "drivers/telemetry.h"
#include "fuzz.h"
#include "fw/fw_base.h"
#include "hal/hal_time.h"
#include "hal_host/hal_host.h"
#include "robot/robot_app.h"

enum { FUZZ_Q_STATES = 64, FUZZ_CELLS = 64, FUZZ_PQ = 32, FUZZ_TABLE = 32 };
// Small tables in each profile's shape; the Dyna-Q tables' 1,920 bytes hold FUZZ_TABLE records
// each (DYNAQ_RECORDS_IN).
#define FUZZ_ALGORITHM_BYTES 1920
#define FUZZ_LAB_(knob) FUZZ_LAB_##knob
#define FUZZ_SIM_(knob) FUZZ_SIM_##knob
#define FUZZ_LAB_Q_TYPE FW_CFG_LAB_Q_TYPE
#define FUZZ_SIM_Q_TYPE FW_CFG_SIM_Q_TYPE
#define FUZZ_LAB_PLACES FW_CFG_LAB_PLACES
#define FUZZ_SIM_PLACES FW_CFG_SIM_PLACES
#define FUZZ_LAB_CLASSES FW_CFG_LAB_CLASSES
#define FUZZ_SIM_CLASSES FW_CFG_SIM_CLASSES
#define FUZZ_LAB_POSITIONS FW_CFG_LAB_POSITIONS
#define FUZZ_SIM_POSITIONS FW_CFG_SIM_POSITIONS
#define FUZZ_LAB_Q_STATES FUZZ_Q_STATES
#define FUZZ_SIM_Q_STATES FUZZ_Q_STATES
#define FUZZ_LAB_CMAC_CELLS FUZZ_CELLS
#define FUZZ_SIM_CMAC_CELLS FUZZ_CELLS
#define FUZZ_LAB_PQ_CAPACITY FUZZ_PQ
#define FUZZ_SIM_PQ_CAPACITY FUZZ_PQ
#define FUZZ_LAB_ALGORITHM_BYTES FUZZ_ALGORITHM_BYTES
#define FUZZ_SIM_ALGORITHM_BYTES FUZZ_ALGORITHM_BYTES
#define FUZZ_LAB_PAPER_FWD_CELLS FUZZ_CELLS
#define FUZZ_SIM_PAPER_FWD_CELLS FUZZ_CELLS
#define FUZZ_LAB_PAPER_INV_CELLS FUZZ_CELLS
#define FUZZ_SIM_PAPER_INV_CELLS FUZZ_CELLS
#define FUZZ_LAB_TRIED_PAIRS 64
#define FUZZ_SIM_TRIED_PAIRS 64
typedef AGENT_MEMORY_STRUCT(FUZZ_LAB_) fuzz_memory_lab_t;
typedef AGENT_MEMORY_STRUCT(FUZZ_SIM_) fuzz_memory_sim_t;
FW_STATIC_ASSERT(DYNAQ_RECORDS_IN(FUZZ_ALGORITHM_BYTES, 0) == FUZZ_TABLE &&
                     DYNAQ_RECORDS_IN(FUZZ_ALGORITHM_BYTES, FW_CFG_MAX_ACTIONS) == FUZZ_TABLE,
                 fuzz_tables_hold_FUZZ_TABLE_records);
static fuzz_memory_lab_t lab_memory_;
static fuzz_memory_sim_t sim_memory_;
static const agent_storage_t lab_storage_ = AGENT_STORAGE_OF(lab_memory_);
static const agent_storage_t sim_storage_ = AGENT_STORAGE_OF(sim_memory_);

static void run_for_(uint64_t dt_us)
{
    const uint64_t end = hal_time_us() + dt_us;
    for (uint32_t guard = 0; guard < 100000u; guard++) {
        robot_app_step();
        hal_can_frame_t f;
        while (hal_host_can_take_tx(&f)) {
        }
        uint8_t tx[64];
        while (hal_host_uart_take_tx(tx, sizeof tx) > 0u) {
        }
        const uint64_t wake = hal_host_wait_deadline();
        const uint64_t now = hal_time_us();
        if (now >= end) {
            return;
        }
        if (wake > now) {
            (void)hal_host_time_set_us(wake < end ? wake : end);
        }
    }
    __builtin_trap();  // the firmware never asked to sleep: a busy loop
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_in_t in = {data, size};
    const uint8_t pick = fuzz_u8(&in);
    const bool lab = (pick & 1u) == 0u;
    robot_app_options_t opt = {0};
    opt.cfg = lab ? &robot_config_paper_lab : &robot_config_paper_sim;
    opt.agent = lab ? &agent_paper_lab : &agent_paper_sim;
    opt.storage = lab ? &lab_storage_ : &sim_storage_;
    opt.seed = 1;
    opt.evaluate = (pick & 2u) != 0u;
    opt.persist = true;
    opt.auto_start = (pick & 4u) != 0u;
    opt.plan_budget_us = ROBOT_PLAN_BUDGET_US;
    hal_host_reset();
    if (hal_host_flash_configure(128u * 1024u, 4, 4) != FW_OK || robot_app_init(&opt) != FW_OK) {
        __builtin_trap();
    }
    const uint64_t programmed = hal_host_flash_programmed_bytes();
    uint8_t tool_counter = 0;
    uint32_t saves = 0;
    for (uint32_t ops = 0; in.left > 0u && ops < 256u; ops++) {
        const uint8_t op = fuzz_u8(&in) % 4u;
        if (op == 0u) {
            hal_can_frame_t f = {0};
            const uint32_t id = fuzz_u16(&in);
            f.id = id < 0x8000u ? candev_rx_ids[id % CANDEV_RX_ID_COUNT] : (id & 0x7FFu);
            const uint8_t dlc = fuzz_u8(&in);
            f.dlc = (uint8_t)((dlc & 0x7Fu) % 9u);
            for (uint32_t i = 0; i < f.dlc; i++) {
                f.data[i] = fuzz_u8(&in);
            }
            // candev_rx_ids: [0] TOOL_CMD (its own CRC-32, op 1); every other a CRC-8.
            if ((dlc & 0x80u) != 0u && f.dlc > 0u && f.id != candev_rx_ids[0]) {
                can_link_e2e_protect(&f, 8u);
            }
            (void)hal_host_can_deliver(&f);
        } else if (op == 1u) {
            tlm_tool_cmd_t cmd = {(uint8_t)(fuzz_u8(&in) % 7u), fuzz_u32(&in)};
            // Three saves reach every slot order (the first slot, the other, then over the record
            // with fewer episodes of two good ones); more only repeat them, at the cost of a whole
            // save each. A RESET_LEARNING that acts saves what it wipes first: it counts too.
            if ((cmd.command == TLM_CMD_SAVE_LEARNED || cmd.command == TLM_CMD_RESET_LEARNING) && ++saves > 3u) {
                cmd.command = TLM_CMD_NOP;
            }
            hal_can_frame_t f;
            if (tlm_encode_tool_cmd(&tool_counter, &cmd, &f) == FW_OK) {
                (void)hal_host_can_deliver(&f);
            }
        } else if (op == 2u) {
            const uint8_t *bytes;
            const size_t n = fuzz_take(&in, fuzz_u8(&in), &bytes);
            (void)hal_host_uart_feed(bytes, n);
        } else {
            run_for_(((uint64_t)fuzz_u8(&in) + 1u) * 1000u);
        }
    }
    run_for_(opt.cfg->period_us * 2u);
    sched_stats_t ss;
    sched_get_stats(robot_app_sched(), &ss);
    if (opt.evaluate && hal_host_flash_programmed_bytes() != programmed) {
        __builtin_trap();  // evaluate mode saves nothing, whoever asks
    }
    return 0;
}
