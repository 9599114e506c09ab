/* test_sc_e2e.c: CRC-8 SAE J1850 check values and every E2E receive outcome. */
#include "sc_test.h"

#include <string.h>

#include "sc_e2e.h"
#include "sc_err.h"

/* SAE J1850 / AUTOSAR Crc_CalculateCRC8 = init 0xFF, final XOR 0xFF. */
static uint8_t crc8_autosar(const uint8_t *d, size_t n)
{
    return (uint8_t)(sc_crc8_j1850(d, n, 0xFFu) ^ 0xFFu);
}

/* Bitwise reference (independent of the table in sc_e2e.c). */
static uint8_t crc8_bitwise(const uint8_t *d, size_t n, uint8_t crc)
{
    for (size_t i = 0; i < n; i++) {
        crc ^= d[i];
        for (int b = 0; b < 8; b++) {
            crc = (uint8_t)((crc & 0x80u) ? (uint8_t)(crc << 1) ^ 0x1Du : (uint8_t)(crc << 1));
        }
    }
    return crc;
}

static void crc8_matches_sae_j1850_and_autosar_check_values(void **state)
{
    (void)state;
    /* CRC catalogue (reveng) CRC-8/SAE-J1850: check over "123456789" = 0x4B. */
    const uint8_t check[] = "123456789";
    assert_int_equal(crc8_autosar(check, 9), 0x4B);
    /* Same polynomial with start 0x00 and XOR 0x00, the parameters profile 1 uses in effect:
     * the catalogue's CRC-8/GSM-A, check 0x37. */
    assert_int_equal(sc_crc8_j1850(check, 9, 0x00u), 0x37);
    /* AUTOSAR SWS CRC Library, 8-bit SAE J1850 table of check values. */
    static const struct {
        uint8_t d[9];
        size_t n;
        uint8_t crc;
    } v[] = {
        {{0x00, 0x00, 0x00, 0x00}, 4, 0x59},
        {{0xF2, 0x01, 0x83}, 3, 0x37},
        {{0x0F, 0xAA, 0x00, 0x55}, 4, 0x79},
        {{0x00, 0xFF, 0x55, 0x11}, 4, 0xB8},
        {{0x33, 0x22, 0x55, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF}, 9, 0xCB},
        {{0x92, 0x6B, 0x55}, 3, 0x8C},
        {{0xFF, 0xFF, 0xFF, 0xFF}, 4, 0x74},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        assert_int_equal(crc8_autosar(v[i].d, v[i].n), v[i].crc);
    }
}

static void crc8_table_equals_bitwise_definition_for_all_bytes(void **state)
{
    (void)state;
    for (unsigned init = 0; init < 256u; init += 51u) {
        for (unsigned b = 0; b < 256u; b++) {
            const uint8_t d = (uint8_t)b;
            assert_int_equal(sc_crc8_j1850(&d, 1, (uint8_t)init),
                             crc8_bitwise(&d, 1, (uint8_t)init));
        }
    }
}

static void profile1_crc_covers_data_id_then_payload_without_crc_byte(void **state)
{
    (void)state;
    uint8_t p[8] = {0xAA, 0x03, 1, 2, 3, 4, 5, 6};
    const uint8_t ref_in[] = {0x34, 0x12, 0x03, 1, 2, 3, 4, 5, 6};
    assert_int_equal(sc_e2e_crc(0x1234u, p, 8), crc8_bitwise(ref_in, 9, 0x00u));
    /* the CRC byte itself is not covered */
    p[0] = 0x55;
    assert_int_equal(sc_e2e_crc(0x1234u, p, 8), crc8_bitwise(ref_in, 9, 0x00u));
    /* a different data ID gives a different CRC over the same payload (masquerade check) */
    assert_int_not_equal(sc_e2e_crc(0x1235u, p, 8), sc_e2e_crc(0x1234u, p, 8));
}

