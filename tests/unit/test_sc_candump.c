/* test_sc_candump.c: candump -l lines: real can-utils lines parse, every frame kind round
 * trips bit for bit, every malformed line is rejected with its reason and counted. */
#include "sc_test.h"

#include <stdio.h>
#include <string.h>

#include "sc_candump.h"
#include "sc_err.h"

static int parse(const char *s, sc_candump_rec *r, sc_candump_reject *why)
{
    return sc_candump_parse_line(s, strlen(s), r, why);
}

static void lines_written_by_candump_parse_to_the_right_frames(void **state)
{
    (void)state;
    sc_candump_rec r;
    sc_candump_reject why;
    /* the examples of can-utils' documentation */
    assert_int_equal(parse("(1436509052.249713) vcan0 123#DEADBEEF\n", &r, &why), 0);
    assert_int_equal(r.ts_us, UINT64_C(1436509052249713));
    assert_int_equal(r.frame.ts_ns, UINT64_C(1436509052249713000));
    assert_string_equal(r.iface, "vcan0");
    assert_int_equal(r.frame.id, 0x123);
    assert_int_equal(r.frame.flags, 0);
    assert_int_equal(r.frame.len, 4);
    const uint8_t want[4] = {0xDE, 0xAD, 0xBE, 0xEF};
    assert_memory_equal(r.frame.data, want, 4);

    assert_int_equal(parse("(1436509052.249713) vcan0 123##1DEADBEEF", &r, &why), 0);
    assert_int_equal(r.frame.flags, SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS);
    assert_int_equal(r.frame.len, 4);

    assert_int_equal(parse("(0000000001.000001) can0 1F334455#1122334455667788\r\n", &r, &why), 0);
    assert_int_equal(r.frame.id, 0x1F334455u);
    assert_int_equal(r.frame.flags, SC_CAN_FLAG_EXT);
    assert_int_equal(r.frame.len, 8);
    assert_int_equal(r.ts_us, 1000001u);

    assert_int_equal(parse("(1.000000) can0 123#", &r, &why), 0); /* zero-length frame */
    assert_int_equal(r.frame.len, 0);
    assert_int_equal(parse("(1.000000) can0 123#R", &r, &why), 0);
    assert_int_equal(r.frame.flags, SC_CAN_FLAG_RTR);
    assert_int_equal(parse("(1.000000) can0 123#R3", &r, &why), 0);
    assert_int_equal(r.frame.len, 3);
    assert_int_equal(parse("(1.000000) can0 123#11.22.33", &r, &why), 0); /* dotted bytes */
    assert_int_equal(r.frame.len, 3);
    assert_int_equal(r.frame.data[2], 0x33);
    assert_int_equal(parse("(1.000000) can0 123#1122334455667788_C", &r, &why), 0);
    assert_int_equal(r.frame.len, 8);
    assert_int_equal(parse("(1.000000) can0 123#11 R", &r, &why), 0); /* candump -x marker */
    assert_int_equal(parse("(1.000000) can0 123##0", &r, &why), 0);   /* empty FD frame */
    assert_int_equal(r.frame.flags, SC_CAN_FLAG_FD);

    /* an error frame: bus-off + controller passive */
    assert_int_equal(parse("(1.000000) can0 20000044#0030000000000000", &r, &why), 0);
    assert_int_equal(r.frame.flags, SC_CAN_FLAG_ERR);
    assert_int_equal(r.frame.id, SC_CAN_ERRF_BUS_OFF | SC_CAN_ERRF_PASSIVE);
}

