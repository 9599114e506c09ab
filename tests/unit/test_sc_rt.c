/* test_sc_rt.c: the Linux real-time helpers: the absolute sleep never returns early, stop
 * signals set the flag, the software watchdog expires when not fed, the device watchdog
 * reports a missing device by name. (SCHED_FIFO itself is not exercised here: a unit test must
 * not make the test runner real-time; the sonocomp benchmark run reports it.) */
#include "sc_test.h"

#include <errno.h>
#include <signal.h>
#include <string.h>
#include <time.h>

#include "sc_err.h"
#include "sc_rt.h"

static void absolute_sleep_returns_at_or_after_its_release_time(void **state)
{
    (void)state;
    sc_clock_dev c = sc_rt_clock_dev();
    uint64_t t0 = sc_clock_now_ns(&c);
    for (int i = 1; i <= 20; i++) {
        uint64_t release = t0 + (uint64_t)i * 1000000u; /* 1 ms apart */
        assert_int_equal(sc_clock_sleep_until_ns(&c, release), 0);
        assert_true(sc_clock_now_ns(&c) >= release);
    }
    /* a release time in the past returns at once without error */
    assert_int_equal(sc_clock_sleep_until_ns(&c, t0), 0);
}

static void stop_signals_set_the_flag(void **state)
{
    (void)state;
    assert_int_equal(sc_rt_install_signals(), 0);
    assert_false(sc_rt_stop_requested());
    raise(SIGTERM);
    assert_true(sc_rt_stop_requested());
    assert_int_equal(sc_rt_stop_signal(), SIGTERM);
}

static void unfed_software_watchdog_expires_and_counts(void **state)
{
    (void)state;
    sc_soft_watchdog w;
    sc_soft_watchdog_init(&w, 0);
    sc_watchdog_dev d = sc_soft_watchdog_dev(&w);
    /* start-up grace: 10 timeouts before the first kick */
    assert_int_equal(sc_watchdog_start(&d, 100u), 0);
    struct timespec grace = {0, 300 * 1000 * 1000};
    nanosleep(&grace, NULL);
    assert_int_equal(atomic_load(&w.expiries), 0u);
    assert_int_equal(sc_watchdog_start(&d, 20u), 0);
    assert_int_equal(sc_watchdog_kick(&d), 0);
    /* not fed for 10 timeouts: it must have expired at least once (checked 4x per timeout) */
    struct timespec nap = {0, 200 * 1000 * 1000};
    nanosleep(&nap, NULL);
    sc_soft_watchdog_stop(&w);
    assert_true(atomic_load(&w.expiries) >= 1u);
    assert_int_equal(sc_watchdog_start(&d, 0u), SC_ERR_RANGE);
}

static void missing_watchdog_device_is_not_found(void **state)
{
    (void)state;
    sc_dev_watchdog w;
    assert_int_equal(sc_dev_watchdog_open(&w, "/nonexistent/watchdog"), SC_ERR_NOT_FOUND);
    sc_dev_watchdog_close(&w, 1);
}

static void prefault_touches_every_page_without_harm(void **state)
{
    (void)state;
    static uint8_t buf[3 * 4096 + 17];
    memset(buf, 0, sizeof buf);
    sc_rt_prefault(buf, sizeof buf);
    for (size_t i = 0; i < sizeof buf; i++) {
        assert_int_equal(buf[i], 0);
    }
}

/* the advice covers whole 2 MiB pages inside the range only; a range without one is left as it
 * is (1); the kernel takes it (0), or, built without transparent huge pages, refuses it with
 * EINVAL (SC_ERR_IO); the data is untouched either way */
static void hugepage_advice_takes_whole_pages_and_keeps_the_data(void **state)
{
    (void)state;
    static uint8_t big[5u << 20]; /* holds at least one aligned 2 MiB page */
    static uint8_t small[(1u << 20) + 4096u];
    for (size_t i = 0; i < sizeof big; i += 4096u) {
        big[i] = (uint8_t)(i >> 12);
    }
    assert_int_equal(sc_rt_advise_hugepages(small, sizeof small), 1);
    assert_int_equal(sc_rt_advise_hugepages(NULL, sizeof big), 1);
    errno = 0;
    const int rc = sc_rt_advise_hugepages(big, sizeof big);
    assert_true(rc == 0 || (rc == SC_ERR_IO && errno == EINVAL));
    for (size_t i = 0; i < sizeof big; i += 4096u) {
        assert_int_equal(big[i], (uint8_t)(i >> 12));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(absolute_sleep_returns_at_or_after_its_release_time),
        cmocka_unit_test(stop_signals_set_the_flag),
        cmocka_unit_test(unfed_software_watchdog_expires_and_counts),
        cmocka_unit_test(missing_watchdog_device_is_not_found),
        cmocka_unit_test(prefault_touches_every_page_without_harm),
        cmocka_unit_test(hugepage_advice_takes_whole_pages_and_keeps_the_data),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
