// SPDX-License-Identifier: MIT
// dynaqpc scheduler: compile-time capacities. Override any of them in your FW_CONFIG_FILE.
#ifndef SCHED_CONFIG_H
#define SCHED_CONFIG_H

#include "fw/fw_user_config.h"

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

/// A periodic task's deadline tolerance, in permille of its period: sched_tolerance_us(period)
/// is what a task registers as tolerance_us, so that a run starting more than that after its
/// release counts as a deadline miss. Default 100 (10 %): 19.2 ms of the paper's 0.192 s control
/// period. On the MCU a task waits behind at most one idle step (the robot's planning update:
/// 100 us), the handlers of the events queued when its pass began and the other tasks due at
/// that moment (well under 1 ms), so a run 10 % late means something is wrong (a driver that
/// blocks, a handler that loops); and a control step that acts 10 % late still acts on nearly
/// the same observation. On the host in real time at --speed X the PC's wake-up latency counts
/// X times in firmware time (10x: 1.92 ms of wall time is the whole tolerance): dynaqpc-fw
/// reports the lateness in wall time too, so that the PC's misses are not mistaken for the
/// firmware's. At most 1000: a run later than one period is already a skipped release.
#ifndef FW_CFG_SCHED_TOLERANCE_PERMILLE
#define FW_CFG_SCHED_TOLERANCE_PERMILLE 100
#endif

/// Buckets of each task's lateness histogram (sched_get_lateness()). Bucket 0 counts the runs
/// that started at their release, bucket k (1 .. B-2) those 2^(k-1) .. 2^k - 1 us late, the last
/// one every run at least 2^(B-2) us late. 20: the last bucket starts at 262 ms, beyond the
/// paper's 192 ms period. Each bucket costs 4 bytes per task in sched_t.
#ifndef FW_CFG_SCHED_LATENESS_BUCKETS
#define FW_CFG_SCHED_LATENESS_BUCKETS 20
#endif

FW_STATIC_ASSERT(FW_CFG_SCHED_MAX_TASKS >= 1 && FW_CFG_SCHED_MAX_TASKS <= 255, sched_max_tasks);
FW_STATIC_ASSERT(FW_IS_POW2(FW_CFG_SCHED_EVENT_CAPACITY) && FW_CFG_SCHED_EVENT_CAPACITY <= 65536,
                 sched_event_capacity_pow2);
FW_STATIC_ASSERT(FW_CFG_SCHED_EVENT_TYPES >= 1 && FW_CFG_SCHED_EVENT_TYPES <= 256,
                 sched_event_types);
FW_STATIC_ASSERT(FW_CFG_SCHED_IDLE_STEPS_PER_PASS >= 1, sched_idle_steps_per_pass);
FW_STATIC_ASSERT((FW_CFG_SCHED_TOLERANCE_PERMILLE) + 1 > 0 &&
                     FW_CFG_SCHED_TOLERANCE_PERMILLE <= 1000,
                 sched_tolerance_permille);
FW_STATIC_ASSERT(FW_CFG_SCHED_LATENESS_BUCKETS >= 2 && FW_CFG_SCHED_LATENESS_BUCKETS <= 33,
                 sched_lateness_buckets);

#endif // SCHED_CONFIG_H
