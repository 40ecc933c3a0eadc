// SPDX-License-Identifier: MIT
// dynaqpc STM32F4 firmware images: the entry point after the reset handler.
//
// Brings the board up (clocks, pins, reset cause) and hands over to the robot application,
// which initialises the HAL, the drivers and the agent and then runs its scheduler for ever.
// Which scenario and agent profile: DYNAQPC_PROFILE_PAPER_LAB, DYNAQPC_PROFILE_PAPER_SIM or
// DYNAQPC_PROFILE_PAPER_SIM_LARGE, defined on this file by targets/stm32f4-robot/CMakeLists.txt,
// selects robot_main_paper_lab(), robot_main_paper_sim() or robot_main_paper_sim_large() in
// robot_main() (robot/robot_main.h) and the record bound below.
#include "robot/agent_profiles.h"
#include "robot/learned_store.h"
#include "robot/robot_main.h"
#include "stm32f4/stm32f4_board.h"

// The largest record this image's agent can save: the header plus, at most, the whole storage of
// its profile (the learned tables are part of it). ld/store.ld fails the link when that does not
// fit one slot of the image's hal_flash region, so an image never boots unable to keep what it
// learned.
#if defined(DYNAQPC_PROFILE_PAPER_SIM_LARGE)
#define IMAGE_AGENT_MEMORY_BYTES AGENT_PAPER_SIM_LARGE_BYTES
#elif defined(DYNAQPC_PROFILE_PAPER_SIM)
#define IMAGE_AGENT_MEMORY_BYTES sizeof(agent_memory_paper_sim_t)
#else
#define IMAGE_AGENT_MEMORY_BYTES sizeof(agent_memory_paper_lab_t)
#endif
#define LEARNED_RECORD_BOUND (sizeof(learned_header_t) + IMAGE_AGENT_MEMORY_BYTES)

// Publishes the bound as the absolute symbol dynaqpc_learned_record_bound for the linker script
// (C has no other way to hand a sizeof to the linker). The function itself is never called and
// --gc-sections drops it; the symbol stays.
__attribute__((used)) static void publish_learned_record_bound_(void)
{
    __asm__(".global dynaqpc_learned_record_bound\n\t"
            ".equ dynaqpc_learned_record_bound, %c0" ::"i"(LEARNED_RECORD_BOUND));
}

int main(void)
{
    if (stm32f4_board_init() != 0) {
        // No crystal or no PLL lock: CAN and UART timing would be wrong. Stop here; the watchdog
        // is not running yet, so the board stays visibly dead rather than half-working.
        for (;;) {
            __asm__ volatile("wfi");
        }
    }
    robot_main((const void *)0);
    for (;;) {  // robot_main() does not return
        __asm__ volatile("wfi");
    }
}
