// SPDX-License-Identifier: MIT
// dynaqpc scheduler: compile-time capacities. Override any of them in your FW_CONFIG_FILE.
#ifndef SCHED_CONFIG_H
#define SCHED_CONFIG_H

#include "fw_config.h"

#include "fw/fw_base.h"

/// Periodic tasks one scheduler can hold. The robot uses a handful (control, telemetry, watchdog).
/// Each costs 64 bytes of RAM in sched_t.
#ifndef FW_CFG_SCHED_MAX_TASKS
#define FW_CFG_SCHED_MAX_TASKS 8
#endif

/// Events the interrupt-fed queue holds before sched_post() refuses (FW_ERR_FULL). A power of
/// two (the ring indexes with a mask). 32 covers a 0.192 s control period's CAN traffic
/// (a few frames per device per period) with room for the Cricket lines. Each event is 20 bytes.
#ifndef FW_CFG_SCHED_EVENT_CAPACITY
#define FW_CFG_SCHED_EVENT_CAPACITY 32
#endif

/// Event types are 0 .. FW_CFG_SCHED_EVENT_TYPES - 1; one handler per type.
#ifndef FW_CFG_SCHED_EVENT_TYPES
#define FW_CFG_SCHED_EVENT_TYPES 16
#endif

/// Idle steps one sched_step() runs at most before it returns (without waiting), so that a pass
/// is bounded even if time does not move (lock-step with idle_step_cycles = 0) and pending
/// events are dispatched at least this often.
#ifndef FW_CFG_SCHED_IDLE_STEPS_PER_PASS
#define FW_CFG_SCHED_IDLE_STEPS_PER_PASS 256
#endif

FW_STATIC_ASSERT(FW_CFG_SCHED_MAX_TASKS >= 1 && FW_CFG_SCHED_MAX_TASKS <= 255, sched_max_tasks);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_SCHED_EVENT_CAPACITY) && FW_CFG_SCHED_EVENT_CAPACITY <= 65536,
                 sched_event_capacity_pow2);
FW_STATIC_ASSERT(FW_CFG_SCHED_EVENT_TYPES >= 1 && FW_CFG_SCHED_EVENT_TYPES <= 256,
                 sched_event_types);
FW_STATIC_ASSERT(FW_CFG_SCHED_IDLE_STEPS_PER_PASS >= 1, sched_idle_steps_per_pass);

#endif // SCHED_CONFIG_H
