// SPDX-License-Identifier: MIT
// dynaqpc: what the algorithm files share from below (algorithm.h): handing facts to a walk's
// visitor, the Q store's rows as visits, and the trivial operations. Apart from agent.c, so that
// the algorithm files use no file that uses them (agent.c holds the registry of their tables).
#include <stddef.h>

#include "algorithm.h"
#include "fw/fw_base.h"

// ---- What the agent knows: the walk's visits ---------------------------------------------------

int agent_visit_counter_(agent_visit_t visit, void *data, const char *name, uint32_t value,
                         uint32_t capacity)
{
    agent_fact_t f;
    f.kind = AGENT_FACT_COUNTER;
    f.u.counter = (agent_counter_t){name, value, capacity};
    return visit(data, &f);
}

int agent_visit_table_(agent_visit_t visit, void *data, const char *name, const char *unit,
                       uint32_t used, uint32_t capacity)
{
    agent_fact_t f;
    f.kind = AGENT_FACT_TABLE;
    f.u.table = (agent_table_fill_t){name, unit, used, capacity, -1};
    return visit(data, &f);
}

int agent_visit_state_(agent_visit_t visit, void *data, const agent_state_facts_t *facts)
{
    agent_fact_t f;
    f.kind = AGENT_FACT_STATE;
    f.u.state = *facts;
    return visit(data, &f);
}

int agent_walk_rows_as_visits_(const agent_t *ag, agent_visit_t visit, void *data)
{
    for (agent_state_t s = 0; (s >> ag->state_bits) == 0u; s++) {
        if (qstore_has_row(&ag->q, s)) {
            const agent_state_facts_t f = {s, false, true, false, {0}};
            AGENT_VISIT_(agent_visit_state_(visit, data, &f));
        }
    }
    return 0;
}

// ---- Trivial operations, for algorithms with nothing to do there -------------------------------

int agent_init_nothing_(agent_t *ag, const agent_storage_t *st)
{
    (void)ag;
    (void)st;
    return FW_OK;
}

void agent_nothing_(agent_t *ag)
{
    (void)ag;
}

uint32_t agent_plan_nothing_(agent_t *ag, uint32_t n)
{
    (void)ag;
    (void)n;
    return 0u;
}

uint32_t agent_list_nothing_(const agent_t *ag, agent_region_t *out)
{
    (void)ag;
    (void)out;
    return 0u;
}

int agent_check_nothing_(const agent_t *ag, const void *const *image, uint32_t state_bits)
{
    (void)ag;
    (void)image;
    (void)state_bits;
    return FW_OK;
}

int agent_walk_nothing_(agent_t *ag, uint32_t what, agent_visit_t visit, void *data)
{
    (void)ag;
    (void)what;
    (void)visit;
    (void)data;
    return 0;
}

uint32_t agent_backlog_none_(const agent_t *ag)
{
    (void)ag;
    return 0u;
}
