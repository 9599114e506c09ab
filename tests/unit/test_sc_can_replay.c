/* test_sc_can_replay.c: the candump-log replay CAN device against a fake clock: frames come
 * out in file order no earlier than their log offset from the first frame (the clock starting
 * at the first recv), the end of the log answers WOULD_BLOCK forever, malformed lines are
 * refused and counted, a missing or frame-less log is refused at open, sends are counted. */
#include "sc_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sc_can_replay.h"
#include "sc_err.h"

static uint64_t fake_now(void *ctx)
{
    return *(const uint64_t *)ctx;
}

/* Writes text to a fresh temporary file; returns its path (static buffer per call site). */
static void write_log(char *path, size_t cap, const char *text)
{
    snprintf(path, cap, "/tmp/test_sc_can_replay_XXXXXX");
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *fp = fdopen(fd, "w");
    assert_non_null(fp);
    assert_int_equal(fputs(text, fp) >= 0, 1);
    assert_int_equal(fclose(fp), 0);
}

static const char k_log[] = "(1700000000.500000) vcan0 101#01\n"
                            "(1700000000.510000) vcan0 102#0203\n"
                            "(1700000000.510000) vcan0 103#04\n"
                            "(1700000001.500000) vcan0 12345678#0506070809\n";

static void frames_come_out_in_order_no_earlier_than_their_log_offset(void **state)
{
    (void)state;
    char path[64];
    write_log(path, sizeof path, k_log);
    uint64_t now = 5000000000u; /* arbitrary clock origin */
    sc_can_replay r;
    assert_int_equal(sc_can_replay_open(&r, path, fake_now, &now), 0);
    unlink(path);
    assert_int_equal(r.count, 4u);
    assert_int_equal(r.rejected, 0u);
    assert_int_equal(r.duration_ns, 1000000000u);
    sc_can_dev d = sc_can_replay_dev(&r);
    sc_can_frame f;

    /* the first recv starts the replay: the first frame (offset 0) is due at once */
    now += 123u; /* time spent before the frame loop (case load) does not count */
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x101u);
    assert_int_equal(f.ts_ns, 5000000123u);
    assert_int_equal(sc_can_recv(&d, &f), SC_ERR_WOULD_BLOCK);

    /* 1 ns before the second frame's 10 ms offset: nothing */
    now += 10000000u - 1u;
    assert_int_equal(sc_can_recv(&d, &f), SC_ERR_WOULD_BLOCK);
    /* at its offset: the second and third (same time stamp), in file order, then nothing */
    now += 1u;
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x102u);
    assert_int_equal(f.len, 2u);
    assert_int_equal(f.data[1], 0x03u);
    assert_int_equal(f.ts_ns, 5000000123u + 10000000u);
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x103u);
    assert_int_equal(sc_can_recv(&d, &f), SC_ERR_WOULD_BLOCK);
    assert_false(sc_can_replay_done(&r));

    /* late poll: the last frame is delivered with its on-bus time, not the poll time */
    now += 5000000000u;
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x12345678u);
    assert_int_equal(f.flags, SC_CAN_FLAG_EXT);
    assert_int_equal(f.len, 5u);
    assert_int_equal(f.ts_ns, 5000000123u + 1000000000u);
    assert_int_equal(r.received, 4u);
    assert_true(sc_can_replay_done(&r));
    sc_can_replay_close(&r);
}

static void end_of_log_answers_would_block_forever(void **state)
{
    (void)state;
    char path[64];
    write_log(path, sizeof path, "(0000000010.000000) can0 123#\n");
    uint64_t now = 0;
    sc_can_replay r;
    assert_int_equal(sc_can_replay_open(&r, path, fake_now, &now), 0);
    unlink(path);
    sc_can_dev d = sc_can_replay_dev(&r);
    sc_can_frame f;
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.len, 0u);
    for (int i = 0; i < 100; i++) {
        now += 1000000000u;
        assert_int_equal(sc_can_recv(&d, &f), SC_ERR_WOULD_BLOCK);
    }
    assert_int_equal(r.received, 1u);
    sc_can_replay_close(&r);
    sc_can_replay_close(&r); /* twice is harmless */
}

static void malformed_lines_are_refused_and_counted(void **state)
{
    (void)state;
    char path[64];
    write_log(path, sizeof path,
              "(1.000000) can0 101#01\n"                 /* good */
              "garbage\n"                                /* no time stamp */
              "(1.100000) can0 1#01\n"                   /* id not 3 or 8 digits */
              "(1.200000) can0 102#0\n"                  /* odd hex digits */
              "(1.300000) can0 103#010203040506070809\n" /* 9 bytes classic */
              "(1.400000) can0 104#AA\n");               /* good */
    uint64_t now = 0;
    sc_can_replay r;
    assert_int_equal(sc_can_replay_open(&r, path, fake_now, &now), 0);
    unlink(path);
    assert_int_equal(r.count, 2u);
    assert_int_equal(r.rejected, 4u);
    assert_int_equal(r.lines, 6u);
    assert_int_equal(r.last_reject_line, 5u);
    assert_int_equal(r.last_reject, SC_CDR_LENGTH);
    sc_can_dev d = sc_can_replay_dev(&r);
    sc_can_frame f;
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x101u);
    now += 400000000u; /* the good frames are 0.4 s apart: the bad ones take no time */
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x104u);
    assert_int_equal(f.data[0], 0xAAu);
    sc_can_replay_close(&r);
}

static void missing_or_frameless_logs_are_refused_at_open(void **state)
{
    (void)state;
    uint64_t now = 0;
    sc_can_replay r;
    assert_int_equal(sc_can_replay_open(&r, "/nonexistent/dir/x.log", fake_now, &now),
                     SC_ERR_NOT_FOUND);
    char path[64];
    write_log(path, sizeof path, "not a candump line\n\n");
    assert_int_equal(sc_can_replay_open(&r, path, fake_now, &now), SC_ERR_PARSE);
    assert_int_equal(r.count, 0u);
    assert_true(r.rejected >= 1u);
    unlink(path);
    sc_can_replay_close(&r);
}

static void sends_are_accepted_and_counted(void **state)
{
    (void)state;
    char path[64];
    write_log(path, sizeof path, k_log);
    sc_can_replay r;
    assert_int_equal(sc_can_replay_open(&r, path, NULL, NULL), 0); /* real clock */
    unlink(path);
    sc_can_dev d = sc_can_replay_dev(&r);
    sc_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = 0x200;
    f.len = 8;
    assert_int_equal(sc_can_send(&d, &f), 0);
    assert_int_equal(sc_can_send(&d, &f), 0);
    f.len = 9; /* not a classic length */
    assert_int_equal(sc_can_send(&d, &f), SC_ERR_INVALID_ARG);
    assert_int_equal(r.sent, 2u);
    sc_can_state st = SC_CAN_STATE_STOPPED;
    assert_int_equal(sc_can_get_state(&d, &st, NULL), 0);
    assert_int_equal(st, SC_CAN_STATE_ERROR_ACTIVE);
    /* with the real clock the first frame is due at the first poll */
    assert_int_equal(sc_can_recv(&d, &f), 0);
    assert_int_equal(f.id, 0x101u);
    sc_can_replay_close(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frames_come_out_in_order_no_earlier_than_their_log_offset),
        cmocka_unit_test(end_of_log_answers_would_block_forever),
        cmocka_unit_test(malformed_lines_are_refused_and_counted),
        cmocka_unit_test(missing_or_frameless_logs_are_refused_at_open),
        cmocka_unit_test(sends_are_accepted_and_counted),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