static void every_frame_kind_round_trips_bit_for_bit(void **state)
{
    (void)state;
    sc_candump_rec in[6];
    memset(in, 0, sizeof in);
    for (int i = 0; i < 6; i++) {
        strcpy(in[i].iface, i % 2 ? "vcan0" : "can_fd_15chars_");
        in[i].ts_us = UINT64_C(1700000000000000) + (uint64_t)i * 16667u;
        in[i].frame.ts_ns = in[i].ts_us * 1000u;
    }
    in[0].frame = (sc_can_frame){.id = 0x100, .len = 8, .data = {1, 2, 3, 4, 5, 6, 7, 0xFF}};
    in[1].frame = (sc_can_frame){.id = 0x1ABCDEF0, .len = 3, .flags = SC_CAN_FLAG_EXT};
    in[2].frame = (sc_can_frame){.id = 0x110, .len = 20, .flags = SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS};
    for (int k = 0; k < 20; k++) {
        in[2].frame.data[k] = (uint8_t)(k * 13);
    }
    in[3].frame = (sc_can_frame){.id = 0x7FF, .len = 64, .flags = SC_CAN_FLAG_FD};
    memset(in[3].frame.data, 0xA5, 64);
    in[4].frame = (sc_can_frame){.id = 0x055, .len = 2, .flags = SC_CAN_FLAG_RTR};
    in[5].frame = (sc_can_frame){.id = SC_CAN_ERRF_BUS_OFF | SC_CAN_ERRF_WARNING |
                                       SC_CAN_ERRF_PROTOCOL | SC_CAN_ERRF_RESTARTED,
                                 .len = 8,
                                 .flags = SC_CAN_FLAG_ERR};
    for (int i = 0; i < 6; i++) {
        in[i].frame.ts_ns = in[i].ts_us * 1000u;
        char line[SC_CANDUMP_LINE_MAX + 64];
        const int n = sc_candump_format(&in[i], line, sizeof line);
        assert_true(n > 0);
        assert_int_equal((size_t)n, strlen(line));
        sc_candump_rec out;
        sc_candump_reject why;
        assert_int_equal(sc_candump_parse_line(line, (size_t)n, &out, &why), 0);
        assert_int_equal(out.ts_us, in[i].ts_us);
        assert_string_equal(out.iface, in[i].iface);
        assert_int_equal(out.frame.id, in[i].frame.id);
        assert_int_equal(out.frame.flags, in[i].frame.flags);
        assert_int_equal(out.frame.len, in[i].frame.len);
        assert_int_equal(out.frame.ts_ns, in[i].frame.ts_ns);
        if (!(in[i].frame.flags & (SC_CAN_FLAG_RTR | SC_CAN_FLAG_ERR))) {
            assert_memory_equal(out.frame.data, in[i].frame.data, in[i].frame.len);
        }
        /* and the line itself is reproduced */
        char again[SC_CANDUMP_LINE_MAX + 64];
        assert_int_equal(sc_candump_format(&out, again, sizeof again), n);
        assert_string_equal(again, line);
    }
    char small[20];
    assert_int_equal(sc_candump_format(&in[0], small, sizeof small), SC_ERR_NO_SPACE);
    sc_candump_rec bad = in[0];
    bad.frame.len = 9;
    char line[300];
    assert_int_equal(sc_candump_format(&bad, line, sizeof line), SC_ERR_INVALID_ARG);
    bad = in[0];
    bad.iface[0] = '\0';
    assert_int_equal(sc_candump_format(&bad, line, sizeof line), SC_ERR_INVALID_ARG);
}

static void every_malformed_line_is_rejected_with_its_reason(void **state)
{
    (void)state;
    static const struct {
        const char *line;
        sc_candump_reject why;
    } bad[] = {
        {"", SC_CDR_EMPTY},
        {"   \r\n", SC_CDR_EMPTY},
        {"1436509052.249713 vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(1436509052) vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(1436509052.2497) vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(1436509052.2497130) vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(.249713) vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(99999999999999.249713) vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(1436509052.249713 vcan0 123#00", SC_CDR_TIMESTAMP},
        {"(1.000000)vcan0 123#00", SC_CDR_IFACE},
        {"(1.000000) ", SC_CDR_IFACE},
        {"(1.000000) a_name_of_16_chars 123#00", SC_CDR_IFACE},
        {"(1.000000) vc\x01n0 123#00", SC_CDR_IFACE},
        {"(1.000000) vcan0", SC_CDR_ID},
        {"(1.000000) vcan0 12#00", SC_CDR_ID},
        {"(1.000000) vcan0 1234#00", SC_CDR_ID},
        {"(1.000000) vcan0 800#00", SC_CDR_ID},
        {"(1.000000) vcan0 12G#00", SC_CDR_ID},
        {"(1.000000) vcan0 123456789#00", SC_CDR_ID},
        {"(1.000000) vcan0 4FFFFFFF#00", SC_CDR_ID},
        {"(1.000000) vcan0 60000000#00", SC_CDR_ID},
        {"(1.000000) vcan0 123", SC_CDR_SEPARATOR},
        {"(1.000000) vcan0 123 00", SC_CDR_SEPARATOR},
        {"(1.000000) vcan0 123###00", SC_CDR_SEPARATOR},
        {"(1.000000) vcan0 20000004##00", SC_CDR_SEPARATOR},
        {"(1.000000) vcan0 123#0", SC_CDR_DATA},
        {"(1.000000) vcan0 123#0G", SC_CDR_DATA},
        {"(1.000000) vcan0 123#.00", SC_CDR_DATA},
        {"(1.000000) vcan0 123#00..11", SC_CDR_DATA},
        {"(1.000000) vcan0 123#00.", SC_CDR_DATA},
        {"(1.000000) vcan0 123#001122334455667788", SC_CDR_LENGTH},
        {"(1.000000) vcan0 123##1001122334455667788", SC_CDR_LENGTH}, /* 9 bytes: not FD */
        {"(1.000000) vcan0 123##", SC_CDR_FD_FLAGS},
        {"(1.000000) vcan0 123##X00", SC_CDR_FD_FLAGS},
        {"(1.000000) vcan0 123#R9", SC_CDR_DLC},
        {"(1.000000) vcan0 123#0011_9", SC_CDR_DLC},
        {"(1.000000) vcan0 123#0011223344556677_8", SC_CDR_DLC},
        {"(1.000000) vcan0 123#0011223344556677_", SC_CDR_DLC},
        {"(1.000000) vcan0 20000004#R", SC_CDR_DLC},
        {"(1.000000) vcan0 123#00 X", SC_CDR_TRAILING},
        {"(1.000000) vcan0 123#00 R R", SC_CDR_TRAILING},
        {"(1.000000) vcan0 123#R1x", SC_CDR_TRAILING},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        sc_candump_rec r;
        sc_candump_reject why = SC_CDR_OK;
        const int rc = parse(bad[i].line, &r, &why);
        if (rc != SC_ERR_PARSE || why != bad[i].why) {
            print_error("line %zu \"%s\": rc %d reason %s, want %s\n", i, bad[i].line, rc,
                        sc_candump_reject_name(why), sc_candump_reject_name(bad[i].why));
            fail();
        }
    }
    char longline[400];
    memset(longline, '1', sizeof longline);
    sc_candump_rec r;
    sc_candump_reject why;
    assert_int_equal(sc_candump_parse_line(longline, sizeof longline, &r, &why), SC_ERR_PARSE);
    assert_int_equal(why, SC_CDR_LINE_TOO_LONG);
    for (int k = 0; k < (int)SC_CDR_COUNT; k++) {
        assert_string_not_equal(sc_candump_reject_name((sc_candump_reject)k), "?");
    }
}