static void protect_writes_counter_nibble_and_crc_and_wraps_counter(void **state)
{
    (void)state;
    sc_e2e_tx tx;
    sc_e2e_tx_init(&tx, 0x100u);
    uint8_t d[8] = {0, 0xA0, 9, 9, 9, 9, 9, 9};
    for (unsigned i = 0; i < 20u; i++) {
        assert_int_equal(sc_e2e_protect(&tx, d, sizeof d), 0);
        assert_int_equal(d[1] & 0x0Fu, i % 16u);
        assert_int_equal(d[1] & 0xF0u, 0xA0u); /* high nibble kept */
        assert_int_equal(d[0], sc_e2e_crc(0x100u, d, sizeof d));
    }
    assert_int_equal(sc_e2e_protect(&tx, d, 1), SC_ERR_INVALID_ARG);
}

typedef struct rxfix {
    sc_e2e_rx rx;
    uint8_t d[8];
} rxfix;

static sc_e2e_status send(rxfix *f, uint8_t counter, uint64_t t_ns)
{
    memset(f->d, 0x5A, sizeof f->d);
    assert_int_equal(sc_e2e_protect_with(0x101u, counter, f->d, sizeof f->d), 0);
    return sc_e2e_check(&f->rx, f->d, sizeof f->d, t_ns);
}

static void setup_rx(rxfix *f, uint8_t max_delta, uint32_t timeout_ms)
{
    sc_e2e_rx_def def = sc_e2e_rx_default_def(0x101u);
    def.max_delta_counter = max_delta;
    def.timeout_ms = timeout_ms;
    assert_int_equal(sc_e2e_rx_init(&f->rx, &def), 0);
}

static void every_receive_outcome_is_reported_and_counted(void **state)
{
    (void)state;
    rxfix f;
    setup_rx(&f, 3u, 100u);
    const uint64_t ms = 1000000u;
    assert_int_equal(sc_e2e_poll(&f.rx, 0), SC_E2E_TIMEOUT); /* nothing ever received */
    assert_int_equal(send(&f, 7, 1 * ms), SC_E2E_INITIAL);
    assert_int_equal(send(&f, 8, 2 * ms), SC_E2E_OK);
    assert_int_equal(send(&f, 8, 3 * ms), SC_E2E_REPEATED);
    assert_int_equal(send(&f, 11, 4 * ms), SC_E2E_OK_SOME_LOST); /* 9, 10 lost */
    assert_int_equal(f.rx.lost, 2);
    assert_int_equal(send(&f, 15, 5 * ms), SC_E2E_WRONG_SEQUENCE); /* jump of 4 > 3 */
    /* re-anchored on 15: the next consecutive counter (wrapping) is fine again */
    assert_int_equal(send(&f, 0, 6 * ms), SC_E2E_OK);
    /* a going-back counter is a wrong sequence, not "repeated" */
    assert_int_equal(send(&f, 14, 7 * ms), SC_E2E_WRONG_SEQUENCE);
    /* corrupt one bit: wrong CRC, state untouched */
    memset(f.d, 0x5A, sizeof f.d);
    sc_e2e_protect_with(0x101u, 15, f.d, sizeof f.d);
    f.d[5] ^= 0x10u;
    assert_int_equal(sc_e2e_check(&f.rx, f.d, sizeof f.d, 8 * ms), SC_E2E_WRONG_CRC);
    assert_int_equal(f.rx.last_counter, 14);
    /* a frame with the right payload but the wrong data ID is a CRC error too */
    memset(f.d, 0x5A, sizeof f.d);
    sc_e2e_protect_with(0x102u, 15, f.d, sizeof f.d);
    assert_int_equal(sc_e2e_check(&f.rx, f.d, sizeof f.d, 8 * ms), SC_E2E_WRONG_CRC);
    assert_int_equal(sc_e2e_check(&f.rx, f.d, 1, 8 * ms), SC_E2E_WRONG_CRC);

    assert_int_equal(sc_e2e_poll(&f.rx, 9 * ms), SC_E2E_OK); /* data arrived since last poll */
    assert_int_equal(sc_e2e_poll(&f.rx, 10 * ms), SC_E2E_NO_NEW_DATA);
    /* last usable message at 6 ms: 106 ms is the limit, 107 ms is past it */
    assert_int_equal(sc_e2e_poll(&f.rx, 106 * ms), SC_E2E_NO_NEW_DATA);
    assert_int_equal(sc_e2e_poll(&f.rx, 107 * ms), SC_E2E_TIMEOUT);
    assert_int_equal(sc_e2e_poll(&f.rx, 108 * ms), SC_E2E_TIMEOUT); /* a level */
    /* after a timeout the next message is INITIAL whatever its counter */
    assert_int_equal(send(&f, 3, 110 * ms), SC_E2E_INITIAL);

    assert_int_equal(f.rx.count[SC_E2E_INITIAL], 2);
    assert_int_equal(f.rx.count[SC_E2E_OK], 2);
    assert_int_equal(f.rx.count[SC_E2E_REPEATED], 1);
    assert_int_equal(f.rx.count[SC_E2E_OK_SOME_LOST], 1);
    assert_int_equal(f.rx.count[SC_E2E_WRONG_SEQUENCE], 2);
    assert_int_equal(f.rx.count[SC_E2E_WRONG_CRC], 3);
    assert_int_equal(f.rx.count[SC_E2E_NO_NEW_DATA], 2);
    assert_int_equal(f.rx.count[SC_E2E_TIMEOUT], 1); /* one edge */
}

