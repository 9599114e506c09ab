#define _POSIX_C_SOURCE 200809L
/* test_sc_udpcan.c: CAN over UDP (platform/linux/sc_udpcan.h): round trip, refusals, and a
 * frame through real localhost sockets. */
#include "sc_test.h"

#include <string.h>
#include <time.h>

#include "sc_err.h"
#include "sc_udpcan.h"

static void encode_decode_round_trip_classic_and_fd(void **state)
{
    (void)state;
    sc_can_frame f = {.id = 0x1abcdef0u & 0x1fffffffu, .len = 64,
                      .flags = SC_CAN_FLAG_EXT | SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS};
    for (int i = 0; i < 64; i++) {
        f.data[i] = (uint8_t)(i * 7);
    }
    uint8_t b[SC_UDPCAN_SIZE];
    assert_int_equal(sc_udpcan_encode(&f, b), SC_OK);
    sc_can_frame g;
    assert_int_equal(sc_udpcan_decode(b, sizeof b, &g), SC_OK);
    assert_int_equal(g.id, f.id);
    assert_int_equal(g.len, 64);
    assert_memory_equal(g.data, f.data, 64);
    sc_can_frame c = {.id = 0x123, .len = 3, .data = {1, 2, 3}};
    assert_int_equal(sc_udpcan_encode(&c, b), SC_OK);
    assert_int_equal(sc_udpcan_decode(b, sizeof b, &g), SC_OK);
    assert_int_equal(g.len, 3);
}

static void decode_refuses_size_magic_length_flags_padding_and_id(void **state)
{
    (void)state;
    sc_can_frame c = {.id = 0x123, .len = 8};
    uint8_t b[SC_UDPCAN_SIZE], x[SC_UDPCAN_SIZE];
    assert_int_equal(sc_udpcan_encode(&c, b), SC_OK);
    sc_can_frame g;
    assert_int_equal(sc_udpcan_decode(b, sizeof b - 1u, &g), SC_ERR_RANGE);
    const struct {
        size_t off;
        uint8_t v;
    } bad[] = {{0, 0}, {8, 9}, {9, 0x80}, {10, 1}, {75, 1}, {5, 0x08}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        memcpy(x, b, sizeof b);
        x[bad[i].off] = bad[i].v;
        assert_int_equal(sc_udpcan_decode(x, sizeof x, &g), SC_ERR_RANGE);
    }
    sc_can_frame fd_bad = {.id = 1, .len = 13, .flags = SC_CAN_FLAG_FD};
    assert_int_equal(sc_udpcan_encode(&fd_bad, b), SC_ERR_INVALID_ARG);
}

static void a_frame_crosses_localhost(void **state)
{
    (void)state;
    sc_udpcan rx, tx;
    uint16_t port = 0;
    for (port = 47900; port < 48000; port++) {
        if (sc_udpcan_open_rx(&rx, port) == SC_OK) {
            break;
        }
        sc_udpcan_close(&rx);
    }
    assert_true(port < 48000);
    assert_int_equal(sc_udpcan_open_tx(&tx, "127.0.0.1", port), SC_OK);
    const sc_can_dev td = sc_udpcan_dev(&tx), rd = sc_udpcan_dev(&rx);
    sc_can_frame f = {.id = 0x42, .len = 2, .data = {0xaa, 0x55}}, g;
    assert_int_equal(sc_can_send(&td, &f), SC_OK);
    int rc = SC_ERR_WOULD_BLOCK;
    for (int i = 0; i < 200 && rc == SC_ERR_WOULD_BLOCK; i++) {
        rc = sc_can_recv(&rd, &g);
        if (rc == SC_ERR_WOULD_BLOCK) {
            const struct timespec ts = {0, 1000000};
            nanosleep(&ts, NULL);
        }
    }
    assert_int_equal(rc, SC_OK);
    assert_int_equal(g.id, 0x42u);
    assert_int_equal(g.data[1], 0x55);
    assert_int_equal(sc_can_recv(&rd, &g), SC_ERR_WOULD_BLOCK);
    sc_udpcan_close(&tx);
    sc_udpcan_close(&rx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(encode_decode_round_trip_classic_and_fd),
        cmocka_unit_test(decode_refuses_size_magic_length_flags_padding_and_id),
        cmocka_unit_test(a_frame_crosses_localhost),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
