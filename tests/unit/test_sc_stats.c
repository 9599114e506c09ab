/* test_sc_stats.c: duration histogram and percentiles. */
#include "sc_test.h"

#include "sc_stats.h"

static void bins_are_monotonic_and_cover_their_values(void **state)
{
    (void)state;
    uint32_t prev = 0;
    for (uint64_t us = 0; us < 5000000u; us += (us < 1000u ? 1u : 997u)) {
        uint32_t b = sc_stats_bin_of_us(us);
        assert_true(b >= prev);
        assert_true(us <= sc_stats_bin_upper_us(b));
        /* relative width of a bin is at most 1/16 */
        if (us >= 16u) {
            assert_true(sc_stats_bin_upper_us(b) - us <= us / 16u);
        }
        prev = b;
    }
}

static void percentiles_of_known_distribution_within_one_bin(void **state)
{
    (void)state;
    sc_stats s;
    sc_stats_reset(&s);
    /* 1..1000 us, one sample each */
    for (uint64_t us = 1; us <= 1000u; us++) {
        sc_stats_add(&s, us * 1000u);
    }
    assert_int_equal(s.count, 1000);
    assert_int_equal(s.worst_ns, 1000000u);
    assert_int_equal(s.best_ns, 1000u);
    uint64_t p50 = sc_stats_percentile_ns(&s, 500);
    uint64_t p99 = sc_stats_percentile_ns(&s, 990);
    assert_true(p50 >= 500000u && p50 <= 500000u + 500000u / 16u + 1000u);
    assert_true(p99 >= 990000u && p99 <= 1000000u);
    assert_int_equal(sc_stats_percentile_ns(&s, 1000), 1000000u);
    assert_int_equal(sc_stats_mean_ns(&s), 500500u);
}

static void empty_stats_report_zero(void **state)
{
    (void)state;
    sc_stats s;
    sc_stats_reset(&s);
    assert_int_equal(sc_stats_percentile_ns(&s, 990), 0);
    assert_int_equal(sc_stats_mean_ns(&s), 0);
}

static void huge_durations_land_in_last_bin(void **state)
{
    (void)state;
    sc_stats s;
    sc_stats_reset(&s);
    sc_stats_add(&s, UINT64_C(100) * 1000000000u);
    assert_int_equal(s.hist[SC_STATS_BINS - 1u], 1);
    assert_int_equal(s.worst_ns, UINT64_C(100) * 1000000000u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bins_are_monotonic_and_cover_their_values),
        cmocka_unit_test(percentiles_of_known_distribution_within_one_bin),
        cmocka_unit_test(empty_stats_report_zero),
        cmocka_unit_test(huge_durations_land_in_last_bin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