static void the_reader_skips_and_counts_bad_lines_and_keeps_good_ones(void **state)
{
    (void)state;
    char content[2048];
    size_t n = 0;
    const char *parts[] = {
        "(1.000000) vcan0 100#01\n",
        "garbage\n",
        "\n",
        "(1.000001) vcan0 101#02\n",
    };
    for (size_t i = 0; i < 4; i++) {
        memcpy(content + n, parts[i], strlen(parts[i]));
        n += strlen(parts[i]);
    }
    memset(content + n, 'x', 600); /* an overlong line */
    n += 600;
    content[n++] = '\n';
    const char nul_line[] = "(1.000002) vcan0 102#03\0trailing\n";
    memcpy(content + n, nul_line, sizeof nul_line - 1u);
    n += sizeof nul_line - 1u;
    const char *last = "(1.000003) vcan0 103#04"; /* no final newline */
    memcpy(content + n, last, strlen(last));
    n += strlen(last);

    FILE *fp = fmemopen(content, n, "r");
    assert_non_null(fp);
    sc_candump_reader rd;
    sc_candump_reader_init(&rd, fp);
    sc_candump_rec r;
    uint32_t ids[4];
    int got = 0;
    int rc;
    while ((rc = sc_candump_reader_next(&rd, &r)) == 0) {
        assert_true(got < 4);
        ids[got++] = r.frame.id;
    }
    assert_int_equal(rc, SC_ERR_NOT_FOUND);
    fclose(fp);
    assert_int_equal(got, 3);
    assert_int_equal(ids[0], 0x100);
    assert_int_equal(ids[1], 0x101);
    assert_int_equal(ids[2], 0x103);
    assert_int_equal(rd.line_no, 7);
    assert_int_equal(rd.records, 3);
    assert_int_equal(rd.rejected[SC_CDR_TIMESTAMP], 1);
    assert_int_equal(rd.rejected[SC_CDR_EMPTY], 1);
    assert_int_equal(rd.rejected[SC_CDR_LINE_TOO_LONG], 1);
    assert_int_equal(rd.rejected[SC_CDR_TRAILING], 1); /* embedded NUL */
    assert_int_equal(sc_candump_reader_rejected_total(&rd), 4);
    assert_int_equal(rd.last_reject_line, 6);
}

static void random_garbage_never_crashes_and_is_always_classified(void **state)
{
    (void)state;
    /* mutate a valid line byte by byte: every result is either a record or a named reject */
    const char *base = "(1436509052.249713) vcan0 123##1DEADBEEF00112233445566778899AABB";
    uint32_t seed = 1;
    char buf[128];
    for (int it = 0; it < 200000; it++) {
        const size_t n = strlen(base);
        memcpy(buf, base, n);
        for (int k = 0; k < 3; k++) {
            seed = seed * 1103515245u + 12345u;
            const size_t pos = (seed >> 8) % n;
            seed = seed * 1103515245u + 12345u;
            buf[pos] = (char)(seed >> 16);
        }
        seed = seed * 1103515245u + 12345u;
        const size_t len = (seed >> 8) % (n + 1u);
        sc_candump_rec r;
        sc_candump_reject why = SC_CDR_COUNT;
        const int rc = sc_candump_parse_line(buf, len, &r, &why);
        assert_true((rc == 0 && why == SC_CDR_OK) ||
                    (rc == SC_ERR_PARSE && why > SC_CDR_OK && why < SC_CDR_COUNT));
        if (rc == 0) {
            assert_true(sc_can_len_valid(r.frame.len, r.frame.flags) ||
                        (r.frame.flags & SC_CAN_FLAG_ERR));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lines_written_by_candump_parse_to_the_right_frames),
        cmocka_unit_test(every_frame_kind_round_trips_bit_for_bit),
        cmocka_unit_test(every_malformed_line_is_rejected_with_its_reason),
        cmocka_unit_test(the_reader_skips_and_counts_bad_lines_and_keeps_good_ones),
        cmocka_unit_test(random_garbage_never_crashes_and_is_always_classified),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