static void only_ok_initial_and_some_lost_are_usable(void **state)
{
    (void)state;
    for (int s = 0; s < (int)SC_E2E_STATUS_COUNT; s++) {
        const int usable = s == SC_E2E_OK || s == SC_E2E_INITIAL || s == SC_E2E_OK_SOME_LOST;
        assert_int_equal(sc_e2e_status_usable((sc_e2e_status)s), usable);
        assert_string_not_equal(sc_e2e_status_name((sc_e2e_status)s), "?");
    }
}

static void max_delta_one_tolerates_no_loss_and_zero_timeout_never_times_out(void **state)
{
    (void)state;
    rxfix f;
    setup_rx(&f, 1u, 0u);
    assert_int_equal(sc_e2e_poll(&f.rx, 0), SC_E2E_NO_NEW_DATA);
    assert_int_equal(send(&f, 0, 1), SC_E2E_INITIAL);
    assert_int_equal(send(&f, 2, 2), SC_E2E_WRONG_SEQUENCE);
    assert_int_equal(sc_e2e_poll(&f.rx, UINT64_C(1) << 62), SC_E2E_OK);
    assert_int_equal(sc_e2e_poll(&f.rx, UINT64_C(1) << 62), SC_E2E_NO_NEW_DATA);
    sc_e2e_rx_def bad = sc_e2e_rx_default_def(1u);
    bad.max_delta_counter = 0u;
    assert_int_equal(sc_e2e_rx_init(&f.rx, &bad), SC_ERR_INVALID_ARG);
    bad.max_delta_counter = 15u;
    assert_int_equal(sc_e2e_rx_init(&f.rx, &bad), SC_ERR_INVALID_ARG);
}

static void every_single_bit_flip_of_a_frame_is_detected(void **state)
{
    (void)state;
    /* CRC-8 0x1D detects every single-bit error in any message length we use. */
    uint8_t d[64];
    for (size_t i = 0; i < sizeof d; i++) {
        d[i] = (uint8_t)(i * 37u + 1u);
    }
    sc_e2e_protect_with(0x110u, 5, d, 20);
    for (unsigned bit = 0; bit < 20u * 8u; bit++) {
        uint8_t c[20];
        memcpy(c, d, 20);
        c[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
        assert_int_not_equal(c[0], sc_e2e_crc(0x110u, c, 20));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(crc8_matches_sae_j1850_and_autosar_check_values),
        cmocka_unit_test(crc8_table_equals_bitwise_definition_for_all_bytes),
        cmocka_unit_test(profile1_crc_covers_data_id_then_payload_without_crc_byte),
        cmocka_unit_test(protect_writes_counter_nibble_and_crc_and_wraps_counter),
        cmocka_unit_test(every_receive_outcome_is_reported_and_counted),
        cmocka_unit_test(only_ok_initial_and_some_lost_are_usable),
        cmocka_unit_test(max_delta_one_tolerates_no_loss_and_zero_timeout_never_times_out),
        cmocka_unit_test(every_single_bit_flip_of_a_frame_is_detected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
