// SPDX-License-Identifier: MIT
// The paper images' records through the STM32F4 flash driver (hal/ports/stm32f4/src/
// stm32f4_flash.c) and the firmware's two-slot store (firmware/robot/src/learned_store.c), on a
// fake flash interface holding a region of the size the linker scripts give:
//   paper-lab, boards/robot: sectors 10-11, 2 x 128 KB (slots of one sector)
//   paper-sim, boards/robot-f42x: bank-2 sectors 20-23, 4 x 128 KB (slots of two sectors)
// The hal_flash functions below are what hal_stm32f4.c does on the MCU: the driver on a region.
#include "test_common.h"

#include <string.h>

#include "robot/agent_profiles.h"
#include "fw/fw_crc.h"
#include "fw/fw_prng.h"
#include "fw/fw_base.h"
#include "robot/learned_digest.h"
#include "robot/learned_store.h"
#include "robot/robot_config.h"
#include "robot/robot_geometry.h"
#include "stm32f4/stm32f4_drivers.h"
#include "stm32f4_fake.h"

#define SECTOR_BYTES (128u * 1024u)
#define MAX_SECTORS 4u

static uint8_t mem_[MAX_SECTORS * SECTOR_BYTES];
static stm32f4_fake_flash_t fake_;
static stm32f4_flash_dev_t dev_;

int hal_flash_get_geometry(hal_flash_geometry_t *out)
{
    return stm32f4_flash_geometry(&dev_, out);
}

int hal_flash_read(uint32_t offset, void *buf, size_t len)
{
    return stm32f4_flash_read(&dev_, offset, buf, len);
}

const void *hal_flash_map(uint32_t offset, size_t len)
{
    return stm32f4_flash_map(&dev_, offset, len);
}

int hal_flash_erase(uint32_t sector)
{
    return stm32f4_flash_erase(&dev_, sector);
}

int hal_flash_write(uint32_t offset, const void *data, size_t len)
{
    return stm32f4_flash_program(&dev_, offset, data, len);
}

// A region as the port builds it from the linker script's symbols: checked against the sector
// map and a part of `flash_kb`, no region if it does not fit.
static void use_region_(uint32_t addr, uint32_t first, uint32_t count, uint32_t flash_kb)
{
    stm32f4_fake_flash_reset(&fake_, mem_, MAX_SECTORS, SECTOR_BYTES, first);
    dev_.regs = &fake_.regs;
    dev_.mem = mem_;
    dev_.first_sector = first;
    dev_.sector_size = SECTOR_BYTES;
    dev_.sector_count =
        stm32f4_flash_region_check(addr, first, count, SECTOR_BYTES, flash_kb) == FW_OK ? count
                                                                                       : 0u;
    dev_.on_wait = NULL;
}

static agent_space_t space_;

static void init_agent_(agent_t *ag, const robot_config_t *cfg, const agent_storage_t *storage,
                        uint32_t seed)
{
    robot_config_space(cfg, &space_);
    const agent_config_t ac = {cfg->agent, &space_, cfg->params, storage, seed};
    assert_int_equal(agent_init(ag, &ac), FW_OK);
}

// Experience in random states of the robot's space, with planning: every learned table changes.
static void learn_(agent_t *ag, uint32_t steps, uint32_t seed)
{
    prng_t rng;
    prng_seed(&rng, seed);
    const uint32_t states = 1u << space_state_bits(&space_);
    for (uint32_t i = 0; i < steps; i++) {
        const agent_state_t s = prng_below(&rng, states);
        const uint8_t a = agent_act(ag, s);
        const agent_state_t next = prng_below(&rng, states);
        agent_observe(ag, s, a, prng_unit(&rng) - 0.5f, next, (i % 97u) == 96u);
        (void)agent_plan(ag, 5);
    }
}

static int setup_(void **state)
{
    (void)state;
    memset(mem_, 0xFF, sizeof mem_);  // as shipped: erased
    return 0;
}

// The paper-sim record (~140 KB) cannot live in slots of one 128 KB sector.
static void paper_sim_record_does_not_fit_one_sector_slots(void **state)
{
    (void)state;
    use_region_(0x080C0000u, 10, 2, 2048);
    init_agent_(&agent_paper_sim, &robot_config_paper_sim, &agent_storage_paper_sim, 1);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_int_equal(st.slot_size, SECTOR_BYTES);
    assert_true(learned_store_record_size(&agent_paper_sim) > st.slot_size);
    assert_int_equal(learned_store_save(&st, &agent_paper_sim, 1), FW_ERR_NOMEM);
    assert_int_equal(fake_.erased_snbs, 0);  // refused before touching the flash
}

