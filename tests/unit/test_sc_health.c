/* test_sc_health.c: the health state machine is a function of its fault bits. */
#include "sc_test.h"

#include <string.h>

#include "sc_health.h"

static void starts_in_init_and_runs_when_ready(void **state)
{
    (void)state;
    sc_health h;
    sc_health_init(&h);
    assert_int_equal(h.state, SC_HEALTH_INIT);
    sc_health_set_ready(&h, 1);
    assert_int_equal(h.state, SC_HEALTH_RUNNING);
    assert_int_equal(h.transitions, 1);
}

static void degrading_fault_degrades_and_clears(void **state)
{
    (void)state;
    sc_health h;
    sc_health_init(&h);
    sc_health_set_ready(&h, 1);
    sc_health_raise(&h, SC_FAULT_TRACKER_TIMEOUT);
    assert_int_equal(h.state, SC_HEALTH_DEGRADED);
    sc_health_raise(&h, SC_FAULT_TRACKER_TIMEOUT); /* not a new edge */
    assert_int_equal(h.raised[SC_FAULT_TRACKER_TIMEOUT], 1);
    sc_health_clear(&h, SC_FAULT_TRACKER_TIMEOUT);
    assert_int_equal(h.state, SC_HEALTH_RUNNING);
    assert_int_equal(h.prev_state, SC_HEALTH_DEGRADED);
}

static void fatal_fault_wins_over_everything(void **state)
{
    (void)state;
    sc_health h;
    sc_health_init(&h);
    sc_health_raise(&h, SC_FAULT_NO_CASE);
    assert_int_equal(h.state, SC_HEALTH_FAULT); /* even before ready */
    sc_health_set_ready(&h, 1);
    sc_health_raise(&h, SC_FAULT_DEADLINE);
    assert_int_equal(h.state, SC_HEALTH_FAULT);
    sc_health_clear(&h, SC_FAULT_NO_CASE);
    assert_int_equal(h.state, SC_HEALTH_DEGRADED);
}

static void every_fault_has_a_unique_name_and_a_severity(void **state)
{
    (void)state;
    for (int i = 0; i < SC_FAULT_COUNT; i++) {
        const char *n = sc_fault_name((sc_fault)i);
        assert_true(strncmp(n, "SC_FAULT_", 9) == 0);
        for (int j = 0; j < i; j++) {
            assert_string_not_equal(n, sc_fault_name((sc_fault)j));
        }
    }
    assert_true(sc_fault_is_fatal(SC_FAULT_CAN_BUS_OFF));
    assert_false(sc_fault_is_fatal(SC_FAULT_DEADLINE));
    assert_string_equal(sc_health_state_name(SC_HEALTH_DEGRADED), "degraded");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(starts_in_init_and_runs_when_ready),
        cmocka_unit_test(degrading_fault_degrades_and_clears),
        cmocka_unit_test(fatal_fault_wins_over_everything),
        cmocka_unit_test(every_fault_has_a_unique_name_and_a_severity),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
