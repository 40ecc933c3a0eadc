// SPDX-License-Identifier: MIT
// dynaqpc: private to the agent's sources: forced inlining for the planner's hot paths.
#ifndef AGENT_INLINE_H
#define AGENT_INLINE_H

// The MCU build is optimised for size (-Os), under which GCC keeps a static function that has
// more than one caller as a call. The planner's inner lookups are small and run about twenty
// times per planning update; these few are inlined regardless.
#if defined(__GNUC__)
#define AGENT_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define AGENT_ALWAYS_INLINE static inline
#endif

#endif // AGENT_INLINE_H