static void paper_sim_record_persists_in_bank2(void **state)
{
    (void)state;
    use_region_(0x08180000u, 20, 4, 2048);
    init_agent_(&agent_paper_sim, &robot_config_paper_sim, &agent_storage_paper_sim, 1);
    learn_(&agent_paper_sim, 3000, 7);
    const uint32_t learned = learned_digest(&agent_paper_sim);

    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_int_equal(st.sectors_per_slot, 2);
    assert_int_equal(st.slot_size, 2u * SECTOR_BYTES);
    const uint32_t record = learned_store_record_size(&agent_paper_sim);
    assert_true(record > SECTOR_BYTES && record <= st.slot_size);
    assert_int_equal(learned_store_save(&st, &agent_paper_sim, 12), FW_OK);
    assert_int_equal(fake_.erased_snbs, (1u << 24) | (1u << 25));  // slot 0 = sectors 20, 21

    // A reboot: a fresh agent, the store found again from flash.
    init_agent_(&agent_paper_sim, &robot_config_paper_sim, &agent_storage_paper_sim, 2);
    assert_int_not_equal(learned_digest(&agent_paper_sim), learned);
    learned_store_t again;
    assert_int_equal(learned_store_init(&again), FW_OK);
    assert_int_equal(again.newest, 0);
    uint32_t episodes = 0;
    assert_int_equal(learned_store_load(&again, &agent_paper_sim, &episodes), FW_OK);
    assert_int_equal(episodes, 12);
    assert_int_equal(learned_digest(&agent_paper_sim), learned);

    // More learning, the next save goes to the other slot (sectors 22, 23) and wins.
    learn_(&agent_paper_sim, 500, 8);
    const uint32_t more = learned_digest(&agent_paper_sim);
    fake_.erased_snbs = 0;
    assert_int_equal(learned_store_save(&again, &agent_paper_sim, 13), FW_OK);
    assert_int_equal(fake_.erased_snbs, (1u << 26) | (1u << 27));
    init_agent_(&agent_paper_sim, &robot_config_paper_sim, &agent_storage_paper_sim, 3);
    learned_store_t third;
    assert_int_equal(learned_store_init(&third), FW_OK);
    assert_int_equal(learned_store_load(&third, &agent_paper_sim, &episodes), FW_OK);
    assert_int_equal(episodes, 13);
    assert_int_equal(learned_digest(&agent_paper_sim), more);
}

// The paper-sim image on a 1 MB part: no region, the store says so, nothing is touched.
static void paper_sim_layout_on_a_1mb_part_has_no_region(void **state)
{
    (void)state;
    use_region_(0x08180000u, 20, 4, 1024);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_ERR_NOSYS);
    assert_int_equal(fake_.erased_snbs, 0);
}

static void paper_lab_record_persists_in_sectors_10_11(void **state)
{
    (void)state;
    use_region_(0x080C0000u, 10, 2, 1024);
    init_agent_(&agent_paper_lab, &robot_config_paper_lab, &agent_storage_paper_lab, 1);
    learn_(&agent_paper_lab, 2000, 9);
    const uint32_t learned = learned_digest(&agent_paper_lab);
    learned_store_t st;
    assert_int_equal(learned_store_init(&st), FW_OK);
    assert_true(learned_store_record_size(&agent_paper_lab) <= st.slot_size);
    assert_int_equal(learned_store_save(&st, &agent_paper_lab, 4), FW_OK);
    assert_int_equal(fake_.erased_snbs, 1u << 10);
    init_agent_(&agent_paper_lab, &robot_config_paper_lab, &agent_storage_paper_lab, 2);
    learned_store_t again;
    assert_int_equal(learned_store_init(&again), FW_OK);
    assert_int_equal(learned_store_load(&again, &agent_paper_lab, NULL), FW_OK);
    assert_int_equal(learned_digest(&agent_paper_lab), learned);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(paper_sim_record_does_not_fit_one_sector_slots, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(paper_sim_record_persists_in_bank2, setup_, stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(paper_sim_layout_on_a_1mb_part_has_no_region, setup_,
                                        stm32f4_fake_teardown),
        cmocka_unit_test_setup_teardown(paper_lab_record_persists_in_sectors_10_11, setup_,
                                        stm32f4_fake_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
