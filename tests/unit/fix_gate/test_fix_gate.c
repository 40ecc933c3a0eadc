// SPDX-License-Identifier: MIT
// Tests of the gate that decides which fresh Cricket fixes the robot believes (robot/fix_gate.h).
#include "test_common.h"

#include "robot/fix_gate.h"

// A fresh fix in paper-lab's 4.3 x 3.2 m arena.
static fix_gate_in_t fix_(uint64_t now_us, float x, float y)
{
    const fix_gate_in_t in = {now_us, x, y, 4.3f, 3.2f};
    return in;
}

static void test_first_fix_inside_is_the_reference(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, -0.2f, 1.0f);  // outside: never a reference
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(1000000u, 1.0f, 3.3f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    assert_int_equal(g.refused_outside, 2);
    in = fix_(1100000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_true(g.have_ref);
}

static void test_dead_reckoning_moves_the_reference(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // A 0.5 m step along +x, in MOTOR_STATUS slices: the fix there is believed; one as far the
    // other way is not, nor one 0.5 m to the side, although each is as far from the last fix as
    // the wheels drove.
    for (int i = 0; i < 10; i++) {
        fix_gate_travel(&g, 0.05f, 0.0f, true);
    }
    in = fix_(3000000u, 1.52f, 0.99f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    fix_gate_travel(&g, 0.5f, 0.0f, true);
    in = fix_(5000000u, 1.02f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(5000000u, 2.02f, 1.5f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    // Slip: wheels that turned 0.5 m against a wall may not have moved the robot: within
    // FIX_GATE_JUMP_M + FIX_GATE_SLIP * 0.5 m = 0.425 m of dead reckoning, believed.
    in = fix_(5500000u, 1.62f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // Driven forward along +y, backed off, turned to -x and driven: dead reckoning follows each
    // leg with the heading of its moment.
    fix_gate_travel(&g, 0.6f, 1.5707964f, true);
    fix_gate_travel(&g, -0.2f, 1.5707964f, true);
    fix_gate_travel(&g, 0.3f, 3.1415927f, true);
    in = fix_(6000000u, 1.33f, 1.41f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // Standing (a turn in place does not travel), a fix 0.6 m away is refused, although 1.5 m/s
    // for the time since (the rule before the gate) would have allowed it.
    in = fix_(8000000u, 1.93f, 1.41f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
}

static void test_travel_on_an_untrusted_heading_has_no_direction(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // The straight leg after a boot: the gyro reads 0, the robot drives 0.4 m along +y. Any fix
    // within 0.3 + 1.25 * 0.4 m of the leg's start is believed, in any direction.
    fix_gate_travel(&g, 0.4f, 0.0f, false);
    in = fix_(3000000u, 1.0f, 1.4f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_false(g.blind);  // a believed fix: dead reckoning starts again from it
    fix_gate_travel(&g, 0.4f, 0.0f, false);
    in = fix_(5000000u, 1.0f, 2.3f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
}

static void test_a_lone_wrong_fix_is_refused_and_forgotten(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // A reflection puts one fix 2 m away; solved again each period from the same ranges, it
    // stays refused however long it lasts, and never becomes a move.
    for (uint64_t t = 2000000u; t < 9000000u; t += 20000u) {
        in = fix_(t, 3.0f, 1.0f);
        assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    }
    assert_int_equal(g.refused_jump, 1);
    in = fix_(9100000u, 1.01f, 0.99f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_false(g.have_suspect);
}

static void test_fixes_that_keep_agreeing_elsewhere_are_a_move(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_false(g.corroborated);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);  // the same fix again
    assert_false(g.corroborated);
    in = fix_(1500000u, 1.01f, 0.99f);  // new ranges agree
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_true(g.corroborated);
    // Picked up and put down 2 m away: fresh fixes there, each a little different (noise).
    in = fix_(2000000u, 3.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(3000000u, 3.01f, 1.0f);  // agrees, but not for FIX_GATE_CONFIRM_US yet
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(2000000u + FIX_GATE_CONFIRM_US, 2.99f, 1.01f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_MOVED);
    assert_true(g.have_ref && g.dr_x == 2.99f && g.travel_m == 0.0f);
    in = fix_(2100000u + FIX_GATE_CONFIRM_US, 3.0f, 1.0f);  // and then believed
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // Wrong fixes that disagree with each other start the wait again each time.
    in = fix_(8000000u, 0.5f, 2.5f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(9000000u, 1.5f, 0.2f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(10500000u, 0.5f, 2.5f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    assert_int_equal(g.refused_jump, 4);
}

static void test_fixes_that_keep_agreeing_after_a_drive_are_a_drift(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    // A 0.5 m step on a heading the gyro reads as +x while the robot drove 60 degrees off it.
    fix_gate_travel(&g, 0.5f, 0.0f, true);
    in = fix_(3000000u, 1.25f, 1.43f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(3000000u + FIX_GATE_CONFIRM_US, 1.26f, 1.44f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_DRIFTED);
    assert_int_equal(g.drifts, 1);
    assert_true(g.dr_x == 1.26f && g.travel_m == 0.0f);
}

static void test_a_wrong_first_fix_is_no_move(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    // The first fix after the operator's START is 0.5 m off (a reflection); the good fixes that
    // follow disagree with it: once they agree for FIX_GATE_CONFIRM_US they are believed, and
    // the robot, whose wheels never turned, was not carried: nothing corroborated the wrong fix.
    fix_gate_in_t in = fix_(1000000u, 0.9f, 0.1f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    in = fix_(2000000u, 0.53f, 0.49f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_REFUSE);
    in = fix_(2000000u + FIX_GATE_CONFIRM_US, 0.54f, 0.48f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_DRIFTED);
}

static void test_forget_believes_the_next_fix(void **state)
{
    (void)state;
    fix_gate_t g;
    fix_gate_init(&g);
    fix_gate_in_t in = fix_(1000000u, 1.0f, 1.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    fix_gate_forget(&g);  // the operator put the robot down elsewhere
    in = fix_(1100000u, 4.0f, 3.0f);
    assert_int_equal(fix_gate_check(&g, &in), FIX_GATE_ACCEPT);
    assert_int_equal(g.refused_jump, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_first_fix_inside_is_the_reference),
        cmocka_unit_test(test_dead_reckoning_moves_the_reference),
        cmocka_unit_test(test_travel_on_an_untrusted_heading_has_no_direction),
        cmocka_unit_test(test_a_lone_wrong_fix_is_refused_and_forgotten),
        cmocka_unit_test(test_fixes_that_keep_agreeing_elsewhere_are_a_move),
        cmocka_unit_test(test_fixes_that_keep_agreeing_after_a_drive_are_a_drift),
        cmocka_unit_test(test_a_wrong_first_fix_is_no_move),
        cmocka_unit_test(test_forget_believes_the_next_fix),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
