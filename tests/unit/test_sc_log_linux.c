/* test_sc_log_linux.c: log records become one logfmt line each; a stalled output never blocks
 * the producer: records beyond the ring are dropped and counted, none is lost silently. */
#include "sc_test.h"

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "sc_err.h"
#include "sc_log_linux.h"

static void a_record_formats_as_one_logfmt_line(void **state)
{
    (void)state;
    const sc_log_linux_rec r = {.wall_ns = INT64_C(1700000000123456789),
                                .level = SC_LOG_WARN,
                                .event = "tracker_timeout",
                                .err = SC_ERR_TIMEOUT,
                                .a = -3,
                                .b = 42};
    char buf[256];
    size_t n = sc_log_linux_format(buf, sizeof buf, &r);
    assert_int_equal(n, strlen(buf));
    assert_string_equal(buf, "ts=2023-11-14T22:13:20.123Z level=warn event=tracker_timeout "
                             "err=SC_ERR_TIMEOUT a=-3 b=42");
    const sc_log_linux_rec ok = {.wall_ns = 0, .level = SC_LOG_INFO, .event = "case_loaded"};
    sc_log_linux_format(buf, sizeof buf, &ok);
    assert_string_equal(buf, "ts=1970-01-01T00:00:00.000Z level=info event=case_loaded a=0 b=0");
    /* a tiny buffer truncates, never overflows */
    char tiny[8];
    n = sc_log_linux_format(tiny, sizeof tiny, &r);
    assert_true(n < sizeof tiny);
    assert_int_equal(tiny[n], '\0');
}

static sc_log_linux g_log;

static void stalled_output_drops_and_counts_without_blocking(void **state)
{
    (void)state;
    int p[2];
    assert_int_equal(pipe(p), 0);
    assert_int_equal(sc_log_linux_start(&g_log, p[1], SC_LOG_INFO), 0);
    sc_log_dev dev = sc_log_linux_dev(&g_log);
    /* nobody reads the pipe: the writer thread blocks once it is full (64 KiB, about 700 lines),
     * then the ring (256) fills and the producer must drop */
    const uint32_t n = 5000u;
    for (uint32_t i = 0; i < n; i++) {
        sc_log(&dev, SC_LOG_INFO, "spam", 0, (int64_t)i, 0);
    }
    sc_log(&dev, SC_LOG_DEBUG, "below_level", 0, 0, 0); /* filtered: neither written nor dropped */
    assert_true(sc_log_linux_dropped(&g_log) > 0u);
    /* unblock the writer: read everything in the background of the stop */
    int fl = fcntl(p[0], F_GETFL);
    fcntl(p[0], F_SETFL, fl | O_NONBLOCK);
    uint64_t lines = 0;
    char buf[65536];
    for (int spins = 0; spins < 2000; spins++) {
        ssize_t r = read(p[0], buf, sizeof buf);
        if (r > 0) {
            for (ssize_t i = 0; i < r; i++) {
                lines += buf[i] == '\n';
            }
            spins = 0;
        } else if (lines + sc_log_linux_dropped(&g_log) >= n) {
            break;
        } else {
            usleep(1000);
        }
    }
    sc_log_linux_stop(&g_log);
    for (;;) {
        ssize_t r = read(p[0], buf, sizeof buf);
        if (r <= 0) {
            break;
        }
        for (ssize_t i = 0; i < r; i++) {
            lines += buf[i] == '\n';
        }
    }
    assert_int_equal(lines + sc_log_linux_dropped(&g_log), n);
    close(p[0]);
    close(p[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_record_formats_as_one_logfmt_line),
        cmocka_unit_test(stalled_output_drops_and_counts_without_blocking),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
